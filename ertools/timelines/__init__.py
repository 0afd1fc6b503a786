"""Bags from many machines ordered by time: scan the files, build the sessions, pair them (the
public API's function is ``ertools.timeline``)."""
