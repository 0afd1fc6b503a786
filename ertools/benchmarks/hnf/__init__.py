"""HNF (FBM2@Home 2017-19, navigation) re-scored from its RSBB run bag (docs/hnf.md)."""
