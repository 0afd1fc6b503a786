"""The deterministic simulator of 2015 benchmark logs with known answers.

``python -m ertools.samples OUTDIR`` writes every registered scenario (see
:mod:`ertools.samples.scenario`) into ``OUTDIR/<name>/``; ``sample_bags/`` is its output.

Building blocks for scenario modules:

- :mod:`ertools.samples.writer`: :class:`~ertools.samples.writer.BagWriter`, one log in
  ROS1 / rosbag2 (mcap, sqlite3) / MCAP format, bulk-serialised and sorted by record time.
- :mod:`ertools.samples.packing`: the writer's bulk serialisation (fixed-layout messages
  packed with NumPy, ROS1 and CDR) and its typestore.
- :mod:`ertools.samples.mocap`: what the 2015 mocap node published for a rigid body (noise,
  latency, tracking loss), the static ``world -> map``, map topics and ``/rosout``.
- :mod:`ertools.samples.statemachine`: the BmBox/RefBox/Client state topics (10 Hz heartbeats
  plus exact transitions).
- :mod:`ertools.samples.scenario`: the registry, the answers-file convention, ``write_answers``.

This package never imports the scorers (``ertools.benchmarks``): answers are computed
independently from the simulated truth.
"""
