"""A robot's own pose log against the mocap ground truth: association, clock offset, errors."""
