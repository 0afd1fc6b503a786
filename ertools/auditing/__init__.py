"""A benchmark reconstructed from its state topics: analyse the machines, recompute the score,
compare it with the live one (the public API's function is ``ertools.audit``)."""
