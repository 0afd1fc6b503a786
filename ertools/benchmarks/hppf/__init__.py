"""HPPF (FBM4@Home 2019, people perception) re-scored from its RSBB run logs."""
