"""A result as an MCAP file that opens in Foxglove (``--foxglove FILE.mcap``): ``write`` (the
file), ``mcapout`` (its MCAP writer) and ``audit`` (an audit's messages). A benchmark's own
messages are built by its ``foxglove`` module; docs/foxglove.md lists every topic."""
