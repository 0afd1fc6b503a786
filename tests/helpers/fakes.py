"""A minimal BenchmarkResult for tests that must not depend on a real scorer."""

from __future__ import annotations

import shutil
from dataclasses import dataclass, field
from typing import Any

from ertools.benchmarks.base import Rows
from ertools.serialize import dump_yaml
from ertools.streams import Provenance


@dataclass(frozen=True)
class FakeResult:
    name: str
    data: dict[str, Any]
    table: dict[str, Rows] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    deviations: tuple[str, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)

    def to_dict(self) -> dict[str, Any]:
        return self.data

    def to_yaml(self) -> str:
        return dump_yaml(self.data)

    def tables(self) -> dict[str, Rows]:
        return self.table


# Headless Chromium for the browser tests (Debian: apt-get install chromium); None where absent.
BROWSER = next(
    (shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)),
    None,
)
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
]
