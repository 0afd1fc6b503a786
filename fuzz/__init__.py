"""Mutation fuzzing of ertools' ROS1 and MCAP readers against the official readers.

``seeds`` writes small bags, ``mutate`` damages them (structure-aware, seeded), ``judge`` reads
each mutant with ertools and with rosbags / mcap and classifies the case, ``run`` drives many
cases in watched worker processes (``make fuzz``; ``tests/fuzz`` runs a sample). See docs/qa.md.
"""
