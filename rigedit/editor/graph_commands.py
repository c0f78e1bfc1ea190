"""The graph editor's model: the current clip's channels as curves, and their edits as undo
steps (no Qt; the dock in ``rigedit.ui`` draws and drives these).

A channel is one axis of one channel of one joint (:class:`ChannelId`). :func:`channels` shows
each as a :class:`ChannelView` whose curve is the track's own when the track is a bezier track,
else the track converted (:func:`~rigedit.animation.curve_track.curves_from_track`: rotations
as continuous Euler angles in degrees, ``XYZ``). Every edit goes through :func:`edit_curves`:
the touched tracks become bezier tracks (their untouched axes converted) in one undo step
(:func:`~.clip_edits.edit_clip`), which samples the pose again and announces KeysChanged, so
the 3D view and the timeline follow. :class:`CurveDrag` shows a drag live and records one step
at its end, as the timeline's :class:`~.key_commands.KeyDrag` does.

Whole-clip interpolation modes (``Clip.set_interpolation``, the timeline's menu) still apply to
bezier tracks: the track becomes a plain track of that mode keyed at the union of its curves'
key times, with the values the curves had there (the handles are dropped).
"""
from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from ..animation.curve import Curve
from ..animation.curve_track import curves_from_track
from ..animation.euler_curves import DEFAULT_ORDER, quat_to_euler
from ..animation.track import Track
from .clip_edits import edit_clip
from .events import KeysChanged

__all__ = ["ChannelId", "ChannelView", "channels", "channel_curve", "edit_curves",
           "CurveDrag", "moved_keys", "insert_keys", "delete_keys", "set_interpolation",
           "set_handle_type", "set_easing", "CHANNEL_KINDS", "AXES"]

CHANNEL_KINDS = ("translation", "rotation", "scale")
AXES = "XYZ"
#: (r, g, b) per channel kind and axis: X red, Y green, Z blue; rotation full, translation
#: lighter, scale darker, so the three kinds of one axis stay apart.
COLOURS = {
    "rotation": ((0.90, 0.20, 0.20), (0.25, 0.80, 0.25), (0.25, 0.45, 0.95)),
    "translation": ((1.00, 0.60, 0.55), (0.65, 0.95, 0.55), (0.55, 0.75, 1.00)),
    "scale": ((0.60, 0.10, 0.15), (0.10, 0.50, 0.15), (0.10, 0.20, 0.60)),
}


@dataclass(frozen=True)
class ChannelId:
    """One axis of one channel of one joint."""

    joint: str
    channel: str   # "translation" | "rotation" | "scale"
    axis: int      # 0, 1, 2 (X, Y, Z)


# conversions of plain tracks for display, by track identity (tracks are immutable); bounded
_CONVERTED = OrderedDict()
_CONVERTED_MAX = 512


def _track_curves(track):
    """The three curves of a track, converted once per track object."""
    if track.curves is not None:
        return track.curves
    hit = _CONVERTED.get(id(track))
    if hit is not None and hit[0] is track:
        _CONVERTED.move_to_end(id(track))
        return hit[1]
    curves = curves_from_track(track, DEFAULT_ORDER)
    _CONVERTED[id(track)] = (track, curves)
    if len(_CONVERTED) > _CONVERTED_MAX:
        _CONVERTED.popitem(last=False)
    return curves


@dataclass
class ChannelView:
    """What the graph editor shows of one channel.

    ``curve`` is None when the joint has no track for this channel; ``bezier`` tells whether
    the track is already a bezier track (else the curve is the track converted, and what it
    plays between keys may differ: :meth:`sample` gives what it plays).
    """

    id: ChannelId
    label: str
    colour: tuple
    curve: "Curve | None"
    bezier: bool
    track: "Track | None" = None

    def sample(self, times):
        """(N,) what the channel plays at clip times ``times`` (degrees for rotation; the
        curve's values clamped to its keys; NaN without a track)."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        if self.track is None:
            return np.full(len(times), np.nan)
        if self.bezier:
            return self.curve.sample(times)
        values = self.track.sample_many(times)
        if self.id.channel == "rotation":
            ref = _track_curves(self.track)
            values = quat_to_euler(values, DEFAULT_ORDER, [c.sample(times[0]) for c in ref])
        return values[:, self.id.axis]


def channels(document, joints):
    """The channel views of ``joints`` (names or indices) in the current clip: per joint its
    translation, rotation and scale, X, Y, Z; [] without a clip."""
    clip = document.clip
    if clip is None:
        return []
    sk = document.skeleton
    out = []
    for j in joints:
        name = sk.names[sk.joint_index(j)]
        for kind in CHANNEL_KINDS:
            track = clip.tracks.get((name, kind))
            curves = None if track is None else _track_curves(track)
            for a in range(3):
                out.append(ChannelView(ChannelId(name, kind, a), f"{name} {kind} {AXES[a]}",
                                       COLOURS[kind][a], None if curves is None else curves[a],
                                       track is not None and track.curves is not None, track))
    return out


def channel_curve(clip, cid):
    """The curve of channel ``cid`` in ``clip`` (converted when not bezier), or None."""
    track = clip.tracks.get((cid.joint, cid.channel))
    return None if track is None else _track_curves(track)[cid.axis]


def _rest_values(skeleton, joint, channel):
    """(3,) the joint's rest value of a channel as curve values (Euler degrees)."""
    rest = getattr(skeleton, f"rest_{channel}")[skeleton.joint_index(joint)]
    return quat_to_euler(rest[None], DEFAULT_ORDER)[0] if channel == "rotation" else rest


def _apply(clip, curves):
    """Set the tracks of ``curves`` (``{ChannelId: Curve or None}``) in ``clip``: a None axis
    lost its keys (holding its value at the others' first key; the track goes when all three
    did). Returns the number of tracks changed."""
    groups, changed = {}, 0
    for cid, curve in curves.items():
        groups.setdefault((cid.joint, cid.channel), {})[cid.axis] = curve
    for (joint, channel), axes in groups.items():
        track = clip.tracks.get((joint, channel))
        if track is None:
            given = [c for c in axes.values() if c is not None]
            if not given:
                continue
            t0 = min(c.times[0] for c in given)
            rest = _rest_values(clip.skeleton, joint, channel)
            base = [Curve([t0], [v]) for v in rest]
        else:
            base = list(_track_curves(track))
        old = list(base)
        for a, c in axes.items():
            base[a] = c
        if all(c is None for c in base):
            clip.remove_track(joint, channel)
            continue
        t0 = min(c.times[0] for c in base if c is not None)
        base = [Curve([t0], [o.sample(t0)]) if c is None else c for c, o in zip(base, old)]
        if track is not None and track.curves is not None and all(
                a == b for a, b in zip(base, track.curves)):
            continue   # the same curves: the track stays (an edit that changed nothing)
        order = (track.euler_order if track is not None and track.euler_order
                 else DEFAULT_ORDER)
        clip.set_track(joint, channel, Track.from_curves(channel, base, order))
        changed += 1
    return changed


def edit_curves(document, curves, label):
    """Set channels' curves (``{ChannelId: Curve}``) in the current clip as ONE undo step;
    each touched track becomes a bezier track. Returns the number of tracks changed (0
    without a clip or when nothing changed)."""
    if document.clip is None or not curves:
        return 0
    return edit_clip(document, label, lambda c: _apply(c, curves)) or 0


class CurveDrag:
    """A live drag of curves: many :meth:`update`, one undo step at :meth:`finish`.

    Parameters
    ----------
    document : Document
        Its current clip is edited.
    label : str
        The undo step's text.
    """

    def __init__(self, document, label):
        self.document, self.label = document, label
        self.clip = document.clip
        self.before = None if self.clip is None else self.clip.state()
        self.after = None
        self.changed = 0   # tracks the last update changed

    def update(self, curves):
        """Show ``curves`` (``{ChannelId: Curve}``, each the whole curve as dragged so far):
        the clip is updated and the pose sampled again, no undo step."""
        if self.clip is None:
            return
        self.clip.restore(self.before)
        self.changed = _apply(self.clip, curves)
        self.after = self.clip.state()
        self.document.clip_changed(KeysChanged(self.clip.name), True)

    def finish(self):
        """One undo step for the drag (none when nothing changed or the clip is no longer the
        current one). Returns whether a step was recorded."""
        if self.clip is None or self.after is None:
            return False
        after, self.after = self.after, None
        self.clip.restore(self.before)
        if self.changed == 0 or self.clip is not self.document.clip:
            self.document.clip_changed(KeysChanged(self.clip.name), True)
            return False
        edit_clip(self.document, self.label, lambda c: c.restore(after), clip=self.clip)
        return True

    def cancel(self):
        """Back to before the drag, no undo step."""
        if self.clip is None:
            return
        self.after = None
        self.clip.restore(self.before)
        self.document.clip_changed(KeysChanged(self.clip.name), True)


def moved_keys(base, dt, dv):
    """Selected keys of several channels moved together: ``base`` is ``{ChannelId: (Curve,
    key indices)}``; every curve's keys move by the same time offset, ``dt`` clamped to the
    range of every curve (:meth:`~rigedit.animation.curve.Curve.shift_range`), and ``dv``
    units. Clamping each curve alone would split keys of one time when one curve has a
    neighbour in the way (two keys in the timeline where there was one).

    Returns
    -------
    dict
        ChannelId -> the moved Curve.
    """
    low, high = -np.inf, np.inf
    for curve, idx in base.values():
        a, b = curve.shift_range(idx)
        low, high = max(low, a), min(high, b)
    dt = float(np.clip(dt, min(low, 0.0), max(high, 0.0)))
    return {cid: curve.with_keys_moved(idx, dt, dv) for cid, (curve, idx) in base.items()}


def _views(document, ids):
    clip = document.clip
    return {} if clip is None else {cid: channel_curve(clip, cid) for cid in ids}


def insert_keys(document, ids, t):
    """A key on each channel ``ids`` at clip time ``t``, holding what the channel plays there
    (a channel without a track gets the rest value). Returns the number of keys set."""
    clip = document.clip
    if clip is None or not ids:
        return 0
    views = {v.id: v for v in channels(document, sorted({i.joint for i in ids}))}
    new = {}
    for cid in ids:
        view = views[cid]
        if view.curve is None:
            rest = _rest_values(document.skeleton, cid.joint, cid.channel)[cid.axis]
            new[cid] = Curve([t], [rest])
        else:
            new[cid] = view.curve.with_key(t, float(view.sample([t])[0]), keep_shape=True)
    edit_curves(document, new, f"Insert keys at {t:.2f}s")
    return len(new)


def _selected(document, selection):
    """``{ChannelId: (Curve, sorted unique key indices)}`` of ``selection``'s channels that have
    a curve in the current clip, each keeping only indices of keys it has: a selection kept
    from before an undo may name keys the curve no longer has (an IndexError then, and a
    negative index would pick a key from the end)."""
    curves = _views(document, selection)
    out = {}
    for cid, idx in selection.items():
        curve = curves.get(cid)
        if curve is None:
            continue
        idx = np.unique(np.asarray(list(idx), dtype=int).reshape(-1))
        idx = idx[(idx >= 0) & (idx < len(curve))]
        if len(idx):
            out[cid] = (curve, idx)
    return out


def delete_keys(document, selection):
    """Delete keys: ``selection`` is ``{ChannelId: [key indices]}``. Returns the number of
    keys deleted."""
    chosen = _selected(document, selection)
    if not chosen:
        return 0
    new = {cid: curve.without_keys(idx) for cid, (curve, idx) in chosen.items()}
    count = sum(len(idx) for _, idx in chosen.values())
    edit_curves(document, new, f"Delete {count} key{'s' if count != 1 else ''}")
    return count


def _per_key(document, selection, label, edit):
    chosen = _selected(document, selection)
    if not chosen:
        return 0
    edit_curves(document, {cid: edit(curve, list(idx)) for cid, (curve, idx) in chosen.items()},
                label)
    return sum(len(idx) for _, idx in chosen.values())


def set_interpolation(document, selection, name):
    """Interpolation ``name`` (constant, linear, bezier) on the selected keys' segments.
    Returns the number of keys set."""
    return _per_key(document, selection, f"Interpolation {name}",
                    lambda c, idx: c.with_interpolation(idx, name))


def set_handle_type(document, selection, name):
    """Handle type ``name`` on both handles of the selected keys. Returns the keys set."""
    return _per_key(document, selection, f"Handles {name}",
                    lambda c, idx: c.with_handle_type(idx, name))


def set_easing(document, selection, name):
    """Easing preset ``name`` (ease_in, ease_out, ease_in_out) on the selected keys. Returns
    the keys set."""
    return _per_key(document, selection, f"Easing {name.replace('_', ' ')}",
                    lambda c, idx: c.with_easing(idx, name))
