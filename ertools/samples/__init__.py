"""The deterministic simulator of 2015 benchmark logs with known answers.

``python -m ertools.samples OUTDIR`` writes every registered scenario (see
:mod:`ertools.samples.scenario`) into ``OUTDIR/<name>/``; ``sample_bags/`` is its output.

Scenario modules build on :mod:`ertools.simulator` (the writer, mocap, state machines).

This package never imports the scorers (``ertools.benchmarks``): answers are computed
independently from the simulated truth.
"""
