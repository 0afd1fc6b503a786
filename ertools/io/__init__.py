"""The reader layer: every file ertools reads goes through here.

ROS1 bags (indexed and ``.bag.active``), rosbag2 directories (sqlite3, mcap) and standalone
MCAP files, decoded with the message definitions stored in each file. See ``docs/io.md``.
The functions live in ertools.io.reader (read_poses, read_tf...), ertools.io.summary and
ertools.io.model (the records); this package imports nothing.
"""
