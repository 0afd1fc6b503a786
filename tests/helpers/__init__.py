"""Helpers that tests in several folders share (a helper used by one folder stays in it)."""
