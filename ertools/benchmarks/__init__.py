"""One package per benchmark; each has the same shape: load -> find runs -> score -> result.

Each declares itself in its ``declare`` module (:class:`ertools.benchmarks.base.Benchmark`);
:mod:`ertools.benchmarks.registry` lists them, imported lazily, as rosbags registers its
storage plugins.
"""
