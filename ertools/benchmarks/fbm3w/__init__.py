"""FBM3@Work, following a path (manual 7.3): runs, paths, motion, score, result."""
