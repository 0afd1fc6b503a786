"""A toy benchmark, a complete package: what docs/writing-a-benchmark.md walks through."""
