"""Every import inside a function says why it is there, on its own line (issue 37):
``# lazy: <reason>``, the reason naming the cost avoided. The contracts see function-level
imports, so an ertools module may be imported lazily too; the reason is for the reader."""

from __future__ import annotations

from pathlib import Path

from tests.architecture.archscan import ROOT, plant, ratchet, unexplained_lazy_imports

# Today's imports whose reason is on the line above (or missing): the list only shrinks.
ALLOWED = frozenset(
    {
        "ertools/api.py: matplotlib.figure",
        "ertools/benchmarks/fbm1/gt.py: scipy.spatial.transform x2",
        "ertools/benchmarks/fbm1/intervals.py: scipy.stats",
        "ertools/configs/shapes.py: scipy.interpolate",
        "ertools/configs/transform.py: scipy.spatial.transform",
        "ertools/exporting/formats.py: scipy.spatial.transform",
        "ertools/geometry.py: scipy.spatial.transform",
        "ertools/io/decode/typestore.py: rosbags.serde",
        "ertools/io/decode/typestore.py: rosbags.typesys",
        "ertools/io/files.py: rosbags.interfaces",
        "ertools/io/files.py: rosbags.rosbag1",
        "ertools/io/files.py: rosbags.rosbag2",
        "ertools/io/mcap/summary.py: mcap.exceptions",
        "ertools/io/text.py: scipy.spatial.transform",
        "ertools/live/logfile.py: mcap.writer",
        "ertools/live/rosmsg.py: rosbags.typesys",
        "ertools/report/figures.py: matplotlib.backends.backend_agg",
        "ertools/report/figures.py: matplotlib.figure",
        "ertools/report/figures.py: matplotlib.image",
        "ertools/report/foxglove/messages.py: google.protobuf.descriptor_pb2",
        "ertools/report/plots_timeline.py: matplotlib.dates x3",
        "ertools/report/plots_timeline.py: matplotlib.figure",
        "ertools/report/plots_timeline.py: matplotlib.patches",
        "ertools/report/plots_timeline.py: matplotlib.transforms",
        "ertools/samples/packing.py: rosbags.typesys",
        "ertools/samples/rsbb.py: rosbags.typesys",
        "ertools/samples/writer.py: mcap.writer",
        "ertools/samples/writer.py: rosbags.rosbag1",
        "ertools/samples/writer.py: rosbags.rosbag2",
        "ertools/samples/writer.py: rosbags.rosbag2.enums",
    }
)


def test_no_new_function_import_without_its_reason() -> None:
    ratchet(unexplained_lazy_imports(ROOT), ALLOWED, "function-level imports without a reason")


def test_the_reason_must_be_on_the_import_line(tmp_path: Path) -> None:
    root = plant(
        tmp_path,
        {
            "ertools/a.py": (
                "from typing import TYPE_CHECKING\n"
                "import json\n"
                "if TYPE_CHECKING:\n"
                "    import numpy\n"
                "def f() -> None:\n"
                "    import scipy  # lazy: scipy ~150 ms, only here\n"
                "    # lazy: above, not on the line\n"
                "    import matplotlib\n"
                "    from ertools import b\n"
                "    def g() -> None:\n"
                "        import yaml  # lazy:\n"
                "    from ertools import (  # lazy: optional extra\n"
                "        c,\n"
                "    )\n"
            ),
        },
    )
    assert unexplained_lazy_imports(root) == {
        "ertools/a.py: matplotlib",
        "ertools/a.py: ertools",
        "ertools/a.py: yaml",
    }
