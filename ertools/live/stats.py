"""The recorder's own health: what arrived, what was lost, how fast each body is tracked."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class BodyCounters:
    """Counters of one configured rigid body (mutable: the recorder loop owns them)."""

    name: str
    written: int = 0  # frames with a valid pose, written
    untracked: int = 0  # frames where Motive's tracking-valid flag was off
    missing: int = 0  # frames that did not list the body at all
    tracking: bool | None = None  # state in the last frame that listed it
    window_written: int = 0  # written since the last health line

    def as_text(self, window_s: float) -> str:
        rate = self.window_written / window_s if window_s > 0 else 0.0
        state = {True: "", False: " UNTRACKED", None: " no data"}[self.tracking]
        return f"{self.name} {rate:.1f} Hz{state}"


@dataclass
class RecorderStats:
    """Everything the recorder counts; printed every few seconds and stored in each file."""

    bodies: dict[int, BodyCounters]
    frames: int = 0  # frames decoded
    dropped: int = 0  # frames missing from gaps in Motive's frame numbers
    undecodable: int = 0  # datagrams no supported NatNet layout decodes
    other_messages: int = 0  # well-formed NatNet messages that are not frames
    duplicates: int = 0  # frames received twice (same frame number back to back)
    restarts: int = 0  # frame number went backwards (Motive restarted)
    foreign: int = 0  # datagrams from another sender than --source
    unconfigured: set[int] = field(default_factory=set)  # streamed IDs absent from the config
    last_frame_number: int | None = None
    last_error: str = ""
    window_frames: int = 0

    def accept_frame_number(self, number: int) -> bool:
        """Count gaps; False for a duplicate of the previous frame (not written twice)."""
        last = self.last_frame_number
        if last is not None:
            if number == last:
                self.duplicates += 1
                return False
            if number > last + 1:
                self.dropped += number - last - 1
            elif number < last:
                self.restarts += 1
        self.last_frame_number = number
        self.frames += 1
        self.window_frames += 1
        return True

    def health_line(self, window_s: float, file_name: str, file_size: int) -> str:
        """One line: file, frames and rate, losses, per-body rates; resets the window."""
        rate = self.window_frames / window_s if window_s > 0 else 0.0
        parts = [
            f"{file_name} {file_size / 1e6:.2f} MB",
            f"frames {self.frames} ({rate:.1f}/s) dropped {self.dropped} "
            f"undecodable {self.undecodable}",
        ]
        if self.duplicates or self.restarts:
            parts[-1] += f" duplicates {self.duplicates} restarts {self.restarts}"
        if self.foreign:
            parts[-1] += f" foreign {self.foreign}"
        parts.append(", ".join(b.as_text(window_s) for b in self.bodies.values()))
        self.window_frames = 0
        for b in self.bodies.values():
            b.window_written = 0
        return " | ".join(parts)

    def as_metadata(self) -> dict[str, str]:
        """Key/value strings for the ``ertools.recorder.stats`` MCAP metadata record."""
        out = {
            "frames": str(self.frames),
            "dropped": str(self.dropped),
            "undecodable": str(self.undecodable),
            "other_messages": str(self.other_messages),
            "duplicates": str(self.duplicates),
            "restarts": str(self.restarts),
            "foreign": str(self.foreign),
            "unconfigured_ids": ",".join(str(i) for i in sorted(self.unconfigured)),
        }
        for bid, b in self.bodies.items():
            out[f"body.{bid}.name"] = b.name
            out[f"body.{bid}.written"] = str(b.written)
            out[f"body.{bid}.untracked"] = str(b.untracked)
            out[f"body.{bid}.missing"] = str(b.missing)
        return out
