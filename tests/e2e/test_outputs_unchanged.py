"""What users see stays put while the code moves: the JSON/YAML/CSV of every README and
``make demo`` command, compared with the outputs recorded before the restructuring.

The recorded files are in ``tests/e2e/golden/``. A case runs a command (in the current
vocabulary: only the spelling of options may change, never the output) and compares its stdout
and the data files of its report folder with the recording: the same text, numbers each within
what its quantity may move between CPUs (``tests/helpers/floats.py``: NumPy's and OpenBLAS's code
differs in the last bits between instruction sets; YAML's 9-decimal values may move by one in
the last digit), after normalisations: the temporary folder becomes ``<OUT>``, the repository
``<ROOT>`` and a report's ``generated`` time ``<TIME>`` and its recorded command line
``<ARGV>``. The commands run in the test's process (tests/helpers/inprocess.py), in the temporary
folder. Record again, only when an output is meant to change, with
``ERTOOLS_RECORD_GOLDEN=1 pytest tests/e2e/test_outputs_unchanged.py`` and say why in the
commit; on an AVX-512 CPU prefix ``NPY_DISABLE_CPU_FEATURES="X86_V4 AVX512_ICL"`` (the AVX2
path the recording was made on) so that the diff shows only what changed (docs/qa.md).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.helpers.floats import output_difference
from tests.helpers.inprocess import run

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"
REAL = ROOT.parent / "shared" / "real_bags"
GOLDEN = ROOT / "tests" / "e2e" / "golden"
RECORD = os.environ.get("ERTOOLS_RECORD_GOLDEN") == "1"
# Report files that are data (pictures and pages are checked elsewhere), and how each is read.
DATA_SUFFIXES = {".json": "json", ".yaml": "yaml", ".csv": "csv", ".tum": "text", ".txt": "text"}


@dataclass(frozen=True)
class Case:
    name: str
    argv: tuple[str, ...]
    # A folder the command writes (``{out}`` in argv); its data files are compared too.
    folder: str | None = None
    needs_real: bool = False


FBM3 = "{samples}/fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
FBM2 = "{samples}/fbm2h/log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
FBM2_INPUTS = (
    "--goal",
    "{samples}/fbm2h/fbm2h_goal.yaml",
    "--transform",
    "{samples}/fbm2h/transform-simbot.yaml",
)
FBM1 = "{samples}/fbm1h/log_fbm1h_2015-11-20-12-00-00_0.bag"
FBM1_ITEMS = ("--items", "{samples}/fbm1h/fbm1h.yaml")
ROBOT = "{samples}/robotlog/FBM2H_201511201200_homer.bag"
STATIONARY = "{samples}/stationary/log_fbm3w_noise_2015-11-20-09-00-00_0.bag"
TRAJ = ("score", "trajectory", ROBOT, "{samples}/robotlog/", "--offset", "auto", "--apply-offset")
REAL_FBM2 = (
    "score",
    "fbm2h",
    "{real}/log_fbm2h_mocap_2015-10-23-16-15-40_0.bag",
    "--goal",
    "{real}/fbm2h_test_optitrackless_goal.yaml",
    "--reached",
    "timing",
    "{real}/log_fbm2h_mocap_2015-10-23-16-15-40_0_reached_waypoint_timing.yaml",
)

CASES = (
    Case("timeline_json", ("timeline", "{samples}", "--format", "json")),
    Case("timeline_csv", ("timeline", "{samples}", "--format", "csv")),
    Case("info_fbm3w_json", ("info", FBM3, "--format", "json")),
    Case("fbm3w_yaml", ("score", "fbm3w", FBM3)),
    Case("fbm3w_json", ("score", "fbm3w", FBM3, "--format", "json")),
    Case("fbm3w_report", ("score", "fbm3w", FBM3, "--report", "{out}/r"), folder="r"),
    Case("fbm2h_yaml", ("score", "fbm2h", FBM2, *FBM2_INPUTS)),
    Case("fbm2h_json", ("score", "fbm2h", FBM2, *FBM2_INPUTS, "--format", "json")),
    Case("fbm2h_report", ("score", "fbm2h", FBM2, *FBM2_INPUTS, "--report", "{out}/r"), "r"),
    Case("fbm1h_yaml", ("score", "fbm1h", FBM1, *FBM1_ITEMS)),
    Case("fbm1h_json", ("score", "fbm1h", FBM1, *FBM1_ITEMS, "--format", "json")),
    Case("fbm1h_report", ("score", "fbm1h", FBM1, *FBM1_ITEMS, "--report", "{out}/r"), "r"),
    Case("trajectory_yaml", TRAJ),
    Case("trajectory_json", (*TRAJ, "--format", "json")),
    Case("trajectory_report", (*TRAJ, "--report", "{out}/r"), folder="r"),
    Case(
        "export_matched",
        ("export", ROBOT, "{samples}/robotlog/", "--out-dir", "{out}/evo", "--matched"),
        folder="evo",
    ),
    Case("noise_json", ("noise", STATIONARY, "--format", "json")),
    Case("audit_json", ("audit", FBM2, "--format", "json")),
    Case("audit_yaml", ("audit", FBM2, "--format", "yaml")),
    Case("audit_report", ("audit", FBM2, "--format", "text", "--report", "{out}/r"), folder="r"),
    Case("real_fbm2h_yaml", REAL_FBM2, needs_real=True),
    Case("real_fbm2h_json", (*REAL_FBM2, "--format", "json"), needs_real=True),
)


# The command line a report records is spelled as the case spells it; the rest must not move.
ARGV = re.compile(r'"argv": \[[^\]]*\]')
# The one field that changes from run to run: when a report was written.
GENERATED = re.compile(r'"generated": "[^"]*"')


def _normalise(text: str, out: Path) -> str:
    text = GENERATED.sub('"generated": "<TIME>"', text)
    text = ARGV.sub('"argv": "<ARGV>"', text)
    return text.replace(str(out), "<OUT>").replace(str(ROOT), "<ROOT>")


def _run(case: Case, out: Path) -> dict[str, str]:
    """The case's outputs by name: ``stdout`` and ``<folder>/<relative path>`` data files."""
    argv = [a.format(samples=SAMPLES, real=REAL, out=out) for a in case.argv]
    ran = run(argv, cwd=out)  # in this process (tests/helpers/inprocess.py): outputs are the point
    assert ran.code in (0, 1), ran.stderr[-2000:]
    outputs = {"stdout": _normalise(ran.stdout, out), "exit": str(ran.code)}
    if case.folder is not None:
        folder = out / case.folder
        for path in sorted(folder.rglob("*")):
            if path.is_file() and path.suffix in DATA_SUFFIXES:
                key = f"{case.folder}/{path.relative_to(folder).as_posix()}"
                outputs[key] = _normalise(path.read_text(encoding="utf-8"), out)
    return outputs


def _format(case: Case, key: str) -> str:
    """How output ``key`` of ``case`` is written: its suffix, else the command's --format
    (``score`` and ``audit`` write YAML by default; ``export`` prints nothing)."""
    suffix = Path(key).suffix
    if suffix in DATA_SUFFIXES:
        return DATA_SUFFIXES[suffix]
    if key == "stdout" and "--format" in case.argv:
        return case.argv[case.argv.index("--format") + 1]
    return "yaml" if key == "stdout" and case.argv[0] in ("score", "audit") else "text"


def _golden_files(case: Case) -> dict[str, str]:
    base = GOLDEN / case.name
    return {
        p.relative_to(base).as_posix(): p.read_text(encoding="utf-8")
        for p in sorted(base.rglob("*"))
        if p.is_file()
    }


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_outputs_equal_the_recording(case: Case, tmp_path: Path) -> None:
    if case.needs_real and not REAL.is_dir():
        pytest.skip("../shared/real_bags not present: the case scores a real 2015 log")
    outputs = _run(case, tmp_path)
    if RECORD:
        base = GOLDEN / case.name
        for key, text in outputs.items():
            (base / key).parent.mkdir(parents=True, exist_ok=True)
            (base / key).write_text(text, encoding="utf-8")
        return
    golden = _golden_files(case)
    assert golden, f"no recording for {case.name}: record with ERTOOLS_RECORD_GOLDEN=1"
    assert sorted(outputs) == sorted(golden), f"{case.name}: other files than recorded"
    for key, text in outputs.items():
        # numbers within their quantity's tolerance across CPUs (tests/helpers/floats.py), the rest
        # exactly
        where = output_difference(text, golden[key], _format(case, key), key)
        assert where is None, f"{case.name}: {key} differs from the recording: {where}"
