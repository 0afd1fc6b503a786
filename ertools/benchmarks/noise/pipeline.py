"""The noise measure's stages: the marker set's poses read, the whole recording (or its
still phases) measured (:func:`ertools.benchmarks.common.epsilon.noise_from_stream`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ertools.benchmarks.common.epsilon import NoiseResult, noise_from_stream
from ertools.benchmarks.common.sources import read_source, tf, topic
from ertools.benchmarks.noise.config import (
    DEFAULT_FRAME,
    DEFAULT_TOPIC,
    FALLBACK_TOPIC,
    NoiseOptions,
)
from ertools.streams import PoseStream


def load(logs: Sequence[Path], options: NoiseOptions) -> PoseStream:
    """The marker set's poses: the source given, else the FBM3@Work topics, its tf frame, or
    the logs' only pose topic."""
    return read_source(
        logs,
        options.source,
        (topic(DEFAULT_TOPIC), topic(FALLBACK_TOPIC), tf(DEFAULT_FRAME)),
        what="marker set poses",
        only_topic=True,
    )


def find_runs(loaded: PoseStream, options: NoiseOptions) -> None:
    """No runs: the recording (or its still phases, found when scoring) is one measurement."""
    del loaded, options


def score_runs(loaded: PoseStream, runs: None, options: NoiseOptions) -> NoiseResult:
    """The noise statistics of the poses."""
    del runs
    return noise_from_stream(loaded, stationary=options.stationary, bin=options.bin, c=options.c)
