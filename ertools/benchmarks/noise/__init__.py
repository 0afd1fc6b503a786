"""Mocap noise of a stationary marker set, and the d_min it suggests."""
