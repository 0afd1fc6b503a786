"""Test-suite root: its presence puts ``tests/`` on ``sys.path`` (pytest's prepend import
mode), so helpers shared by several test folders live in one module, ``tests/fakes.py``."""
