"""Every notebook in notebooks/ runs top to bottom on the sample logs (nbclient).

A notebook whose library module is missing fails here (it is not skipped): the notebooks are
the documentation of the library's API and must keep running.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
NOTEBOOKS = REPO / "notebooks"
SCENARIOS = ("fbm1h", "fbm2h", "fbm3w", "robotlog", "timeline")
CELL_TIMEOUT_S = 60  # the slowest cell (a d_min sweep of 5 scores) takes a few seconds


def _names() -> list[str]:
    return sorted(p.stem for p in NOTEBOOKS.glob("*.ipynb"))


@pytest.fixture(scope="module")
def samples(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """sample_bags/ when it has every scenario, else the samples generated once for the run."""
    shipped = REPO / "sample_bags"
    if all(any((shipped / s).glob("*.answers.yaml")) for s in SCENARIOS):
        return shipped
    from ertools.samples.__main__ import generate

    out = tmp_path_factory.mktemp("samples")
    generate(out, list(SCENARIOS))
    return out


def test_every_notebook_is_built_by_build_py() -> None:
    import importlib.util

    spec = importlib.util.spec_from_file_location("nb_build", NOTEBOOKS / "build.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert sorted(module.NOTEBOOKS) == _names()
    assert module.main(["--check"]) == 0, "run python notebooks/build.py"


@pytest.mark.parametrize("name", _names())
def test_notebook_runs(name: str, samples: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    nb = nbformat.read(NOTEBOOKS / f"{name}.ipynb", as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), (
        "commit notebooks without outputs"
    )
    monkeypatch.setenv("ERTOOLS_SAMPLES", str(samples))
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    client = NotebookClient(
        nb,
        timeout=CELL_TIMEOUT_S,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOKS)}},
    )
    try:
        client.execute(env=dict(os.environ))
    except CellExecutionError as err:
        pytest.fail(f"{name}.ipynb: a cell failed:\n{str(err)[-3000:]}")
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert any("image/png" in o.get("data", {}) for o in outputs), "no figure was drawn"
