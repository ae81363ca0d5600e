"""The research notebooks run top to bottom on the public API (nbclient, python3 kernel)."""

import os
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"


def _execute(name: str, timeout: int = 900):
    nb = nbformat.read(NOTEBOOKS / name, as_version=4)
    env_path = os.environ.get("PYTHONPATH", "")
    root = str(NOTEBOOKS.parent)
    os.environ["PYTHONPATH"] = root + (os.pathsep + env_path if env_path else "")
    os.environ.setdefault("MPLBACKEND", "Agg")
    client = NotebookClient(nb, timeout=timeout, kernel_name="python3",
                            resources={"metadata": {"path": str(NOTEBOOKS)}})
    client.execute()
    return nb


def test_quickstart_runs():
    nb = _execute("quickstart.ipynb")
    text = "".join(
        o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
    )
    assert "contact ratio 1.7547" in text
    assert "all converged: True" in text
    assert "converged True" in text


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(p.name for p in NOTEBOOKS.glob("*.ipynb")
                                        if p.name != "quickstart.ipynb"))
def test_other_notebooks_run(name):
    _execute(name, timeout=1800)
