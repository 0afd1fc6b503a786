"""Poses out for other tools: TUM, KITTI and CSV writers, and the robot/GT pairs (the public
API's function is ``ertools.export``)."""
