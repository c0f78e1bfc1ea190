"""Old home of the code-built demo rig and the default character, now
:mod:`rigedit.editor.demo` (the UI tests, benchmarks and scripts import them from here)."""
from __future__ import annotations

from ..editor.demo import default_rig, demo_rig

__all__ = ["default_rig", "demo_rig"]
