"""Below the public API no module imports the root package (issue 37): ``ertools/__init__``
is the API's, and a module importing it (``from ertools import atomic``, ``import ertools``)
closes a cycle through the API's ``TYPE_CHECKING`` import. Import what is meant instead:
``from ertools.atomic import write_text``, ``from ertools._version import __version__``."""

from __future__ import annotations

from pathlib import Path

from archscan import ROOT, plant, ratchet, root_imports

ALLOWED = frozenset(
    {
        "ertools/api.py",
        "ertools/audit/analyse.py",
        "ertools/benchmarks/base.py",
        "ertools/benchmarks/common/teams.py",
        "ertools/benchmarks/fbm2h/result.py",
        "ertools/cli/acquire_transform.py",
        "ertools/cli/audit.py",
        "ertools/cli/common.py",
        "ertools/cli/main.py",
        "ertools/cli/output.py",
        "ertools/cli/rescore.py",
        "ertools/configs/_yaml.py",
        "ertools/demo.py",
        "ertools/export/formats.py",
        "ertools/export/pairs.py",
        "ertools/fidelity.py",
        "ertools/io/formats.py",
        "ertools/io/mcap/scan.py",
        "ertools/io/mcap/summary.py",
        "ertools/io/ros1/layout.py",
        "ertools/io/rosbag2/metadata.py",
        "ertools/live/logfile.py",
        "ertools/live/recorder.py",
        "ertools/live/recover.py",
        "ertools/report/combine.py",
        "ertools/report/figures.py",
        "ertools/report/folder.py",
        "ertools/report/foxglove/__init__.py",
        "ertools/report/foxglove/mcapout.py",
        "ertools/report/plots_timeline.py",
        "ertools/report/timeline_page.py",
        "ertools/rescore/cache.py",
        "ertools/rescore/memo.py",
        "ertools/rescore/pipeline.py",
        "ertools/rescore/site.py",
        "ertools/samples/__main__.py",
        "ertools/samples/competition.py",
    }
)


def test_no_new_root_import() -> None:
    ratchet(root_imports(ROOT), ALLOWED, "modules importing the root package")


def test_every_spelling_of_a_root_import_is_found(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/__init__.py": "from ertools import api\n",
            "ertools/a.py": "from ertools import atomic\n",
            "ertools/b.py": "import ertools\n",
            "ertools/c.py": "def f() -> None:\n    import json, ertools  # lazy: x\n",
            "ertools/d.py": "import ertools.atomic\nfrom ertools.atomic import write_text\n",
            "ertools/pkg/e.py": "from . import d\n",
        },
    )
    assert root_imports(root) == {"ertools/a.py", "ertools/b.py", "ertools/c.py"}
