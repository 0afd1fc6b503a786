"""HOPF (FBM1@Home 2017-19, object perception) re-scored from its RSBB run logs."""
