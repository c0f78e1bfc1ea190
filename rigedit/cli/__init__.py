"""The ``rigedit`` command: one module per command that needs more than a few lines
(:mod:`.retarget`, :mod:`.autorig`), the parser and the small commands in :mod:`.main`, output
files and interruption in :mod:`.output`."""
from .main import build_parser, main

__all__ = ["main", "build_parser"]
