"""Autosave and recovery in the editor, as Blender does: the document is written to a
recovery entry in the user's cache folder every few minutes when it changed, and at once on
an unexpected error or a termination signal; the next start offers to recover what an
editor that is no longer running left behind. Where and how entries are written is
:mod:`rigedit.editor.recovery` (pure); this module holds the timer, the signals and the dialog.

The interval is ``RIGEDIT_AUTOSAVE_SECONDS`` (default 120; 0 turns the timer off, the
crash and signal saves stay). The timer's writes run in a thread (a bundled character's
folder takes seconds to write, mostly the OBJ text: ``benchmarks/bench_autosave.py``); the
UI thread only copies the clips and the pose. Crash and signal saves write at once, after
any write under way.
"""
from __future__ import annotations

import copy
import os
import signal
import socket
import threading

from PyQt5 import QtCore, QtWidgets

from ..editor import events as ev, recovery
from ..errors import RigFileError
from . import errors_hook

__all__ = ["Autosave", "DEFAULT_INTERVAL", "offer_recovery", "ask_recover", "recover",
           "install_signal_handlers", "ask_save_changes", "confirm_unsaved_changes"]

DEFAULT_INTERVAL = 120.0  # seconds (Blender's default is 2 minutes too)


def _interval_from_env():
    text = os.environ.get("RIGEDIT_AUTOSAVE_SECONDS", "")
    try:
        value = float(text) if text else DEFAULT_INTERVAL
    except ValueError:
        value = DEFAULT_INTERVAL
    return value if value >= 0 and value == value else DEFAULT_INTERVAL


class Autosave(QtCore.QObject):
    """Writes the document to this editor's recovery entry.

    Parameters
    ----------
    parent : QObject
        Owns the timer (the window).
    document : Document
    status : callable
        ``status(text)``: a failed write is said there.
    error : callable
        ``error(title, message)``: a recovery that cannot be done.
    interacting : callable, optional
        ``interacting()`` is True while a gizmo drag is held (no write then).
    interval : float, optional
        Seconds between checks (``RIGEDIT_AUTOSAVE_SECONDS`` or 120 by default; 0: no
        timer).

    Attributes
    ----------
    folder : Path
        This editor's recovery entry folder.
    writes : int
        Snapshots written so far.
    """

    # (generation, revision written, error message or None, the thread), from the writer thread
    _written_in_thread = QtCore.pyqtSignal(int, int, object, object)

    _windows = 0

    def __init__(self, parent, document, status, error, interacting=lambda: False,
                 interval=None):
        super().__init__(parent)
        self.document = document
        self.status = status
        self.error = error
        self.interacting = interacting
        Autosave._windows += 1  # each window of a process has its own entry
        self.folder = recovery.entry_folder(window=Autosave._windows)
        self.writes = 0
        self._written = None  # undo-stack revision of the last snapshot
        self._lock = threading.Lock()  # one writer of the entry folder at a time
        self._thread = None
        self._generation = 0  # a discard makes the results of earlier writes stale
        self._written_in_thread.connect(self._thread_signalled)
        self.timer = QtCore.QTimer(self)
        self.timer.timeout.connect(self.tick)
        document.listen(self._on_event)
        self.set_interval(_interval_from_env() if interval is None else interval)

    def set_interval(self, seconds):
        self.interval = float(seconds)
        self.timer.stop()
        if self.interval > 0:
            self.timer.start(int(round(self.interval * 1000)))

    def _on_event(self, event):
        # Saved, or undone back to the saved state: nothing to recover any more.
        if isinstance(event, ev.UndoChanged) and not self.document.modified and self.folder.exists():
            self.discard()

    def tick(self):
        """The timer's check: write when the document changed; wait while a drag is under
        way (its intermediate pose is not an edit yet)."""
        if self.document.dragging or self.interacting():
            return False
        return self.save(background=True)

    @property
    def busy(self):
        """Whether a write runs in the background."""
        return self._thread is not None and self._thread.is_alive()

    def save(self, force=False, background=False):
        """Write a snapshot if the document has unsaved changes made since the last one
        (``force``: even when none were made since). A document without unsaved changes
        needs no recovery: its entry is removed.

        With ``background`` the writing runs in a thread (skipped while one runs) and
        :attr:`writes` counts it when it is done. Returns whether a snapshot was written
        (or, in the background, started)."""
        doc = self.document
        if not doc.modified:
            self.discard()
            return False
        revision = doc.undo_stack.revision
        if not force and revision == self._written or background and self.busy:
            return False
        # What the thread writes must not change under it: the clips are edited in place,
        # the rest (skeleton, binding, vertices) is replaced on edit, never changed.
        rig = copy.copy(doc.rig)
        rig.clips = {name: clip.copy() for name, clip in doc.rig.clips.items()}
        args = (rig, doc.pose_snapshot(), doc.current_clip, doc.time, doc.rig.path)
        if background:
            self._thread = threading.Thread(target=self._write_in_thread,
                                            args=(self._generation, revision, args),
                                            daemon=True)
            self._thread.start()
            return True
        error = self._write(args)
        self._thread_done(self._generation, revision, error)
        return error is None

    def _write(self, args):
        rig, pose, clip, time, path = args
        try:
            with self._lock:
                recovery.write_entry(rig, pose, clip, time, original_path=path,
                                     folder=self.folder)
        except (OSError, ValueError) as exc:
            errors_hook.logger().error("autosave to %s failed: %s", self.folder, exc)
            return str(exc)
        return None

    def _write_in_thread(self, generation, revision, args):
        try:
            error = self._write(args)
        except Exception as exc:  # noqa: BLE001 - logged and shown, never a silent thread death
            errors_hook.logger().error("autosave failed", exc_info=True)
            error = f"{type(exc).__name__}: {exc}"
        self._written_in_thread.emit(generation, revision, error, threading.current_thread())

    def _thread_signalled(self, generation, revision, error, thread):
        # The signal is the thread's last act, but it may arrive before the thread has ended:
        # :attr:`busy` must not count it (else a save made during the write left its entry behind).
        thread.join()
        self._thread_done(generation, revision, error)

    def _thread_done(self, generation, revision, error):
        if generation != self._generation:  # discarded while it wrote
            if not self.document.modified and not self.busy:
                recovery.remove_entry(self.folder)
            return
        if error is not None:
            self.status(f"Autosave failed: {error}")
            return
        self._written = revision
        self.writes += 1

    @property
    def holds_work(self):
        """Whether the entry holds the document's unsaved changes up to the last edit."""
        doc = self.document
        return doc.modified and self._written == doc.undo_stack.revision

    def crash_save(self):
        """Save for recovery after an unexpected error or on a signal, unless the entry
        already holds the last edit (a callback failing at each mouse move must not write
        each time). Returns :attr:`holds_work`; never raises."""
        try:
            self.save()
            return self.holds_work
        except Exception:  # noqa: BLE001 - called while handling a failure already
            errors_hook.logger().error("recovery save failed", exc_info=True)
            return False

    def discard(self, wait=False):
        """Remove this editor's recovery entry (a clean close, or nothing left unsaved).
        A write under way is not waited for (its end removes what it wrote) unless
        ``wait`` (on close, when nothing would be left to remove it)."""
        self._generation += 1
        self._written = None
        if self.busy:
            if not wait:
                return
            self._thread.join()
        with self._lock:
            if self.folder.exists():
                recovery.remove_entry(self.folder)

    def stop(self):
        self.timer.stop()

    # ------------------------------------------------------------------ recovery at start
    def offer_recovery(self, ask=None):
        """Offer each entry left by an editor that no longer runs, newest first. The first
        one recovered replaces the document (the rest stay for a later start).

        Parameters
        ----------
        ask : callable, optional
            ``ask(parent, entry) -> "recover" | "discard" | "later"`` (:func:`ask_recover`).

        Returns
        -------
        RecoveryEntry or None
            The entry recovered.
        """
        ask = ask or ask_recover
        for entry in recovery.stale_entries():
            choice = ask(self.parent(), entry)
            if choice == "discard":
                recovery.remove_entry(entry.folder)
            elif choice == "recover" and self.recover(entry):
                return entry
        return None

    def recover(self, entry):
        """Open a recovery entry as an unsaved document (its Save goes to the original
        folder; Save As when there was none or it was a bundled character). The entry is
        removed once this editor's own recovery snapshot holds the work. Returns success."""
        doc = self.document
        if doc.modified:  # never replace unsaved work with other unsaved work
            self.error("Recover", f"save or discard the changes to {doc.rig.name} first, "
                                  f"then recover {entry.describe()}")
            return False
        try:
            rig, pose, clip, time = recovery.read_entry(entry)
        except (RigFileError, ValueError, OSError) as exc:
            self.error("Recover", f"cannot recover {entry.describe()}: {exc}")
            return False
        doc.set_rig(rig, modified=True)
        doc.set_current_clip(clip)
        doc.set_time(time)
        doc.set_pose(pose)
        if self.save(force=True):
            recovery.remove_entry(entry.folder)
        self.status(f"Recovered {entry.describe()}; save it to keep it")
        return True


# ---------------------------------------------------------------------- recovery at start
def ask_recover(parent, entry):
    """Ask what to do with a recovery entry: "recover", "discard" or "later"."""
    box = QtWidgets.QMessageBox(parent)
    box.setIcon(QtWidgets.QMessageBox.Question)
    box.setWindowTitle("Recover unsaved work")
    box.setText("An editor that is no longer running left unsaved work:")
    box.setInformativeText(f"{entry.describe()}\n\nRecover it now, discard it, or decide "
                           "the next time rigedit starts?")
    recover_button = box.addButton("Recover", QtWidgets.QMessageBox.AcceptRole)
    discard_button = box.addButton("Discard", QtWidgets.QMessageBox.DestructiveRole)
    box.addButton("Later", QtWidgets.QMessageBox.RejectRole)
    box.setDefaultButton(recover_button)
    box.exec_()
    clicked = box.clickedButton()
    return "recover" if clicked is recover_button else \
        "discard" if clicked is discard_button else "later"


def offer_recovery(window, ask=None):
    """:meth:`Autosave.offer_recovery` of ``window``'s autosave."""
    return window.autosave.offer_recovery(ask)


def recover(window, entry):
    """:meth:`Autosave.recover` of ``window``'s autosave."""
    return window.autosave.recover(entry)


# ---------------------------------------------------------------------- closing
def ask_save_changes(parent, name, action="closing"):
    """Ask about the unsaved changes to ``name`` before ``action`` ("closing", "opening
    another rig", ...): "save", "discard" or "cancel"."""
    box = QtWidgets.QMessageBox(parent)
    box.setIcon(QtWidgets.QMessageBox.Warning)
    box.setWindowTitle("Unsaved changes")
    box.setText(f"Save the changes to {name} before {action}?")
    box.setInformativeText(f"{action[:1].upper()}{action[1:]} without saving loses them "
                           "(no recovery file is kept).")
    box.setStandardButtons(QtWidgets.QMessageBox.Save | QtWidgets.QMessageBox.Discard
                           | QtWidgets.QMessageBox.Cancel)
    box.setDefaultButton(QtWidgets.QMessageBox.Save)
    answer = box.exec_()
    return {QtWidgets.QMessageBox.Save: "save",
            QtWidgets.QMessageBox.Discard: "discard"}.get(answer, "cancel")


def confirm_unsaved_changes(parent, document, save, ask=None, action="closing"):
    """Whether the window may close (or its document be replaced: ``action`` says by what,
    e.g. "opening another rig"): no unsaved changes, or the user discarded them, or they
    were saved by ``save()`` (File > Save; Save As when there is no folder to save to).
    ``ask(parent, name, action=...)`` is :func:`ask_save_changes` by default."""
    if not document.modified:
        return True
    choice = (ask or ask_save_changes)(parent, document.rig.name, action=action)
    if choice == "save":
        return bool(save()) and not document.modified
    return choice == "discard"


# ---------------------------------------------------------------------- signals
_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGINT", "SIGHUP")
                 if hasattr(signal, name))  # no SIGHUP on Windows


def install_signal_handlers(app, autosave, keep_recovery, signals=_SIGNALS):
    """On a termination signal, write the recovery snapshot with ``autosave`` and quit with
    status 128 + signal; ``keep_recovery()`` is called first so that closing keeps the entry
    (the next start offers it).

    Python runs signal handlers only between bytecodes, and a Qt event loop may wait in C
    for a long time: ``signal.set_wakeup_fd`` writes to a socket that a QSocketNotifier
    watches, so the handler runs at once. Returns the notifier (keep it alive).
    """
    rsock, wsock = socket.socketpair()
    for s in (rsock, wsock):
        s.setblocking(False)
    signal.set_wakeup_fd(wsock.fileno())
    notifier = QtCore.QSocketNotifier(rsock.fileno(), QtCore.QSocketNotifier.Read, app)

    def drain():
        try:
            rsock.recv(64)
        except OSError:
            pass

    notifier.activated.connect(drain)
    notifier._sockets = (rsock, wsock)

    def on_signal(signum, _frame):
        name = signal.Signals(signum).name
        errors_hook.logger().warning("%s received: writing the recovery snapshot", name)
        autosave.crash_save()
        autosave.stop()
        keep_recovery()
        app.exit(128 + signum)

    for s in signals:
        signal.signal(s, on_signal)
    return notifier
