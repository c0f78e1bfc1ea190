"""The template embedded in each orientation tried, each result checked, and the verdict
(step 3 of :mod:`.pipeline`).

In each orientation the mesh is turned into rigedit's frame and stood on y = 0
(:func:`placement`), the template embedded (:func:`rigedit.embedding.embed_skeleton`, the
first of its standing poses that fits) and the result checked as a rigger would
(:mod:`.confidence`) and scored (:func:`.confidence.fit_score`); :mod:`.orient_search` keeps
the best. A failed check or a runner-up within the margin makes the result NOT SURE
(:func:`verdict`).
"""
from __future__ import annotations

import numpy as np

from ...embedding import EmbeddingError, HintError, embed_skeleton
from ...embedding.distance import distance_field
from ...embedding.template import reduce_template
from ...errors import RigFileError
from .confidence import check_embedding, fit_score
from .orient import SURE_FORWARD
from .orient_search import MARGIN, search

__all__ = ["Trials", "embed_best", "placement", "turned_hints", "verdict"]


class Trials:
    """Embedding and checking the template in one orientation after another (what
    :func:`.orient_search.search` calls).

    Parameters
    ----------
    vertices : (V, 3) float64
        The mesh, in the input's coordinates (its extent places it).
    body_v, body_f : (Vb, 3) float64, (Fb, 3) int
        The body the embedding fits in (the mesh, or a watertight proxy of it).
    poses : list of (Skeleton, str)
        The template's standing poses, tried in order.
    t_mesh : ((Vt, 3) float64, (Ft, 3) int) or None
        The template's own mesh in its rest pose.
    hints : dict[str, (3,) float] or None
        Joints pinned, in the input's coordinates.
    stands_tall : bool
        The template is upright (a biped).
    source : str
        Names the mesh in errors.
    n_frames : int
        How many orientations may be tried (each one's share of the progress).
    progress : callable(fraction)
        The embedding stage's progress, 0..1 over every orientation.
    """

    def __init__(self, vertices, body_v, body_f, poses, t_mesh, hints, stands_tall, source,
                 n_frames, progress):
        self.vertices, self.body_v, self.body_f = vertices, body_v, body_f
        self.used = np.unique(body_f)
        self.remap = np.full(len(body_v), -1, dtype=np.int64)
        self.remap[self.used] = np.arange(len(self.used))
        self.poses, self.t_mesh, self.hints = poses, t_mesh, hints
        self.stands_tall, self.source = stands_tall, source
        self.n_frames, self.progress = n_frames, progress
        self.done = 0.0           # the search's own fraction, before this orientation
        self.reduced = {}         # id(template skeleton) -> its ReducedTemplate
        self.field = None         # one field, in the input's frame, for every frame tried

    def embed(self, orientation):
        """(embedding, placement, template skeleton, its pose) in one frame."""
        place = placement(self.vertices, orientation)
        emb_v = self.body_v[self.used] @ place[:3, :3].T + place[:3, 3]
        first = None
        for t_sk, t_pose in self.poses:   # the first standing pose of the template that fits
            try:
                emb = embed_skeleton(emb_v, self.remap[self.body_f], t_sk,
                                     template_mesh=self.t_mesh,
                                     progress=lambda f, stage=None: self._sub(f / self.n_frames),
                                     hints=turned_hints(self.hints, place))
                return emb, place, t_sk, t_pose
            except HintError as exc:   # an unknown joint, a point outside the mesh
                raise RigFileError(self.source, str(exc)) from None
            except EmbeddingError as exc:
                first = first or exc
        raise first

    def check(self, found):
        """``(Confidence, fit score)`` of an :meth:`embed` result."""
        emb, place, t_sk, _ = found
        if id(t_sk) not in self.reduced:
            self.reduced[id(t_sk)] = reduce_template(t_sk, self.t_mesh)
        red = self.reduced[id(t_sk)]
        if self.field is None:
            self.field = distance_field(self.body_v[self.used], self.remap[self.body_f])
        back = np.linalg.inv(place)
        return (check_embedding(self.field, red, emb.positions, list(t_sk.names),
                                emb.placed, self.stands_tall, to_field=back),
                fit_score(red, emb.positions))

    def step(self, fraction):
        """The search's progress: ``fraction`` of the orientations done."""
        self.done = fraction

    def _sub(self, f):
        self.progress(self.done + f)


def embed_best(trials, frames, t_name):
    """Search the orientations ``frames`` with ``trials`` (a :class:`Trials`).

    Returns
    -------
    tried : list of Trial
        Best first (:func:`.orient_search.search`).
    result : tuple
        The best :meth:`Trials.embed` result.

    Raises
    ------
    RigFileError
        When nothing fits in any frame tried: the first guess's reason.
    """
    tried = search(frames, trials.embed, trials.check, failure=EmbeddingError,
                   progress=trials.step)
    best = tried[0]
    if best.result is None:   # nothing fits in any frame tried: the guess's reason
        guess = next(t for t in tried if t.orientation is frames[0])
        raise RigFileError(trials.source, f"{guess.error} (template {t_name}, orientation "
                                          f"{frames[0].describe()}"
                                          + (f"; {len(tried)} orientations tried"
                                             if len(tried) > 1 else "") + ")") from None
    return tried, best.result


def placement(vertices, orientation):
    """(4, 4) input -> rig: turn into rigedit's frame, stand on y = 0, centre x and z."""
    m = np.eye(4)
    m[:3, :3] = orientation.rotation
    turned = vertices @ m[:3, :3].T
    lo, hi = turned.min(axis=0), turned.max(axis=0)
    m[:3, 3] = [-(lo[0] + hi[0]) / 2, -lo[1], -(lo[2] + hi[2]) / 2]
    return m


def turned_hints(hints, place):
    """Hints in the input's coordinates -> the embedding's frame (``place``, (4, 4))."""
    out = {}
    for name, p in (hints or {}).items():
        try:
            out[name] = place[:3, :3] @ np.asarray(p, dtype=np.float64).reshape(3) + place[:3, 3]
        except (TypeError, ValueError):
            out[name] = p   # embed_skeleton names the joint and what is wrong
    return out


def verdict(best, tried, frames, upright):
    """The winning orientation, marked sure or not by the search, and the winner's checks
    with the margin check added (see :mod:`.orient_search`)."""
    o, conf = best.orientation, best.confidence
    if not o.guessed:
        return o, conf
    others = [t for t in tried[1:] if np.isfinite(t.score)]
    margin = others[0].score - best.score if others else np.inf
    o.notes["tried"] = float(len(tried))
    o.notes["margin"] = float(margin)
    # the embedding tells up from down and a turned body, but hardly a biped's front from
    # its back: that stays the forward cue's
    cue_ok = not upright or o.notes.get("forward", SURE_FORWARD) >= SURE_FORWARD
    o.sure = bool(margin >= MARGIN and cue_ok)
    if margin < MARGIN:
        conf.fail("margin", f"orientation: {others[0].describe()} fits almost as well as "
                            f"{best.describe()} (margin {margin:.2f}, under {MARGIN:g})")
    elif not cue_ok:
        conf.fail("margin", f"orientation: front and back told apart only by "
                            f"{o.notes['forward']:.3f} of the height (under {SURE_FORWARD:g})")
    return o, conf
