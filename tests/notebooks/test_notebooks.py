"""The research notebooks run top to bottom on the public API (nbclient, python3 kernel)."""

import os

import nbformat
import pytest
from helpers import ROOT
from nbclient import NotebookClient

NOTEBOOKS = ROOT / "notebooks"
DEFAULT = ("quickstart.ipynb",)
# run below at reduced resolution (their cheap siblings: tests/optimise/test_design_optimise.py)
OWN_TEST = (
    "paper_reproduction.ipynb",
    "tip_relief_optimisation.ipynb",
    "design_optimisation.ipynb",
)


def _execute(name, monkeypatch, timeout=900):
    nb = nbformat.read(NOTEBOOKS / name, as_version=4)
    env_path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    monkeypatch.setenv("PYTHONPATH", env_path)  # the kernel is a subprocess: import this checkout
    monkeypatch.setenv("MPLBACKEND", "Agg")
    NotebookClient(
        nb, timeout=timeout, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOKS)}}
    ).execute()
    errors = [
        out
        for cell in nb.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if out.get("output_type") == "error"
    ]
    assert not errors
    return "".join(
        out.get("text", "")
        for cell in nb.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
    )


def test_quickstart_runs(monkeypatch):
    text = _execute("quickstart.ipynb", monkeypatch)
    assert "contact ratio 1.7547" in text
    assert "all converged: True" in text
    assert "converged True" in text


@pytest.mark.slow
def test_tip_relief_optimisation_notebook(monkeypatch):
    # tribo-dynamic rung, coarse grid: simulate and two optimiser programs compile in the kernel
    monkeypatch.setenv("JAXGEAR_NOTEBOOK_QUICK", "1")
    text = _execute("tip_relief_optimisation.ipynb", monkeypatch)
    assert "grid best" in text and "optimum:" in text and "checks passed" in text


@pytest.mark.slow
def test_design_optimisation_notebook(monkeypatch):
    # reduced: one torque, a 4-point front on a 3 x 3 grid; the constrained optimiser, the front's
    # batch program and the sensitivity report compile in the kernel
    monkeypatch.setenv("JAXGEAR_NOTEBOOK_QUICK", "1")
    text = _execute("design_optimisation.ipynb", monkeypatch, timeout=1800)
    assert "relief:" in text and "DTE <=" in text and "elasticities" in text
    assert "checks passed" in text


@pytest.mark.slow
@pytest.mark.parametrize(
    "name",
    sorted(p.name for p in NOTEBOOKS.glob("*.ipynb") if p.name not in DEFAULT + OWN_TEST),
)
def test_other_notebooks_run(name, monkeypatch):
    _execute(name, monkeypatch, timeout=1800)


@pytest.mark.slow
def test_paper_reproduction_notebook(monkeypatch):
    # Reduced resolution (seven speeds, 24 positions per cycle) at the fast fidelity: one compile of
    # the tribo-dynamic model in the kernel, 1-3 min on 2 cores. Every figure is drawn or skipped with
    # a reason, and the table has all of R1-R11.
    monkeypatch.setenv("JAXGEAR_NOTEBOOK_QUICK", "1")
    text = _execute("paper_reproduction.ipynb", monkeypatch)
    for n in range(3, 13):
        assert f"Fig. {n} drawn" in text or f"Fig. {n} skipped: " in text, n
    for n in (3, 4, 5, 8, 10, 11):
        assert f"Fig. {n} drawn" in text, n
    for i in range(1, 12):
        assert f"R{i}: " in text, i
