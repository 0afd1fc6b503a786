"""Reports: folders with HTML, YAML, JSON, CSV and figures. Only this layer draws.

Its heavier parts are imported on first use as attributes (``ertools.report.folder``: pages,
Jinja2; ``ertools.report.foxglove``: protobuf), so that a command imports them only when
``--report`` or ``--foxglove`` asks for them."""

from ertools._callable import submodules

__getattr__ = submodules(__name__)
