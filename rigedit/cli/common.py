"""What the ``rigedit`` subcommands share: the rig loader with the run's reading options, the
usage error, and the options every rig-reading command takes."""
from __future__ import annotations

__all__ = ["UsageError", "LOAD_OPTIONS", "load", "parse_size", "scale_option"]


class UsageError(Exception):
    """Bad input that is not about a file (an unknown clip, a bad option value)."""


#: Options of every rig the command loads (set by :func:`rigedit.cli.main.main` from
#: ``--allow-outside-uris``).
LOAD_OPTIONS = {}


def load(rig_arg, method=None, scale=None):
    """``rigedit.load_rig`` with the run's options; its warnings become one line each."""
    import rigedit

    from .output import warning_lines

    with warning_lines():
        return rigedit.load_rig(rig_arg, weights_method=method, scale=scale, **LOAD_OPTIONS)


def parse_size(text):
    """``(width, height)`` from ``WIDTHxHEIGHT``; :class:`UsageError` otherwise."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise UsageError(f"--size: expected WIDTHxHEIGHT such as 1280x720, got {text!r}") from None
    return w, h


def scale_option(s):
    """The options of the rigs a command reads: ``--scale`` and ``--allow-outside-uris``."""
    s.add_argument("--scale", type=float, default=None, metavar="M",
                   help="metres per file unit of a .bvh RIG (default: guessed from its height)")
    s.add_argument("--allow-outside-uris", action="store_true",
                   help="let a .gltf read buffers and images outside its folder (absolute "
                        "paths, '..', file:); off by default")
