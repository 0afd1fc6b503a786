"""HPFF (FBM5@Home 2019, person following) re-scored from its RSBB run bag (docs/hpff.md)."""
