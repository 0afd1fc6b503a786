"""The text trajectory layouts ertools reads, by name: what ``--input-format`` offers. Apart
from :mod:`ertools.io.model` (its frozen dataclasses cost ~0.6 ms each at import) because
``ertools score trajectory``'s parser needs only these names."""

from __future__ import annotations

from typing import Literal

# Text trajectories ertools reads (:mod:`ertools.io.text`).
TextFormat = Literal["tum", "kitti", "euroc", "csv"]
TEXT_FORMATS: tuple[TextFormat, ...] = ("tum", "kitti", "euroc", "csv")
# ``--input-format``: a text layout, or ``bag`` (ROS1, rosbag2, MCAP) to skip the sniffing.
INPUT_FORMATS: tuple[str, ...] = (*TEXT_FORMATS, "bag")
