"""Auto-rig a mesh into the document: the slow half (:func:`rigedit.autorig`, safe in a
worker) and the quick half that opens the result as a new, unsaved character in bind (edit)
mode with the first joint in doubt selected, and says what the auto-rigger decided. The
File menu's dialog (:class:`~rigedit.ui.autorig_dialog.AutorigAction`) runs them; no Qt here.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["autorig_mesh", "reembed_mesh", "open_autorigged", "describe_report"]


def autorig_mesh(mesh, template="humanoid", up=None, forward=None, progress=None):
    """The rig :func:`rigedit.autorig` makes of the mesh file ``mesh`` (the slow half).

    Parameters
    ----------
    mesh : str or Path
    template : str or Path
        ``"humanoid"``, ``"quadruped"`` or a skeleton file.
    up, forward : str, optional
        ``"y"``, ``"-z"``, ...; guessed when None.
    progress : callable, optional
        ``progress(fraction, stage)`` (:mod:`rigedit.progress`); its ``Cancelled`` stops
        the work.

    Returns
    -------
    Rig
        ``rig.meta.autorig_report`` says what was decided.
    """
    import rigedit   # looked up at the call: scripts and tests may stand in for it

    if progress is not None:
        progress(0.0)
    return rigedit.autorig(str(mesh), template=template, up=up, forward=forward,
                           progress=progress)


def reembed_mesh(vertices, faces, template, weights, clips, hints, progress=None):
    """The rig :func:`rigedit.autorig` makes of a character's own mesh again with ``hints``
    pinned (File > Re-embed around the joints I moved; the slow half).

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int
        The character's mesh, standing +Y up and facing +Z already (no orientation to guess).
    template : str or Path
    weights : {"heat", "idw"}
    clips : bool
        Give it the template's clips.
    hints : dict[str, (3,) float]
        Joint name -> its position in the mesh's coordinates.
    progress : callable, optional
        ``progress(fraction)``: the stage names are not passed on.

    Returns
    -------
    Rig
    """
    import rigedit   # looked up at the call: scripts and tests may stand in for it

    if progress is not None:
        progress(0.0)
    report = (lambda f, stage=None: progress(f)) if progress is not None else None
    return rigedit.autorig((vertices, faces), template=template, up="y", forward="z",
                           weights=weights, clips=clips, hints=hints, progress=report)


def open_autorigged(document, rig, mesh):
    """Make ``rig`` (auto-rigged from the file ``mesh``) the document: new and unsaved (no
    folder: Save asks where; named after the mesh when it has no name), in edit mode, the
    first joint in doubt selected, ready to drag.

    Returns
    -------
    str
        For the status bar: what the auto-rigger decided (:func:`describe_report`).
    """
    mesh = Path(mesh)
    rig.path = None
    if not rig.name:
        rig.name = mesh.stem
    document.set_rig(rig, modified=True)
    document.set_mode("edit")   # the window follows the mode event
    report = rig.meta.autorig_report
    doubtful = [n for n in getattr(report, "doubtful", []) if n in rig.skeleton.index]
    if doubtful:   # the status bar says why
        document.select(rig.skeleton.index[doubtful[0]])
    about = describe_report(report)
    # short enough for the status bar beside the mode label; counts are in Info
    return f"Auto-rigged {mesh.name}" + (f": {about}" if about else "") + \
        "; drag joints to fix them"


def describe_report(report):
    """One line for the status bar from ``rig.meta.autorig_report``
    (:class:`rigedit.rigging.autorig.pipeline.AutorigReport`): NOT SURE and the first reason
    when a check failed, the orientation used and whether it was guessed (and sure), the
    template clips that came along, and each stage's time.

    Returns
    -------
    str
    """
    if report is None:
        return ""
    # imported here: the auto-rigger's package is loaded once it is used, not at start-up
    from ..rigging.autorig.orient import axis_name

    o = report.orientation
    how = "given" if not o.guessed else ("guessed" if o.sure else
                                         "guessed, NOT SURE: check it, or choose Up and "
                                         "Forward in the dialog")
    parts = [f"up {axis_name(o.up)}, forward {axis_name(o.forward)} ({how})"]
    reasons = getattr(report, "reasons", [])
    if not getattr(report, "sure", True) and reasons:
        # the first reason in full (the joints in doubt are selected), the count of others
        parts.insert(0, f"NOT SURE: {reasons[0]}"
                     + (f" (and {len(reasons) - 1} more)" if len(reasons) > 1 else ""))
    left_out = [name for name, how in report.clips.items() if how != "retargeted"]
    if left_out:
        parts.append(f"clips left out: {', '.join(left_out)}")
    seconds = report.seconds
    # the embedding's own stages ("embedding/search") are inside its total: top level only
    top = {k: v for k, v in seconds.items()
           if not k.startswith("embedding/") and k != "total"}
    if top:
        total = seconds.get("total", sum(top.values()))
        parts.append(f"{total:.1f} s (" + ", ".join(f"{k} {v:.1f} s" for k, v in top.items())
                     + ")")
    return "; ".join(parts)
