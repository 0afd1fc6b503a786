"""A benchmark is one package (issue 37): no module named after a benchmark, and none
importing a benchmark package, outside ``benchmarks/<name>/``; the registry and the CLI's
command modules (which import what their command runs) aside."""

from __future__ import annotations

from pathlib import Path

from tests.architecture.archscan import (
    ROOT,
    benchmark_codes_in_shared,
    outside_benchmark_modules,
    plant,
    ratchet,
)

ALLOWED: frozenset[str] = frozenset()


def test_no_new_benchmark_module_outside_its_package() -> None:
    ratchet(outside_benchmark_modules(ROOT), ALLOWED, "benchmark modules outside their package")


def test_a_module_outside_its_package_is_found(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/benchmarks/registry.py": "import ertools.benchmarks.fbm9.declare\n",
            "ertools/benchmarks/common/gaps.py": "",
            "ertools/benchmarks/fbm9/declare.py": "from ertools.benchmarks.common import gaps\n",
            "ertools/benchmarks/fbm9/plots.py": "from ertools.benchmarks.fbm9 import declare\n",
            "ertools/report/plots_fbm9.py": "",
            "ertools/report/shared.py": "from ertools.benchmarks.fbm9.result import R\n",
            "ertools/report/common.py": "from ertools.benchmarks.common import gaps\n",
            "ertools/cli/score.py": "from ertools.benchmarks.fbm9 import declare\n",
            "ertools/samples/competition.py": "from ertools.benchmarks.fbm9 import sample\n",
            "ertools/samples/competition_x.py": "import ertools.benchmarks.fbm9.sample\n",
            "ertools/samples/schedule.py": "from ertools.benchmarks.fbm9 import sample\n",
            "ertools/samples/competition_y.py": "from ertools.benchmarks.fbm9.result import R\n",
        },
    )
    assert outside_benchmark_modules(root) == {
        "ertools/report/plots_fbm9.py: named after a benchmark",
        "ertools/report/shared.py: imports ertools.benchmarks.fbm9",
        "ertools/samples/schedule.py: imports ertools.benchmarks.fbm9",
        "ertools/samples/competition_y.py: imports ertools.benchmarks.fbm9",
    }


def test_no_shared_rsbb_module_names_a_benchmark_code() -> None:
    """Issue 38 item 6: a new RSBB benchmark is its folder and one registry line, so the
    shared RSBB modules never name a registered code (nothing allowed)."""
    assert benchmark_codes_in_shared(ROOT) == set()


def test_a_code_in_a_shared_rsbb_module_is_found(tmp_path: Path) -> None:
    """Each form is caught where it is forbidden, and only there: the planted registry names
    ``hzz`` and ``hyy``; HSUF is no registered code."""
    registry = 'ENTRIES = (Entry("hzz", ".hzz.declare", "z"), Entry("hyy", ".hyy.declare", "y"))\n'
    root = plant(
        tmp_path,
        {
            "ertools/benchmarks/registry.py": registry,
            "ertools/rsbb/layout.py": 'def f(code):\n    return 1 if code == "HZZ" else 0\n',
            "ertools/rsbb/other.py": 'NAMES = {"HYY": "y"}\nHSUF = "HSUF"\nLOWER = "hzz"\n',
            "ertools/competition/text.py": 'def f(c):\n    match c:\n        case "HYY":\n'
            "            return 1\n    return 0\n",
            "ertools/samples/season.py": 'ORDER = ("HZZ", "HYY")\n',
            "ertools/rsbb_states.py": 'TABLE = (B("HZZ", "z"), B("HYY", "y"))\n'
            'X = TABLE[0] if TABLE[0].code in ("HYY", "Q") else TABLE["HZZ"]\n',
            "ertools/benchmarks/hzz/config.py": 'CODE = "HZZ"\n',
            "ertools/report/page.py": 'def f(code):\n    return code == "HZZ"\n',
        },
    )
    assert benchmark_codes_in_shared(root) == {
        "ertools/rsbb/layout.py:2: names the code 'HZZ'",
        "ertools/rsbb/other.py:1: names the code 'HYY'",
        "ertools/competition/text.py:3: names the code 'HYY'",
        "ertools/samples/season.py:1: names the code 'HZZ'",
        "ertools/samples/season.py:1: names the code 'HYY'",
        "ertools/rsbb_states.py:2: chooses by the code 'HYY'",
        "ertools/rsbb_states.py:2: chooses by the code 'HZZ'",
    }
