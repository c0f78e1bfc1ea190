"""View > Compare compressed: the current clip compressed, played over the original.

A thin second skeleton (:class:`~rigedit.render.compare_overlay.CompareOverlay`) stands at
the compressed pose, each joint coloured by its error at the time shown (green 0, yellow half
the bound, red the bound), with the figures in the view's corner. The compression
(:class:`~rigedit.editor.compression.CompressedPreview`) runs as a job when the comparison is
turned on and again after a clip edit, a clip change, a rest edit or a new rig; meanwhile the
overlay is hidden and the status bar says why.
"""
from __future__ import annotations

from PyQt5 import QtCore

from ..editor import events as ev
from ..editor.compression import CompressedPreview
from ..render.compare_overlay import CompareOverlay
from .menus import make_action

__all__ = ["CompareCompressed", "RETRY_MS"]

#: Wait before trying again when another job holds the runner.
RETRY_MS = 400
_RECOMPRESS = (ev.KeysChanged, ev.ClipChanged, ev.RestChanged, ev.RigReplaced)


class CompareCompressed:
    """The comparison's action, its preview and its overlay.

    Parameters
    ----------
    document : Document
    view : SceneView
        Its ``plotter`` and joint sphere ``radius``.
    services : Services
    settings : CompressionSettings
        The bound and shell (File > Export compressed's last values).

    Attributes
    ----------
    action : QAction
        Checkable.
    preview : CompressedPreview or None
    overlay : CompareOverlay or None
        Shown while on and up to date.
    job : Job or None
        The compression running for the comparison.
    """

    def __init__(self, document, view, services, settings):
        self.document = document
        self.view = view
        self.services = services
        self.settings = settings
        self.preview = self.overlay = self.job = None
        self._waiting = False
        self.action = make_action(services.parent, "Compare compressed", self.set_enabled,
                                  checkable=True,
                                  tip="Play the clip compressed (File > Export compressed's "
                                      "bound) over the original, joints coloured by error")
        document.listen(self._on_event)

    def actions(self):
        """name -> QAction for :func:`.menus.build_menus`."""
        return {"compare_compressed": self.action}

    @property
    def enabled(self):
        return self.action.isChecked()

    # ------------------------------------------------------------------ on and off
    def set_enabled(self, on):
        """Turn the comparison on (compressing the current clip in a job) or off."""
        if self.action.isChecked() != bool(on):
            self.action.setChecked(bool(on))   # calls back here through ``toggled``
            return
        if not on:
            self._drop_overlay()
            self.preview = None
            self.services.status("Compare compressed: off")
            self.services.request_render()
            return
        if self.document.clip is None:
            self.action.setChecked(False)
            self.services.status("Compare compressed: no clip to compare (open or create "
                                 "a clip first)")
            return
        s = self.settings
        self.preview = CompressedPreview(self.document, s.max_error, s.shell)
        self._recompress("Compressing the clip to compare")

    def _recompress(self, why):
        """Compress the current clip again in a job (once the runner is free)."""
        preview = self.preview
        if preview is None or not self.enabled:
            return
        if self.document.clip is None:
            self._drop_overlay()
            self.services.status("Compare compressed: no clip to compare")
            return
        try:
            snapshot = preview.snapshot()
        except ValueError as exc:
            self.action.setChecked(False)
            self.services.error("Compare compressed", str(exc))
            return
        if self.services.jobs.current() is not None:
            if not self._waiting:   # one retry queued at a time
                self._waiting = True
                QtCore.QTimer.singleShot(RETRY_MS, lambda: self._retry(why))
            self.services.status(f"Compare compressed: waiting for "
                                 f"'{self.services.jobs.current().label}'")
            return
        self._hide()
        self.job = self.services.run_job(
            f"{why}", lambda report: preview.compute(snapshot, report),
            lambda entry: self._compressed(preview, entry), self._stopped)

    def _retry(self, why):
        self._waiting = False
        if self.preview is not None and self.preview.stale:
            self._recompress(why)

    def _compressed(self, preview, entry):
        self.job = None
        if preview is not self.preview:
            return   # turned off, or on again with other settings, meanwhile
        if not preview.accept(entry):   # the clip changed while it compressed
            self._recompress("The clip changed: compressing it again to compare")
            return
        self._show()
        self.services.status(f"Compare compressed ({self.document.current_clip}): "
                             f"{preview.summary()}; green 0, yellow "
                             f"{self.settings.max_error_cm / 2:g} cm, red "
                             f"{self.settings.max_error_cm:g} cm")

    def _stopped(self):
        self.job = None
        if self.preview is not None and self.preview.entry is None:
            self.action.setChecked(False)

    # ------------------------------------------------------------------ the overlay
    def _drop_overlay(self):
        if self.overlay is not None:
            self.overlay.remove()
            self.overlay = None

    def _hide(self):
        if self.overlay is not None:
            self.overlay.set_visible(False)

    def _show(self):
        """The overlay at the document's time, made for the preview's skeleton."""
        preview = self.preview
        positions, errors = preview.at(self.document.time)
        skeleton = preview.entry.compressed.skeleton
        if (self.overlay is None or len(self.overlay.positions) != len(skeleton)
                or self.overlay.bound != preview.max_error):
            self._drop_overlay()
            self.overlay = CompareOverlay(self.view.plotter, positions, skeleton.parents,
                                          errors, preview.max_error, self.view.radius,
                                          self.view.scene.carriers)
        self.overlay.set_visible(self.document.mode == "pose")
        self._draw(positions, errors)

    def _draw(self, positions, errors):
        self.overlay.update(positions, errors)
        self.overlay.set_text(self.preview.summary(errors))
        self.services.request_render()

    def refresh(self):
        """Draw the compressed pose at the document's time (when on and up to date)."""
        p = self.preview
        if self.overlay is None or p is None or p.entry is None or p.stale:
            return
        self._draw(*p.at(self.document.time))

    def _on_event(self, event):
        if self.preview is None:
            return
        if isinstance(event, ev.RigReplaced):
            self._drop_overlay()   # the view was rebuilt: a new skeleton, maybe no clip
        if isinstance(event, _RECOMPRESS):
            if self.preview.stale:
                self._recompress("The clip changed: compressing it again to compare")
        elif isinstance(event, ev.TimeChanged):
            self.refresh()
        elif isinstance(event, ev.ModeChanged) and self.overlay is not None:
            self.overlay.set_visible(event.mode == "pose")   # edit mode shows the rest
