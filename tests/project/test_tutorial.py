"""``examples/tutorial.ipynb``: committed without outputs, and it runs headless to a successful reach,
with MeshCat and where Drake's network policy refuses it."""

from __future__ import annotations

import json

import nbclient
import nbformat
import pytest
from conftest import REPO
from ipykernel.kernelspec import install

NOTEBOOK = REPO / "examples" / "tutorial.ipynb"


def test_the_committed_notebook_has_no_outputs():
    cells = json.loads(NOTEBOOK.read_text())["cells"]
    code = [cell for cell in cells if cell["cell_type"] == "code"]
    assert code and any(cell["cell_type"] == "markdown" for cell in cells)
    for cell in code:
        assert cell["outputs"] == [] and cell["execution_count"] is None, cell["source"]


def text(cell) -> str:
    return "".join(output.get("text", "") for output in cell.outputs if output.output_type == "stream")


@pytest.mark.parametrize("network", ["meshcat", "none"])
def test_the_notebook_runs_headless_to_a_successful_reach(tmp_path, monkeypatch, network):
    """On a kernel of this interpreter (a kernelspec made here: a fresh venv has none). With MeshCat
    allowed the view is embedded; refused, the notebook says so and goes on."""
    install(user=False, prefix=str(tmp_path), kernel_name="hlp-drake-test")
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "share" / "jupyter"))
    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", network)
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(
        notebook, kernel_name="hlp-drake-test", timeout=300, resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    cells = [cell for cell in notebook.cells if cell.cell_type == "code"]
    (result,) = [cell for cell in cells if "result" in cell.metadata.get("tags", [])]
    assert text(result).startswith("reach succeeded\n"), text(result)
    (view,) = [cell for cell in cells if "StartMeshcat()" in cell.source]
    frames = [
        o
        for o in view.outputs
        if o.output_type == "display_data" and "<iframe" in o.data.get("text/html", "")
    ]
    if network == "meshcat":
        assert len(frames) == 1 and "http://" in frames[0].data["text/html"]
    else:
        assert not frames and "No 3-D view here" in text(view)
