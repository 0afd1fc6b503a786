"""The machinery every simulated log is written with: what a benchmark's ``sample`` module and
the sample competition build their logs from. It never imports a scorer: the answers are
computed from the simulated truth.

- :mod:`ertools.simulator.writer`: :class:`~ertools.simulator.writer.BagWriter`, one log in
  ROS1 / rosbag2 (mcap, sqlite3) / MCAP format, bulk-serialised and sorted by record time.
- :mod:`ertools.simulator.packing`: the writer's bulk serialisation (fixed-layout messages
  packed with NumPy, ROS1 and CDR) and its typestore.
- :mod:`ertools.simulator.mocap`: what the 2015 mocap node published for a rigid body (noise,
  latency, tracking loss), the static ``world -> map``, map topics and ``/rosout``.
- :mod:`ertools.simulator.statemachine`: the BmBox/RefBox/Client state topics (10 Hz
  heartbeats plus exact transitions).
- :mod:`ertools.simulator.simulated`: one simulated execution before it is written.
- :mod:`ertools.simulator.rsbb`, :mod:`~ertools.simulator.rsbb_scenario`: ERL 2017-19 RSBB
  runs (bag and result file) from a timed scenario.
"""
