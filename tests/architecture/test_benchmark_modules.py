"""A benchmark is one package (issue 37): no module named after a benchmark, and none
importing a benchmark package, outside ``benchmarks/<name>/``; the registry and the CLI's
command modules (which import what their command runs) aside."""

from __future__ import annotations

from pathlib import Path

from tests.architecture.archscan import ROOT, outside_benchmark_modules, plant, ratchet

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
