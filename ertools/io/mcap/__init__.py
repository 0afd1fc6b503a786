"""MCAP files: the summary and chunk-index fast path, and the record-by-record scan."""
