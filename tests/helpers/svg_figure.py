"""Read an SVG figure of ertools back into data: its axis labels, its series by legend label,
and each polyline's vertices in data units, through the scale its tick labels state (a tick
labelled "500" at pixel 120 and one labelled "1000" at pixel 220 give the axis' mapping).

Only the SVG's text is used, never the writer's code, so a test built on this checks what a
reader of the figure sees."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

NS = {"s": "http://www.w3.org/2000/svg"}
PAIR = re.compile(r"([ML])(-?[\d.]+),(-?[\d.]+)")


@dataclass
class Figure:
    root: ET.Element

    def texts(self, cls: str) -> list[str]:
        return ["".join(e.itertext()) for e in self.root.iter() if e.get("class") == cls]

    def series(self, label: str) -> ET.Element:
        found = [
            e
            for e in self.root.iter()
            if e.get("class") == "series" and e.get("data-label") == label
        ]
        assert len(found) == 1, f"{len(found)} series labelled {label!r}"
        return found[0]

    def labels(self) -> list[str]:
        return [e.get("data-label", "") for e in self.root.iter() if e.get("class") == "series"]

    def scale(self, axis: str) -> tuple[float, float]:
        """(a, b) with data = a * pixel + b, fitted to the tick labels of ``axis`` ('x', 'y')."""
        cls, attr = ("xtick", "x") if axis == "x" else ("ytick", "y")
        pixels, values = [], []
        for e in self.root.iter():
            if e.get("class") == cls:
                text = "".join(e.itertext())
                pixel = float(e.get(attr, "nan"))
                if axis == "y":  # the label's baseline sits 0.35 em below its tick
                    pixel -= 0.35 * float(e.get("font-size", "0"))
                pixels.append(pixel)
                values.append(float(text))
        assert len(pixels) >= 2, f"fewer than two {axis} ticks"
        a, b = np.polyfit(pixels, values, 1)
        return float(a), float(b)

    def polyline(self, label: str) -> tuple[np.ndarray, int]:
        """The vertices (data units, NaN rows between pieces) of the series' line, and the
        vertex count the path states."""
        path = self.series(label).find("s:path", NS)
        assert path is not None and path.get("class") == "line"
        ax, bx = self.scale("x")
        ay, by = self.scale("y")
        rows = []
        for cmd, x, y in PAIR.findall(path.get("d", "")):
            if cmd == "M" and rows:
                rows.append((np.nan, np.nan))
            rows.append((ax * float(x) + bx, ay * float(y) + by))
        return np.asarray(rows), int(path.get("data-points", "-1"))


def read(path: Path | str) -> Figure:
    text = Path(path).read_text(encoding="utf-8") if isinstance(path, Path) else path
    return Figure(ET.fromstring(text))
