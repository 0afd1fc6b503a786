"""Poses out for other tools: TUM, KITTI and CSV writers, and the robot/GT pairs.

Called, this package is the public API's ``ertools.export(...)`` (:func:`ertools.api.export`).
"""

from ertools._callable import make_callable

make_callable(__name__)
