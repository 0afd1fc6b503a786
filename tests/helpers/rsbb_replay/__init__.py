"""Statement-by-statement replays of the RSBB benchmark scripts (ERL @Home 2017-19).

The oracles of the RSBB benchmarks' tests: each module replays one script at the commits that
served events (docs/hopf.md ... docs/hgmf.md) against a
:class:`~tests.helpers.rsbb_replay.world.World`, the BmBox, RefBox and tf as the script saw
them, built by hand in a test or from a run bag (:mod:`tests.helpers.rsbb_replay.fromlog`,
which uses ertools' readers only). Nothing here imports ertools' scoring code.
"""
