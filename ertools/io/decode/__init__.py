"""Message payloads to NumPy: the fast CDR/ROS1 pose decoders, the typestore and tf."""
