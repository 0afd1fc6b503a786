"""ROS1 bag files (format 2.0): records, the index fast path, and the index check."""
