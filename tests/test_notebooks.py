"""Every notebook in notebooks/ runs top to bottom.

By default in a smoke mode: MBJAX_QUICK=1 (the notebooks shorten their studies) and without the
cells tagged "slow" (long studies whose results the unit tests check anyway: the scaling runs,
the long marches, the stability sweeps). `-m slow` runs every cell."""

from pathlib import Path

import nbformat
import pytest
from jupyter_client import KernelManager
from nbclient import NotebookClient

NOTEBOOKS = sorted((Path(__file__).parent.parent / "notebooks").glob("*.ipynb"))


def test_there_are_notebooks():
    assert NOTEBOOKS


def _run(path, tmp_path, monkeypatch, smoke: bool):
    monkeypatch.setenv("MBJAX_QUICK", "1")
    nb = nbformat.read(path, as_version=4)
    if smoke:
        nb.cells = [c for c in nb.cells if "slow" not in c.metadata.get("tags", [])]
    # the kernel talks over Unix sockets in tmp_path, not TCP ports: two xdist workers starting
    # kernels at once raced for one port ("Address already in use"; the kernel died)
    km = KernelManager(kernel_name="python3", transport="ipc", ip=str(tmp_path / "kernel"))
    try:
        NotebookClient(nb, km=km, timeout=600, kernel_name="python3",
                       resources={"metadata": {"path": str(tmp_path)}}).execute()
    finally:
        # a client given its kernel manager leaves the kernel running: 11 idle kernels held
        # 0.5-1.3 GB each until the suite ended
        if km.has_kernel:
            km.shutdown_kernel(now=True)
    errors = [o for cell in nb.cells if cell.cell_type == "code"
              for o in cell.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_smoke(path, tmp_path, monkeypatch):
    _run(path, tmp_path, monkeypatch, smoke=True)


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_runs(path, tmp_path, monkeypatch):
    _run(path, tmp_path, monkeypatch, smoke=False)
