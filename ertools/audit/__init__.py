"""A benchmark reconstructed from its state topics: analyse the machines, rescore, compare."""
