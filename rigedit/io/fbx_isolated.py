"""FBX in, in a child process: what the registry and every user of ``.fbx`` files call.

The FBX reader (:mod:`rigedit.io.fbx_read`) runs on ufbx's Python binding, whose 0.0.5
release crashes the process (a segmentation fault in the cyclic garbage collector) when
wrappers of a freed scene are collected in an unlucky order: measured here in a test run that
read a few dozen files in one process (``tests/io/test_bad_input.py`` then
``tests/io/test_fbx_read.py``: a segfault inside ``read_fbx`` in 2 of 2 runs), while each
file alone read fine. A crash in the editor would lose the user's unsaved work, so the read
runs in a child process that collects nothing (``gc.disable``) and exits when done; the parent
gets plain data back (:class:`~rigedit.io.data.RigData`, pickled by our own code in the child:
the file only chooses values, never the stream's structure). A hostile file that crashes or
hangs the reader costs the child, not the editor: one :class:`~rigedit.errors.RigFileError`
naming the file.

Run as ``python -m rigedit.io.fbx_isolated PATH``: writes the pickled result (a RigData or a
RigFileError) to stdout.
"""
from __future__ import annotations

import os
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

from ..errors import RigFileError

__all__ = ["read_fbx", "TIMEOUT"]

#: Seconds a read may take before the child is stopped (the shared files read in well under 2).
TIMEOUT = 300.0


def read_fbx(path):
    """Read an FBX file into a :class:`~rigedit.io.data.RigData` in a child process (see the
    module's notes); the same result and errors as :func:`rigedit.io.fbx_read.read_fbx`.

    Raises
    ------
    RigFileError
        What the reader raises, or, naming the file, a reader that crashed (the signal), hung
        (past :data:`TIMEOUT`) or said nothing.
    """
    path = Path(path)
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    try:
        run = subprocess.run([sys.executable, "-m", __name__, str(path)], capture_output=True,
                             timeout=TIMEOUT, env=env, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise RigFileError(path, f"expected an FBX file read within {TIMEOUT:.0f} s, got one "
                                 "whose reading did not end (stopped)") from None
    if run.returncode < 0:
        raise RigFileError(path, f"expected an FBX file the reader (ufbx) survives, got one "
                                 f"that crashed it (signal {-run.returncode})")
    try:
        result = pickle.loads(run.stdout)
    except Exception:
        last = (run.stderr.decode("utf-8", "replace").strip().splitlines() or ["no message"])[-1]
        raise RigFileError(path, f"expected the FBX reader's result, got none (exit status "
                                 f"{run.returncode}: {last})") from None
    result, caught = result
    for category, message in caught:   # the reader's warnings, as if it had run here
        warnings.warn(message, category, stacklevel=2)
    if isinstance(result, BaseException):
        raise result
    return result


def _child(path):
    import gc

    gc.disable()   # the binding's crash is in the collector; the child exits before it matters
    from .fbx_read import read_fbx as read_here

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = read_here(path)
        except RigFileError as exc:
            result = RigFileError(exc.path, exc.problem)
    warned = [(w.category, str(w.message)) for w in caught]
    out = sys.stdout.buffer
    out.write(pickle.dumps((result, warned), protocol=pickle.HIGHEST_PROTOCOL))
    out.flush()
    # skip the interpreter's teardown (it would free the binding's objects after all)
    os._exit(0)


if __name__ == "__main__":
    _child(sys.argv[1])
