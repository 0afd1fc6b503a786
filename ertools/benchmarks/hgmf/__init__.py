"""HGMF (FBM6@Home 2019, grasping and manipulation) re-scored from its RSBB run bag."""
