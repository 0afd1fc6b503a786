"""What a benchmark shows, as data: charts, display units, path thinning, figure specs and
Foxglove messages. Below the benchmarks, so that each benchmark's ``plots`` and ``foxglove``
modules build on it; drawing and writing files stay in :mod:`ertools.report`."""
