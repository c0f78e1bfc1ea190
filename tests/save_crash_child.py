"""Helper process for the crash tests of whole-folder saves (tests/test_save.py).

Run as ``python save_crash_child.py FOLDER``: it builds the two rig states A and B once, prints
``ready`` and then reads commands on stdin, one per line, answering one line each:

``loop``
    fork a child that saves A, B, A, B, ... into FOLDER for ever; answer its pid (the test
    kills it with SIGKILL at a random moment).
``crash STATE N``
    fork a child that saves STATE (``A`` or ``B``) and exits abruptly (``os._exit``, no clean
    up) just before its N-th file-system operation; answer ``crashed`` or ``completed``.
``reap PID``
    wait for a killed child; answer ``reaped``.

Forking from this single-threaded process (BLAS pinned to one thread) makes each saving
process start in about a millisecond, so the test can kill many of them quickly.
"""
from __future__ import annotations

import os
import sys
import traceback

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from rigedit.animation import Clip, Track  # noqa: E402
from rigedit.model import Skeleton  # noqa: E402
from rigedit.model.transforms import euler_to_quat  # noqa: E402
from rigedit.rig import Rig  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from builders import cylinder  # noqa: E402

#: File-system calls counted (and interrupted) by ``crash``.
OPERATIONS = ("open", "replace", "rename", "unlink", "rmdir", "mkdir", "fsync")


def rig_state(which, rings=9, segments=8):
    """Rig state ``"A"`` or ``"B"``: same topology, but different vertices, bone lengths,
    weights and clip sets (A: bend, wave; B: bend with other keys, twist), so any mix of the
    two states' files differs from both. ``rings`` x ``segments``: the cylinder's size."""
    b = which == "B"
    t = np.zeros((3, 3))
    t[1:, 1] = 1.2 if b else 1.0
    tails = np.full((3, 3), np.nan)
    tails[-1] = [0.0, 3.6 if b else 3.0, 0.0]
    sk = Skeleton(["j0", "j1", "j2"], [-1, 0, 1], t, tails=tails)
    v, f = cylinder(radius=0.35 if b else 0.3, height=3.6 if b else 3.0, rings=rings,
                    segments=segments)
    rig = Rig(sk, v, f, name="state " + which)
    if b:   # weights that no rest pose would give: the influences squared and renormalised
        w = rig.binding.weights.astype(float) ** 2
        rig.bind(rig.binding.indices, w / w.sum(axis=1, keepdims=True))
    angle = 75 if b else 40
    q = euler_to_quat([[0, 0, 0], [0, 0, angle], [0, 0, 0]], degrees=True)
    clips = {"bend": Clip("bend", sk, {("j1", "rotation"): Track("rotation", [0, .5, 1], q)})}
    second = "twist" if b else "wave"
    q2 = euler_to_quat([[0, 0, 0], [0, 30, 0], [0, 0, 0]], degrees=True)
    clips[second] = Clip(second, sk, {("j2", "rotation"): Track("rotation", [0, 1, 2], q2)},
                         loop=not b)
    rig.clips = clips
    return rig


def _count_operations(limit):
    """Make the ``limit``-th file-system call of this process exit it on the spot."""
    count = [0]

    def wrap(fn):
        def counted(*args, **kwargs):
            count[0] += 1
            if count[0] >= limit:
                os._exit(7)
            return fn(*args, **kwargs)
        return counted

    for name in OPERATIONS:
        setattr(os, name, wrap(getattr(os, name)))


def _fork(work):
    """Run ``work()`` in a child process; the child never returns into the command loop."""
    pid = os.fork()
    if pid == 0:
        try:
            work()
            os._exit(0)
        except BaseException:
            traceback.print_exc()
            os._exit(1)
    return pid


def main(folder):
    from rigedit.io.rig_folder import save_rig_folder

    states = {"A": rig_state("A"), "B": rig_state("B")}
    print("ready", flush=True)
    for line in sys.stdin:
        cmd = line.split()
        if cmd[0] == "loop":
            def alternate():
                while True:
                    save_rig_folder(folder, states["A"])
                    save_rig_folder(folder, states["B"])

            pid = _fork(alternate)
            print(pid, flush=True)
        elif cmd[0] == "crash":
            pid = _fork(lambda: (_count_operations(int(cmd[2])),
                                 save_rig_folder(folder, states[cmd[1]])))
            _, status = os.waitpid(pid, 0)
            print({7: "crashed", 0: "completed"}.get(os.waitstatus_to_exitcode(status),
                                                     "failed"), flush=True)
        elif cmd[0] == "reap":
            os.waitpid(int(cmd[1]), 0)
            print("reaped", flush=True)


if __name__ == "__main__":
    main(sys.argv[1])
