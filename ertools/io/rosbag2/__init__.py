"""rosbag2 folders: metadata.yaml and the sqlite3 / MCAP storage behind it."""
