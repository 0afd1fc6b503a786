"""The version of ertools, written once: pyproject.toml reads it (a dynamic version), and
``ertools --version`` and the files ertools writes show it."""

__version__ = "0.1.0"
