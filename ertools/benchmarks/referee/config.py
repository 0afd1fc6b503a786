"""The referee-scored benchmarks' names, inputs (the options of ``ertools score hgtkmh``...,
the manifest keys) and options (:class:`RefereeOptions`), and :func:`make_options`, which
turns the inputs' values into them. NumPy-free: the command's parser imports it."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Input, resolve_values
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb_states import BENCHMARKS

#: The RSBB benchmarks scored by the referee's items alone.
REFEREE_CODES = ("HGTKMH", "HWV", "HCFGAC", "STB")
#: Registry name -> RSBB code, for every benchmark the referee alone scores.
CODES: dict[str, str] = {code.lower(): code for code in REFEREE_CODES}
#: The mocap bodies whose pose topics a run records, by code (2bb8a41: the STB's actor alone).
MOCAP_BODIES: dict[str, tuple[str, ...]] = {"STB": ("actor_markerset",)}

# The ERL order as one number (higher is better): achievements, then penalties, then time.
# Exact as long as there are fewer than PENALTY_SCALE penalties and the time is below
# TIME_SCALE / PENALTY_SCALE seconds (the RSBB's timeouts are 120 s and 600 s).
PENALTY_SCALE = 1_000.0
TIME_SCALE = 10_000_000.0


def title(code: str) -> str:
    """``HWV (Task Benchmark 2: Welcoming visitors)``."""
    return f"{code} ({BENCHMARKS[code].name})"


@frozen_dataclass
class RefereeOptions:
    """Everything ``ertools score hgtkmh|hwv|hcfgac|stb`` can be told.

    Attributes:
        code: the RSBB code (``HWV``).
        description: ``benchmarks_description.yaml`` (the items' groups, kinds and order);
            None: the items as the log names them.
        result: the run's result file (scripted benchmarks: its ``referee_score``).
        team, run: the run's team and number; None: from the bag's RSBB folder and name,
            else the only zone of the benchmark the log shows.
    """

    code: str
    description: Path | None = None
    result: Path | None = None
    team: str | None = None
    run: int | None = None


INPUTS = (
    Input(
        "description",
        "path",
        "rsbb_etc/config/benchmarks_description.yaml: the items' groups and order (default: "
        "the items as the log names them)",
        metavar="FILE",
    ),
    Input(
        "result",
        "path",
        "the run's result file, whose referee_score is used when it has one (scripted "
        "benchmarks; default: the RefBox's last values in /core/to_gui)",
        metavar="FILE",
    ),
    Input("run", "int", "the run's number (default: from the bag's name)", minimum=0),
)


def make_options(code: str, given: Mapping[str, Any]) -> RefereeOptions:
    """The values of :data:`INPUTS` -> :class:`RefereeOptions` of the benchmark ``code``.

    Raises:
        UsageError: an unknown benchmark code, an unknown input or a value that does not fit.
    """
    if code not in BENCHMARKS:
        raise UsageError(f"unknown RSBB benchmark {code!r}")
    v = resolve_values(INPUTS, given)
    run = v.get("run")
    return RefereeOptions(
        code=code,
        description=v.get("description"),
        result=v.get("result"),
        team=v.get("team") or None,
        run=None if run is None else int(run),
    )
