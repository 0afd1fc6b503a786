"""Every notebook in notebooks/ runs top to bottom on the sample logs, and the ones whose
benchmark applies to the real 2015 log run on it too, without an answers file (papermill).

Parameters are injected the way papermill does from its command line (a cell tagged
``injected-parameters`` after the one tagged ``parameters``), so these runs are the documented
way to run a notebook on one's own log. A notebook whose library module is missing fails here
(it is not skipped): the notebooks are the documentation of the library's API and must keep
running.
"""

from __future__ import annotations

import ast
import importlib.util
import json
import re
from pathlib import Path
from typing import Any

import nbformat
import pytest

import ertools
from ertools.cli.main import main
from ertools.samples.__main__ import generate

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
NOTEBOOKS = REPO / "notebooks"
SCENARIOS = ("fbm1h", "fbm2h", "fbm3w", "robotlog", "timeline")
CELL_TIMEOUT_S = 60  # the slowest cell (a d_min sweep of 5 scores) takes a few seconds
# The folder the parameters' defaults point into, as seen from notebooks/ (build.py SAMPLES).
SAMPLES_PREFIX = "../sample_bags/"

# The real 2015 FBM2@Home test run (../shared/real_bags/README.md): no state topics, the
# reached moments in a timing file, the marker set on the robot's odometric centre.
REAL = REPO / ".." / "shared" / "real_bags"
REAL_BAG = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"
REAL_GOAL = REAL / "fbm2h_test_optitrackless_goal.yaml"
REAL_TIMING = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0_reached_waypoint_timing.yaml"


def _names() -> list[str]:
    return sorted(p.stem for p in NOTEBOOKS.glob("*.ipynb"))


def _real() -> None:
    if not REAL_BAG.exists():
        pytest.skip("../shared/real_bags not present")


@pytest.fixture(scope="module")
def samples(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """sample_bags/ when it has every scenario, else the samples generated once for the run."""
    shipped = REPO / "sample_bags"
    if all(any((shipped / s).glob("*.answers.yaml")) for s in SCENARIOS):
        return shipped

    out = tmp_path_factory.mktemp("samples")
    generate(out, list(SCENARIOS))
    return out


def _parameters_cell(nb: Any) -> Any:
    tagged = [c for c in nb.cells if "parameters" in c.metadata.get("tags", [])]
    assert len(tagged) == 1, "one cell tagged `parameters`"
    return tagged[0]


def _defaults(name: str) -> dict[str, Any]:
    """The parameters cell's assignments, as papermill reads them (literals only)."""

    nb = nbformat.read(NOTEBOOKS / f"{name}.ipynb", as_version=4)
    tree = ast.parse(_parameters_cell(nb).source)
    out: dict[str, Any] = {}
    for node in tree.body:
        assert isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name), (
            f"{name}: the parameters cell holds only `name = literal` lines"
        )
        out[node.targets[0].id] = ast.literal_eval(node.value)
    return out


def _run(name: str, parameters: dict[str, Any], out: Path) -> Any:
    """Execute notebooks/NAME.ipynb with papermill; the executed notebook."""
    # lazy: papermill (dev extra) takes 0.7 s to import; only the notebook runs need it
    import papermill
    from papermill.exceptions import PapermillExecutionError

    try:
        papermill.execute_notebook(
            str(NOTEBOOKS / f"{name}.ipynb"),
            str(out),
            parameters=parameters,
            kernel_name="python3",
            cwd=str(NOTEBOOKS),
            progress_bar=False,
            execution_timeout=CELL_TIMEOUT_S,
        )
    except PapermillExecutionError as err:
        pytest.fail(f"{name}.ipynb: a cell failed:\n{str(err)[-3000:]}")
    nb = nbformat.read(out, as_version=4)
    # papermill's convention: the injected values right after the defaults.
    tags = [c.metadata.get("tags", []) for c in nb.cells]
    at = next(i for i, t in enumerate(tags) if "parameters" in t)
    assert "injected-parameters" in tags[at + 1]
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert any("image/png" in o.get("data", {}) for o in outputs), "no figure was drawn"
    return nb


def _text(nb: Any) -> str:
    """Everything the executed notebook printed or displayed as text."""
    parts = []
    for cell in nb.cells:
        for o in cell.get("outputs", []):
            if o.get("output_type") == "stream":
                parts.append(o.get("text", ""))
            else:
                parts.append(o.get("data", {}).get("text/plain", ""))
    return "\n".join(parts)


def _printed(nb: Any, key: str) -> float:
    found = re.findall(rf"^{key}: (\S+)$", _text(nb), flags=re.MULTILINE)
    assert len(found) == 1, f"one `{key}: ...` line, found {found}"
    return float(found[0])


def test_every_notebook_is_built_by_build_py() -> None:
    spec = importlib.util.spec_from_file_location("nb_build", NOTEBOOKS / "build.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert sorted(module.NOTEBOOKS) == _names()
    assert module.main(["--check"]) == 0, "run python notebooks/build.py"


@pytest.mark.parametrize("name", _names())
def test_every_input_is_a_parameter(name: str) -> None:
    nb = nbformat.read(NOTEBOOKS / f"{name}.ipynb", as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), (
        "commit notebooks without outputs"
    )
    defaults = _defaults(name)
    assert "answers" in defaults
    # No cell after the parameters reads a file it was not given: no globbing of a folder,
    # no environment variable.
    code = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
    assert ".glob(" not in code and "environ" not in code


@pytest.mark.parametrize("name", _names())
def test_notebook_runs_on_the_samples(name: str, samples: Path, tmp_path: Path) -> None:
    """The defaults point at sample_bags/; injected: the same files in the samples in use."""

    def move(value: Any) -> Any:
        if isinstance(value, list):
            return [move(v) for v in value]
        if isinstance(value, str) and value.startswith(SAMPLES_PREFIX):
            path = samples / value.removeprefix(SAMPLES_PREFIX)
            assert path.exists(), f"{name}: default {value} is not in the samples"
            return str(path)
        return value

    parameters = {k: move(v) for k, v in _defaults(name).items()}
    assert parameters["answers"] is not None
    nb = _run(name, parameters, tmp_path / f"{name}.ipynb")
    assert "answers file" not in _text(nb)


def test_fbm2h_notebook_on_the_real_log(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The score the notebook prints is `ertools score fbm2h` of the same inputs."""
    _real()

    assert (
        main(
            [
                "score",
                "fbm2h",
                str(REAL_BAG),
                "--goal",
                str(REAL_GOAL),
                "--reached",
                "timing",
                str(REAL_TIMING),
                "--format",
                "json",  # every bit: the YAML writes 9 decimals
            ]
        )
        == 0
    )
    cli = json.loads(capsys.readouterr().out)
    parameters = {
        "bags": [str(REAL_BAG)],
        "goal": str(REAL_GOAL),
        "transform": None,
        "timing": str(REAL_TIMING),
        "reached": "timing",
        "answers": None,
    }
    nb = _run("fbm2h", parameters, tmp_path / "fbm2h.ipynb")
    text = _text(nb)
    for key in ("position_accuracy", "orientation_accuracy", "execution_time"):
        assert _printed(nb, key) == cli[key], key
    assert "no answers file" in text
    assert "benchmark state topics: none" in text
    assert "no live score" in text
    # The choices table: no `states` rows (no state topics), the timing file and auto.
    choices = nb.cells[-1].outputs[-1]["data"]["text/plain"]
    assert "timing" in choices and "auto" in choices and "states" not in choices


def test_timeline_notebook_on_the_real_logs(tmp_path: Path) -> None:
    """The folder holds one GT log (and its YAML files, which are not bags)."""
    _real()
    nb = _run("timeline", {"folder": str(REAL), "answers": None}, tmp_path / "timeline.ipynb")
    text = _text(nb)
    assert "1 bags, 1 sessions" in text
    row = next(line for line in text.splitlines() if REAL_BAG.name in line).split()
    # path, kind, start, duration (README: a mocap GT log of 57.6 s).
    assert row[2] == "gt"
    assert float(row[4]) == pytest.approx(57.6, abs=0.05)
    assert "nothing to audit" in text
    assert "no answers file" in text


def node_module(node: ast.AST) -> str | None:
    """The module of a ``from M import ...`` (None for any other node)."""
    return node.module if isinstance(node, ast.ImportFrom) else None


def _private_uses(source: str) -> list[str]:
    """What a notebook's code takes from ertools beyond the public API (docs/api.md): any
    ``from ertools... import`` or ``import ertools.x``, and ``ertools.NAME`` for a NAME that
    is not a public one."""

    # the exceptions the API raises are public too (docs/ARCHITECTURE.md, "The public API")
    public = {*ertools.API, "__version__", "errors"}
    # IPython's magics (`%matplotlib inline`) are not Python
    code = "\n".join("" if line.lstrip().startswith("%") else line for line in source.split("\n"))
    found = []
    for node in ast.walk(ast.parse(code)):
        if node_module(node) == "ertools.errors":
            continue
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "ertools":
            found.append(f"from {node.module} import ...")
        elif isinstance(node, ast.Import):
            found += [
                a.name
                for a in node.names
                if a.name.startswith("ertools.") and a.name != "ertools.errors"
            ]
        elif (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id == "ertools"
            and node.attr not in public
        ):
            found.append(f"ertools.{node.attr}")
    return found


@pytest.mark.parametrize("name", _names())
def test_notebook_uses_only_the_public_api(name: str) -> None:
    nb = nbformat.read(NOTEBOOKS / f"{name}.ipynb", as_version=4)
    code = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
    assert "import ertools" in code
    assert _private_uses(code) == [], f"{name}.ipynb: use ertools' public API (docs/api.md)"


def test_the_public_api_rule_sees_private_imports() -> None:
    assert _private_uses("import ertools\nertools.score('x', [])\n%matplotlib inline\n") == []
    assert _private_uses(
        "from ertools.report.frames import result_to_dataframes\n"
        "import ertools.auditing.recompute\n"
        "import ertools\n"
        "ertools.benchmarks.registry.get('fbm2h')\n"
    ) == ["from ertools.report.frames import ...", "ertools.auditing.recompute", "ertools.benchmarks"]
    # the exceptions are public: a notebook may catch them
    assert (
        _private_uses(
            "import ertools\nfrom ertools.errors import BagError\nimport ertools.errors\n"
            "ertools.errors.UsageError\n"
        )
        == []
    )
