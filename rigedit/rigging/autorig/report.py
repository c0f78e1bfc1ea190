"""What :func:`rigedit.rigging.autorig.pipeline.autorig` decided and measured: the report
the command line prints and the editor shows (``rig.autorig_report``)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .orient import Orientation

__all__ = ["AutorigReport"]


@dataclass
class AutorigReport:
    """What :func:`.pipeline.autorig` decided and measured (``rig.autorig_report``).

    Attributes
    ----------
    source : str
        The mesh (its path, or ``"mesh"`` for arrays).
    template : str
    orientation : Orientation
        Up and forward in the input's coordinates, whether guessed and whether sure.
    transform : (4, 4) float64
        Input coordinates -> the rig's (a rotation, then a translation).
    checks : MeshCheck
    seconds : dict[str, float]
        Wall seconds per stage (the embedding's own stages prefixed ``embedding/``), and
        ``total``.
    cost : float
        The embedding's penalty.
    placed : list[str]
        Joints the embedding placed from the mesh (the rest are carried from the template).
    clips : dict[str, str]
        Each template clip -> ``"retargeted"`` or why it was left out.
    template_pose : str
        The template pose embedded: ``"rest"``, or a clip's first frame (see
        :func:`template_poses`).
    outside : list[str]
        Carried template joints with no geometry around them (collapsed by the embedding
        into their base's region): kept, for the clips, but not deforming.
    sure : bool
        Whether every check a rigger would make passed (:mod:`.confidence`) and the
        orientation won by a clear margin (:mod:`.orient_search`).
    reasons : list[str]
        One line per failed check.
    doubtful : list[str]
        The joints in doubt (the editor selects them).
    orientations : list[str]
        Each orientation tried and its score, best first.
    embedded : (J, 3) float64
        Every template joint as embedded, in the rig's coordinates (the editor's "Re-embed
        around the joints I moved" compares the rest with it).
    hints : dict[str, (3,) float64]
        The joints pinned by hints, in the rig's coordinates.
    """

    source: str
    template: str
    orientation: Orientation
    transform: np.ndarray
    checks: object
    seconds: dict = field(default_factory=dict)
    cost: float = 0.0
    placed: list = field(default_factory=list)
    clips: dict = field(default_factory=dict)
    template_pose: str = "rest"
    outside: list = field(default_factory=list)
    embedded: np.ndarray = None
    hints: dict = field(default_factory=dict)
    sure: bool = True
    reasons: list = field(default_factory=list)
    doubtful: list = field(default_factory=list)
    orientations: list = field(default_factory=list)

    def lines(self):
        """The report as short lines (the CLI prints them)."""
        o = self.orientation
        out = [f"orientation: {o.describe()}"]
        if o.guessed:
            out.append("orientation cues: " + ", ".join(f"{k} {v:.3g}" for k, v in o.notes.items()))
        t = self.transform[:3, 3]
        out.append(f"placed: turned into +Y up, facing +Z, moved by ({t[0]:.4g}, {t[1]:.4g}, "
                   f"{t[2]:.4g}) to stand on y = 0")
        out += list(self.checks.lines())
        if len(self.orientations) > 1:
            out.append("orientations tried: " + "; ".join(self.orientations))
        out.append(f"embedding: template {self.template} ({self.template_pose} pose), "
                   f"{len(self.placed)} joints placed from the mesh, cost {self.cost:.4g}")
        if self.hints:
            out.append("hints: " + ", ".join(sorted(self.hints)) + " pinned where given")
        out += [f"NOT SURE: {reason}" for reason in self.reasons]
        out.append("checks: " + ("all passed (limbs, upright, mirror, inside, lengths, "
                                 "margin)" if self.sure else
                                 f"NOT SURE, {len(self.reasons)} failed; check "
                                 f"{', '.join(self.doubtful[:8]) or 'the orientation'}"))
        if self.outside:
            from ...embedding.inside import describe_joints
            out.append(f"{describe_joints(self.outside)}: no geometry, not deforming")
        for name, how in self.clips.items():
            out.append(f"clip {name}: {how}")
        out.append("seconds: " + ", ".join(f"{k} {v:.2f}" for k, v in self.seconds.items()))
        return out
