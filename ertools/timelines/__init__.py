"""Bags from many machines ordered by time: scan the files, build the sessions, pair them.

Called, this package is the public API's ``ertools.timeline(...)`` (:func:`ertools.api.timeline`).
"""

from ertools._callable import make_callable

make_callable(__name__)
