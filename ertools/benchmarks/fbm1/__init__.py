"""FBM1@Home and FBM1@Work, object perception (manual 7.1): runs, ground truth, score, result."""
