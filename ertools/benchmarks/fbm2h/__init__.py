"""FBM2@Home, navigation to waypoints (manual 7.2): segments, transform, score, result."""
