"""ertools: re-score ERL / RoCKIn benchmarks from their logs, with no ROS installed."""

__version__ = "0.1.0"

__all__ = ["__version__"]
