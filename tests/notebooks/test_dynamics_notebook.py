"""The calibration notebook executes end to end (public API only) and its assertions hold."""

from __future__ import annotations

import pytest
from helpers import ROOT

NOTEBOOK = ROOT / "notebooks" / "calibration.ipynb"


@pytest.mark.slow  # ~2 min on the shared 2-core CPU (three compiled sweeps)
def test_calibration_notebook_executes():
    import nbclient
    import nbformat

    nb = nbformat.read(NOTEBOOK, as_version=4)
    # Run from the repository root so that the kernel imports this checkout's jaxgear.
    client = nbclient.NotebookClient(
        nb,
        timeout=900,
        kernel_name="python3",
        resources={"metadata": {"path": str(ROOT)}},
    )
    client.execute()
    text = "".join(
        o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
    )
    assert "peak   1750 rpm" in text
