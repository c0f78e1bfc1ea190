"""What a compression did: errors, sizes, ratio, time; lines for the command line."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["RAW_BYTES_PER_JOINT_FRAME", "ClipRow", "CompressionReport"]

#: ACL's raw size: 10 float32 per joint per source frame (translation, rotation, scale).
RAW_BYTES_PER_JOINT_FRAME = 40

KINDS = ("rotation", "translation", "scale", "times", "header")


@dataclass
class ClipRow:
    """One clip's figures (errors in metres, sizes in bytes)."""

    name: str
    frames: int
    joints: int
    max_error: float
    p99_error: float
    raw_bytes: int
    compressed_bytes: int
    bytes_by_kind: dict
    tracks: dict          # omitted / constant / animated counts
    keys: int             # keys stored in animated tracks
    attempts: int         # encodes until the check held

    @property
    def ratio(self):
        return self.raw_bytes / max(self.compressed_bytes, 1)


@dataclass
class CompressionReport:
    """Figures over every frame of every clip, checked after decoding.

    ``max_error`` / ``p99_error``: metres, over every (frame, joint) of every clip;
    ``ratio``: raw (:data:`RAW_BYTES_PER_JOINT_FRAME` per joint per frame) over compressed;
    ``bytes_by_kind``: compressed bytes per kind (rotation, translation, scale, times,
    header); ``clips``: one :class:`ClipRow` each; ``seconds``: wall time.
    """

    bound: float
    shell: float
    target: str
    clips: list = field(default_factory=list)
    seconds: float = 0.0
    max_error: float = 0.0
    p99_error: float = 0.0

    def finish(self, errors, seconds):
        """Set the totals from every clip's (F, J) errors."""
        flat = np.concatenate([e.reshape(-1) for e in errors]) if errors else np.zeros(1)
        self.max_error = float(flat.max())
        self.p99_error = float(np.percentile(flat, 99))
        self.seconds = float(seconds)
        return self

    @property
    def raw_bytes(self):
        return sum(c.raw_bytes for c in self.clips)

    @property
    def compressed_bytes(self):
        return sum(c.compressed_bytes for c in self.clips)

    @property
    def ratio(self):
        return self.raw_bytes / max(self.compressed_bytes, 1)

    @property
    def bytes_by_kind(self):
        return {k: sum(c.bytes_by_kind.get(k, 0) for c in self.clips) for k in KINDS}

    def lines(self):
        """Human-readable lines (centimetres, as the command line takes its options)."""
        out = [f"{len(self.clips)} clips, bound {self.bound * 100:g} cm (shell "
               f"{self.shell * 100:g} cm), target {self.target}: ratio {self.ratio:.1f}:1 "
               f"({self.raw_bytes} -> {self.compressed_bytes} bytes), max error "
               f"{self.max_error * 100:.4f} cm, 99th percentile {self.p99_error * 100:.4f} cm, "
               f"{self.seconds:.2f} s"]
        kinds = self.bytes_by_kind
        out.append("bytes: " + ", ".join(f"{k} {kinds[k]}" for k in KINDS))
        for c in self.clips:
            out.append(f"  {c.name}: {c.frames} frames x {c.joints} joints, ratio "
                       f"{c.ratio:.1f}:1, max {c.max_error * 100:.4f} cm, p99 "
                       f"{c.p99_error * 100:.4f} cm, tracks {c.tracks['animated']} animated / "
                       f"{c.tracks['constant']} constant / {c.tracks['omitted']} dropped, "
                       f"{c.keys} keys")
        return out
