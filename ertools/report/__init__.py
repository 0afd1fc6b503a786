"""Reports: folders with HTML, YAML, JSON, CSV and figures. Only this layer draws.

Its heavier parts (``ertools.report.folder``: pages, Jinja2; ``ertools.report.foxglove.write``:
protobuf) are imported by the functions that need them, so that a command imports them only
when ``--report`` or ``--foxglove`` asks for them."""
