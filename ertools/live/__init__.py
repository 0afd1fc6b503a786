"""The live side: NatNet mocap recorder to MCAP, log monitor and clock check (no ROS)."""
