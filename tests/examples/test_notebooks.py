"""Every notebook runs top to bottom with the installed package."""

from __future__ import annotations

import helpers
import pytest

nbformat = pytest.importorskip("nbformat", reason="notebooks need the test extra (nbformat)")
nbclient = pytest.importorskip("nbclient", reason="notebooks need the test extra (nbclient)")

NOTEBOOKS = sorted(helpers.NOTEBOOKS.glob("*.ipynb"))
# A notebook renders, records or trains for a minute or more.
pytestmark = pytest.mark.slow


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs(path, tmp_path):
    notebook = nbformat.read(path, as_version=4)
    # A notebook lists the optional extras it needs in its metadata ("ambfplus": {"requires"}).
    for module in notebook.metadata.get("ambfplus", {}).get("requires", []):
        pytest.importorskip(module, reason=f"{path.name} needs {module} (an optional extra)")
    client = nbclient.NotebookClient(
        notebook,
        timeout=300,
        kernel_name="python3",
        resources={"metadata": {"path": str(path.parent)}},
    )
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert any(o.output_type == "display_data" for o in outputs), "the notebook shows images"
