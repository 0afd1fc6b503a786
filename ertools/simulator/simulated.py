"""One simulated benchmark execution, before it is written to any file.

The scenario modules of the 2015 benchmarks (``ertools.benchmarks.<fbm1|fbm2h|fbm3w>.sample``)
split into ``simulate(...) -> SimulatedRun`` (pure: the transitions, what the mocap node
published, the configs' texts and the answers) and ``generate(outdir, seed=...)``, which writes
one log per execution as ``sample_bags/`` has it. The sample competition
(:mod:`ertools.samples.competition`) writes the same simulated executions differently: states
into the benchmark manager's logs, mocap into the GT logger's hourly files.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ertools.frozen_dataclass import frozen_dataclass
from ertools.simulator.mocap import MocapPublished
from ertools.simulator.statemachine import Transition


@frozen_dataclass(eq=False)
class SimulatedRun:
    """A benchmark execution as the simulator knows it.

    Attributes:
        benchmark: ``fbm1h``, ``fbm2h`` or ``fbm3w``.
        namespace: the topics' namespace (``/fbm2h/...``).
        start_ns: when the benchmark's recorder started (its first message).
        end_ns: when the recorder stopped (nothing of the execution after it).
        transitions: the three state machines' transitions.
        state_end_ns: ``end_ns`` given to :func:`~ertools.simulator.statemachine.publish_states`
            (None: each machine stops at its END).
        bodies: body name -> what the mocap node published for it.
        configs: config file name -> text (goal, items, shapes, transform files).
        parameters, truth, expected, tolerance: the answers-file sections
            (:func:`~ertools.simulator.answers.write_answers`).
    """

    benchmark: str
    namespace: str
    start_ns: int
    end_ns: int
    transitions: tuple[Transition, ...]
    state_end_ns: int | None
    bodies: Mapping[str, MocapPublished]
    configs: Mapping[str, str]
    parameters: Mapping[str, Any]
    truth: Mapping[str, Any]
    expected: Mapping[str, Any]
    tolerance: Mapping[str, Any]
