"""The document's morph target weights and their edits (one undo step each).

The weights shown are the current clip's at the current time (its weight tracks; a target
without a track has its default weight, as a joint without a track has its rest), until the
user sets one: like a pose edit, a weight set and not keyed lasts until the time or the clip
changes. The weights live in the rig's binding (``SkinBinding.set_morph_weights``), so every
view that skins the rig shows them; a change is announced as
:class:`~rigedit.editor.events.MorphChanged` followed by
:class:`~rigedit.editor.events.PoseChanged` (the skinned surface changed: the views that
redraw on a pose change redraw).

Commands: :func:`set_weight` (a click), :class:`WeightDrag` (a slider held: one step at the
release), :func:`key_weight` and :func:`delete_weight_key` on the current clip.
"""
from __future__ import annotations

import numpy as np

from . import events as ev
from .clip_edits import edit_clip
from .undo import Command

__all__ = ["MorphWeights", "MorphCommand", "set_weight", "WeightDrag", "key_weight",
           "delete_weight_key", "changed_targets"]


class MorphCommand(Command):
    """A weight edit (not a clip edit: the auto-key answers it with keys)."""

    __slots__ = ()


class MorphWeights:
    """The weights of the document's rig's morph targets (``document.morph``).

    Parameters
    ----------
    document : Document
    """

    def __init__(self, document):
        self.document = document

    @property
    def targets(self):
        """The rig's :class:`~rigedit.model.morph.MorphTargets`, or None."""
        return self.document.rig.morphs

    @property
    def names(self):
        """(M,) target names (empty without targets)."""
        return () if self.targets is None else self.targets.names

    @property
    def weights(self):
        """(M,) float64: the weights shown now (a copy)."""
        return self.document.rig.binding.morph_weights

    def weight(self, target):
        """The weight of ``target`` (a name) shown now; KeyError for an unknown name."""
        return float(self.weights[self._index(target)])

    def _index(self, target):
        if self.targets is None:
            raise KeyError(f"this rig has no morph targets (asked for {target!r})")
        return self.targets.index(target)

    def of_clip(self, clip, t):
        """(M,) weights of ``clip`` at playback time ``t``: its tracks' values, the default
        weights elsewhere (all defaults without a clip)."""
        if self.targets is None:
            return np.zeros(0)
        return self.targets.weights_array(None if clip is None else clip.sample_morphs(t))

    def show(self, weights, announce=True):
        """Put ``weights`` ((M,) or a dict) in the binding; announces MorphChanged (and
        PoseChanged when ``announce``) if they changed. Not an undo step. Returns whether
        they changed."""
        if self.targets is None or not self.document.rig.binding.set_morph_weights(weights):
            return False
        d = self.document
        d.emit(ev.MorphChanged(tuple(float(w) for w in self.weights)))
        if announce:
            d.emit(ev.PoseChanged())
        return True

    def sample(self, clip, t):
        """Show ``clip``'s weights at ``t`` (the document samples its clip); announces only
        MorphChanged: the caller announces the pose. Returns whether they changed."""
        return self.targets is not None and self.show(self.of_clip(clip, t), announce=False)

    def with_weight(self, target, weight):
        """(M,) the current weights with ``target`` set to ``weight``."""
        w = self.weights
        weight = float(weight)
        if not np.isfinite(weight):
            raise ValueError(f"expected a finite weight for {target!r}, got {weight}")
        w[self._index(target)] = weight
        return w


def _command(document, label, before, after):
    morph = document.morph
    return MorphCommand(label, lambda: morph.show(after), lambda: morph.show(before))


def set_weight(document, target, weight, label=None):
    """Set ``target``'s weight (not keyed) as one undo step. Returns whether it changed."""
    morph = document.morph
    before, after = morph.weights, morph.with_weight(target, weight)
    if np.array_equal(before, after):
        return False
    document.push(_command(document, label or f"Set {target} {float(weight):.2f}", before,
                           after))
    return True


class WeightDrag:
    """A weight slider held: the mesh follows at once, :meth:`end` makes the whole drag one
    undo step (none when the weight is back where it started).

    Parameters
    ----------
    document : Document
    target : str
    """

    def __init__(self, document, target):
        self.document = document
        self.target = target
        document.morph._index(target)          # KeyError now, not at the first step
        self.before = document.morph.weights

    def step(self, weight):
        """The slider is at ``weight``: shown, no undo step yet."""
        self.document.morph.show(self.document.morph.with_weight(self.target, weight))

    def end(self):
        """Release: one undo step. Returns whether there was a change."""
        after = self.document.morph.weights
        if np.array_equal(after, self.before):
            return False
        weight = after[self.document.morph._index(self.target)]
        self.document.push(_command(self.document, f"Set {self.target} {weight:.2f}",
                                    self.before, after), execute=False)
        return True

    def cancel(self):
        self.document.morph.show(self.before)


def key_weight(document, target, t=None, weight=None, amend=False):
    """Key ``target``'s weight (the one shown, or ``weight``) at ``t`` (default: the
    document's time) on the current clip, one undo step; a document without a clip gets a
    new one first (its own step, as for joint keys). Returns the number of keys set (1)."""
    from .clip_commands import new_clip

    morph = document.morph
    w = morph.weight(target) if weight is None else float(weight)
    t = document.time if t is None else float(t)
    if document.clip is None:
        new_clip(document)
    # resample=False: the other weights the user set and did not key stay shown
    edit_clip(document, f"Key {target} at {t:.2f}s",
              lambda c: c.set_morph_key(target, t, w), resample=False, amend=amend)
    return 1


def delete_weight_key(document, target, t=None, tolerance=0.5 / 30):
    """Delete ``target``'s key within ``tolerance`` seconds of ``t`` on the current clip, one
    undo step. Returns the number of keys deleted."""
    clip = document.clip
    track = None if clip is None else clip.morph_tracks.get(target)
    if track is None:
        return 0
    t = document.time if t is None else float(t)
    i = track.key_index(t, tolerance)
    if i is None:
        return 0
    k = float(track.times[i])

    def change(c):
        new = c.morph_tracks[target].without_keys([k])
        if new is None:
            c.remove_morph_track(target)
        else:
            c.set_morph_track(target, new)
        return 1

    return edit_clip(document, f"Delete {target} key at {k:.2f}s", change)


def changed_targets(document):
    """Names of the targets whose shown weight differs from the current clip's at the
    current time (what the auto-key keys)."""
    morph = document.morph
    if morph.targets is None or document.clip is None:
        return []
    diff = np.abs(morph.weights - morph.of_clip(document.clip, document.time)) > 1e-9
    return [morph.names[m] for m in np.flatnonzero(diff)]
