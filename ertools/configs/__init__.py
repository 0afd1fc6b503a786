"""The seed's YAML formats, one module per format, each validated into frozen dataclasses."""
