"""The embedding decides the orientation: each hypothesis embedded, checked and scored.

:func:`rigedit.rigging.autorig.orient.hypotheses` offers a few frames (the guess, up reversed, the
other in-plane axis up, the axis-aligned frames near them); :func:`search` embeds each,
checks it as a rigger would (:mod:`.confidence`) and scores it without the raw cost (that
depends on the scale each frame's height implies): :func:`.confidence.fit_score` plus
:data:`CHECK_PENALTY` per failed check. The lowest score wins; the margin to the next is
reported, and under :data:`MARGIN` the result is not sure.

Each try costs an embedding (1-2 s on the test meshes): the hypotheses are capped
(:data:`rigedit.rigging.autorig.orient.HYPOTHESES`), and after the first two (always, for a margin)
the search starts no new one once a winner is settled (it passes every check, fits well
and leads by a clear score) or after :data:`SEARCH_SECONDS`.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

__all__ = ["Trial", "search", "CHECK_PENALTY", "MARGIN", "SEARCH_SECONDS"]

#: Score added per failed check: one unit of the fit score is "clearly wrong" (a bone at
#: 45 degrees to the template's costs 0.9).
CHECK_PENALTY = 1.0
#: Least score lead of the winner over the next orientation for a sure result.
MARGIN = 0.1
#: A winner this good (fit score, every check passed) and this far ahead of the others
#: tried ends the search early (see :func:`_settled`): right rigs of the shared meshes fit
#: at 0.0-0.5, a frame turned from them scores over 1.
SETTLED_FIT, SETTLED_LEAD = 0.6, 1.0
#: Wall seconds after which no new hypothesis is started (the issue allows 30 s in all for
#: a 50k-vertex mesh).
SEARCH_SECONDS = 16.0


@dataclass
class Trial:
    """One orientation tried.

    Attributes
    ----------
    orientation : Orientation
    score : float
        Fit score plus the check penalties (``inf`` when the embedding failed).
    fit : float
        :func:`.confidence.fit_score` of the embedded joints.
    confidence : Confidence or None
    result : object
        What the caller's ``embed`` returned (None when it raised).
    error : Exception or None
        Why the embedding failed.
    seconds : float
    """

    orientation: object
    score: float = np.inf
    fit: float = np.inf
    confidence: object = None
    result: object = None
    error: object = None
    seconds: float = 0.0

    def describe(self):
        from .orient import axis_name

        o = self.orientation
        frame = f"up {axis_name(o.up)}, forward {axis_name(o.forward)}"
        if self.error is not None:
            return f"{frame}: no fit"
        failed = self.confidence.failed if self.confidence is not None else []
        return f"{frame}: score {self.score:.2f}" + (f" ({', '.join(failed)} failed)"
                                                     if failed else "")


def _settled(trials):
    """The best so far passes every check, fits well (:data:`SETTLED_FIT`) and leads every
    other tried by :data:`SETTLED_LEAD`: the frames still to try (turns of a frame that
    fits) will not beat it."""
    scores = sorted(t.score for t in trials)
    best = min(trials, key=lambda t: t.score)
    return (best.confidence is not None and best.confidence.sure
            and best.fit <= SETTLED_FIT and scores[1] - scores[0] >= SETTLED_LEAD)


def search(orientations, embed, check, failure=ValueError, budget=SEARCH_SECONDS,
           progress=None):
    """Embed each orientation, check and score it (see the module notes).

    Parameters
    ----------
    orientations : list of Orientation
        The hypotheses, the guess first.
    embed : callable(Orientation) -> object
        The embedding in that frame; raises ``failure`` when nothing fits.
    check : callable(object) -> (Confidence, float)
        The checks and the fit score of an embedding.
    failure : type or tuple of types
        The exceptions that mean "no fit in this frame" (others propagate).
    budget : float
        Seconds after which no new hypothesis is started (after the first two).
    progress : callable(fraction), optional

    Returns
    -------
    list of Trial
        Best first (the failed ones last, in the order tried).
    """
    trials = []
    t_all = time.perf_counter()
    for i, o in enumerate(orientations):
        if i >= 2 and (time.perf_counter() - t_all > budget or _settled(trials)):
            break
        if progress is not None:
            progress(i / len(orientations))
        t0 = time.perf_counter()
        trial = Trial(o)
        try:
            trial.result = embed(o)
        except failure as exc:
            trial.error = exc
        else:
            trial.confidence, trial.fit = check(trial.result)
            trial.score = trial.fit + CHECK_PENALTY * len(trial.confidence.failed)
        trial.seconds = time.perf_counter() - t0
        trials.append(trial)
    if progress is not None:
        progress(1.0)
    order = sorted(range(len(trials)), key=lambda k: (trials[k].score, k))
    return [trials[k] for k in order]
