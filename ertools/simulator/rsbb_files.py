"""The side files of a simulated RSBB run, where the RSBB kept them (docs/rsbb.md): a team's
``rsbb_etc/transforms/transform-<team>.yaml`` and a script's
``rsbb_bmbox/scripts/benchmark_configs/<CODE>.yaml``."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import yaml

from ertools.atomic import write_text


def write_team_transform(
    root: Path, team: str, translation: Iterable[float], quat_xyzw: Iterable[float]
) -> Path:
    """``transform-<team>.yaml`` under ``root``: the marker set to robot transform as the
    RSBB's files wrote it (a ``!!python/tuple`` of the translation and the quaternion)."""
    folder = root / "rsbb_etc" / "transforms"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"transform-{team}.yaml"
    pair = f"- {[float(v) for v in translation]}\n- {[float(v) for v in quat_xyzw]}\n"
    write_text(path, f"team_name: {team}\nmarkerset_to_robot_transform: !!python/tuple\n{pair}")
    return path


def write_script_config(
    root: Path, code: str, params: Mapping[str, Any], *, flow_style: bool | None
) -> Path:
    """``<CODE>.yaml`` under ``root``: the script's parameters (``flow_style`` as PyYAML's
    ``default_flow_style``)."""
    folder = root / "rsbb_bmbox" / "scripts" / "benchmark_configs"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{code}.yaml"
    write_text(path, yaml.safe_dump(dict(params), default_flow_style=flow_style))
    return path
