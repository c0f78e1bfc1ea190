"""Any mesh to an animated character: ``rigedit.autorig`` (issue 11, section 1).

The pipeline, each stage timed in ``rig.autorig_report.seconds``:

1. **load/check** (:mod:`.mesh_check`): read the mesh, weld it; a mesh that is not one closed
   body (open, non-manifold, many parts) gets a watertight proxy of its volume, which the
   orientation and the embedding use (the weights stay on the real mesh);
2. **orient** (:mod:`.orient`): up and forward given, or a few hypotheses guessed
   (:func:`.orient.hypotheses`); in each the mesh is turned into rigedit's frame (+Y up,
   facing +Z), keeps its units, and is moved to stand on y = 0 centred over the origin in
   x and z (``report.transform``, input -> rig);
3. **embedding** (:mod:`rigedit.embedding`, Baran and Popovic's Pinocchio): every template
   joint placed inside the mesh, in each hypothesis; each result checked as a rigger would
   (:mod:`.confidence`) and scored, the best kept (:mod:`.orient_search`). A failed check or
   a runner-up within the margin makes the result NOT SURE (``report.sure``,
   ``report.reasons``, ``report.doubtful``);
4. **skeleton**: the template's names, hierarchy and deform flags on the embedded positions.
   Joint frames follow the template's: a joint's model-space rest rotation is the
   template's, turned by the smallest rotation taking the template's bone to the embedded one
   (for a joint with several children, the rotation that best takes all its child bones to
   theirs; a leaf keeps its parent's turn; a root keeps the template's frame). So bone rolls
   stay as the template's animator made them, and the template's clips mean the same motion;
5. **weights**: bone heat (or another method of :mod:`rigedit.binding.weights`) on the whole
   mesh, small parts included;
6. **clips**: each template clip through :func:`rigedit.rigging.retarget.pipeline.retarget` (bones
   made to point as the template's in model space, root motion scaled by leg length, feet
   held during contacts), so the character walks at once.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ...errors import RigFileError
from ...progress import adapt, scaled
from .mesh_check import check_mesh, read_mesh
from .confidence import check_embedding, fit_score
from .orient import SURE_FORWARD, Orientation, check_axes, hypotheses
from .orient_search import MARGIN, search
from .templates import load_template, rest_model, template_poses, upright

__all__ = ["autorig", "AutorigReport", "load_template", "template_poses", "build_skeleton",
           "STAGES"]

#: Progress bands of the stages (start, end) as fractions of the whole run.
STAGES = {"load/check": (0.0, 0.05), "orient": (0.05, 0.1), "embedding": (0.1, 0.6),
          "skeleton": (0.6, 0.62), "weights": (0.62, 0.85), "clips": (0.85, 1.0)}


@dataclass
class AutorigReport:
    """What :func:`autorig` decided and measured (``rig.autorig_report``).

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


def build_skeleton(template, positions):
    """The template's joints at new positions, frames turned as the module notes say.

    Parameters
    ----------
    template : Skeleton
    positions : (J, 3) float64
        Model-space position of every template joint, template order.

    Returns
    -------
    Skeleton
    """
    from ...model.skeleton import Skeleton

    positions = np.asarray(positions, dtype=np.float64)
    rest = rest_model(template)
    t_pos = rest[:, :3, 3]
    t_rot = Rotation.from_matrix(rest[:, :3, :3]).as_matrix()  # scale dropped
    n = len(template)
    turn = np.tile(np.eye(3), (n, 1, 1))
    t_len = e_len = 0.0
    for j in range(n):
        p = template.parents[j]
        kids = template.children(j)
        a = t_pos[kids] - t_pos[j]
        b = positions[kids] - positions[j]
        ok = (np.linalg.norm(a, axis=1) > 1e-9) & (np.linalg.norm(b, axis=1) > 1e-9)
        t_len += np.linalg.norm(a, axis=1).sum()
        e_len += np.linalg.norm(b, axis=1).sum()
        if p < 0:
            continue                       # a root keeps the template's frame (its facing)
        if not ok.any():
            turn[j] = turn[p]              # a leaf turns with its parent
            continue
        w = np.linalg.norm(b[ok], axis=1)
        r, _ = Rotation.align_vectors(b[ok], a[ok], weights=w if ok.sum() > 1 else None)
        turn[j] = r.as_matrix()
    model_rot = turn @ t_rot
    local_t = np.empty((n, 3))
    local_r = np.empty((n, 3, 3))
    for j in range(n):
        p = template.parents[j]
        if p < 0:
            local_t[j], local_r[j] = positions[j], model_rot[j]
        else:
            local_t[j] = model_rot[p].T @ (positions[j] - positions[p])
            local_r[j] = model_rot[p].T @ model_rot[j]
    scale = e_len / t_len if t_len > 0 else 1.0
    tails = np.full((n, 3), np.nan)
    has = np.all(np.isfinite(template.tails), axis=1)
    if has.any():
        # tails are given at bind time: carried to the rest pose by their joint, then taken
        # relative to the rest head, turned and scaled
        bind_local = np.einsum("tij,tj->ti", template.inverse_bind_matrices[has],
                               np.c_[template.tails[has], np.ones(has.sum())])
        t_tails = np.einsum("tij,tj->ti", rest[has], bind_local)[:, :3]
        tails[has] = positions[has] + scale * np.einsum("tij,tj->ti", turn[has],
                                                        t_tails - t_pos[has])
    return Skeleton(list(template.names), template.parents.copy(), local_t,
                    Rotation.from_matrix(local_r).as_quat(), tails=tails,
                    deform=template.deform.copy())


def _arrays(mesh):
    """(vertices (V, 3) float64, faces (F, 3) int64) from a pair, checked like a file."""
    try:
        vertices, faces = mesh
        vertices = np.asarray(vertices, dtype=np.float64)
        faces = np.asarray(faces)
    except (TypeError, ValueError):
        raise ValueError("mesh: expected a path or a (vertices, faces) pair") from None
    if vertices.ndim != 2 or vertices.shape[1] != 3 or not np.all(np.isfinite(vertices)):
        raise ValueError(f"mesh: expected finite vertices of shape (V, 3), got "
                         f"{vertices.shape}")
    if faces.size and (faces.ndim != 2 or faces.shape[1] != 3 or faces.dtype.kind not in "iu"
                       or faces.min() < 0 or faces.max() >= len(vertices)):
        raise ValueError(f"mesh: expected faces (F, 3) of vertex indices below "
                         f"{len(vertices)}, got {faces.shape} {faces.dtype}")
    return vertices, faces.reshape(-1, 3).astype(np.int64)


def _placement(vertices, orientation):
    """(4, 4) input -> rig: turn into rigedit's frame, stand on y = 0, centre x and z."""
    m = np.eye(4)
    m[:3, :3] = orientation.rotation
    turned = vertices @ m[:3, :3].T
    lo, hi = turned.min(axis=0), turned.max(axis=0)
    m[:3, 3] = [-(lo[0] + hi[0]) / 2, -lo[1], -(lo[2] + hi[2]) / 2]
    return m


def _turned(hints, place):
    """Hints in the input's coordinates -> the embedding's frame (``place``, (4, 4))."""
    out = {}
    for name, p in (hints or {}).items():
        try:
            out[name] = place[:3, :3] @ np.asarray(p, dtype=np.float64).reshape(3) + place[:3, 3]
        except (TypeError, ValueError):
            out[name] = p   # embed_skeleton names the joint and what is wrong
    return out


def _verdict(best, tried, frames, upright):
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


def autorig(mesh, template="humanoid", up=None, forward=None, weights="heat", clips=True,
            progress=None, hints=None):
    """Rig a static mesh with a template skeleton (see the module notes).

    Parameters
    ----------
    mesh : str, Path or (vertices (V, 3), faces (F, 3))
        A mesh file (OBJ, PLY, STL, VTK, VTU, VTP, or a .glb/.gltf's mesh) or arrays.
    template : str, Path, Rig or Skeleton
        ``"humanoid"``, ``"quadruped"``, a skeleton file, rig folder, .glb or .bvh (its clips
        come along), or an object.
    up, forward : str, optional
        Axes of the input such as ``"y"``, ``"-x"``; guessed when omitted (and reported).
    weights : str
        Skin weights method (``"heat"``, ``"idw"``).
    clips : bool
        Give the template's clips to the new character.
    progress : callable(fraction, stage), optional
        :mod:`rigedit.progress`'s protocol, called as the work advances (stages
        ``STAGES``); :class:`rigedit.progress.Cancelled` (or any exception) raised by it
        cancels.
    hints : dict[str, (3,) float], optional
        Template joint name -> where it must be, in the mesh's (the input's) coordinates:
        those joints are pinned and the embedding places the others around them.

    Returns
    -------
    Rig
        With ``rig.autorig_report`` (:class:`AutorigReport`).

    Raises
    ------
    RigFileError
        Naming the mesh (or template) file and what is wrong: no volume, no limbs
        like the template's, a template that is not a skeleton.
    """
    from ...embedding import EmbeddingError, HintError, embed_skeleton
    from ...embedding.distance import distance_field
    from ...embedding.template import reduce_template
    from ...binding.weights import compute_weights
    from ...rig import Rig

    tell = adapt(progress)
    seconds = {}
    t_all = time.perf_counter()

    def band(stage):
        lo, hi = STAGES[stage]
        return scaled(tell, lo, hi, stage)

    t0 = time.perf_counter()
    band("load/check")(0.0)
    check_axes(up, forward)          # a usage error before any file is read
    t_rig, t_sk, t_name = load_template(template)
    poses = template_poses(t_sk, t_rig, t_name)
    if isinstance(mesh, (str, Path)):
        source = str(mesh)
        vertices, faces, surface = read_mesh(mesh, with_surface=True)
    else:
        source, surface = "mesh", None
        vertices, faces = _arrays(mesh)
    checks = check_mesh(vertices, faces, source)
    seconds["load/check"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    band("orient")(0.0)
    body_v, body_f = checks.embedding_mesh()     # the body, or a watertight proxy of it
    stands_tall = upright(poses[0][0])
    frames = hypotheses(body_v, body_f, upright=stands_tall, up=up, forward=forward)
    seconds["orient"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    used = np.unique(body_f)
    remap = np.full(len(body_v), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    t_mesh = None
    if t_rig is not None and len(t_rig.vertices) and len(t_rig.faces):
        t_mesh = (t_rig.skin(t_rig.rest_pose()), t_rig.faces)   # the rest pose's, as the joints
    trials = len(frames)

    def embed(orientation):
        """(embedding, placement, template skeleton, its pose) in one frame."""
        place = _placement(vertices, orientation)
        emb_v = body_v[used] @ place[:3, :3].T + place[:3, 3]
        first = None
        for t_sk, t_pose in poses:   # the first standing pose of the template that fits
            try:
                emb = embed_skeleton(emb_v, remap[body_f], t_sk, template_mesh=t_mesh,
                                     progress=lambda f, stage=None: sub(f / trials),
                                     hints=_turned(hints, place))
                return emb, place, t_sk, t_pose
            except HintError as exc:   # an unknown joint, a point outside the mesh
                raise RigFileError(source, str(exc)) from None
            except EmbeddingError as exc:
                first = first or exc
        raise first

    reduced, body_field = {}, []

    def check(found):
        emb, place, t_sk, _ = found
        if id(t_sk) not in reduced:
            reduced[id(t_sk)] = reduce_template(t_sk, t_mesh)
        red = reduced[id(t_sk)]
        if not body_field:   # one field, in the input's frame, for every frame tried
            body_field.append(distance_field(body_v[used], remap[body_f]))
        back = np.linalg.inv(place)
        return (check_embedding(body_field[0], red, emb.positions, list(t_sk.names),
                                emb.placed, stands_tall, to_field=back),
                fit_score(red, emb.positions))

    def sub(f):
        band("embedding")(done[0] + f)
    done = [0.0]

    def step(f):
        done[0] = f
    tried = search(frames, embed, check, failure=EmbeddingError, progress=step)
    best = tried[0]
    if best.result is None:   # nothing fits in any frame tried: the guess's reason
        guess = next(t for t in tried if t.orientation is frames[0])
        raise RigFileError(source, f"{guess.error} (template {t_name}, orientation "
                                   f"{frames[0].describe()}"
                                   + (f"; {len(tried)} orientations tried" if len(tried) > 1
                                      else "") + ")") from None
    emb, place, t_sk, t_pose = best.result
    orientation, confidence = _verdict(best, tried, frames, stands_tall)
    seconds["embedding"] = time.perf_counter() - t0
    for k, v in emb.seconds.items():
        seconds[f"embedding/{k}"] = v

    t0 = time.perf_counter()
    skeleton = build_skeleton(t_sk, emb.positions)
    skeleton.deform[[skeleton.names.index(n) for n in emb.outside]] = False
    seconds["skeleton"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    rig_v = vertices @ place[:3, :3].T + place[:3, 3]
    idx, w = compute_weights(rig_v, skeleton, weights, faces=faces, progress=band("weights"))
    name = Path(source).stem if source != "mesh" else "autorig"
    rig = Rig(skeleton, rig_v, faces, idx, w, name=name, up="y", weights_method=weights,
              surface=surface)
    rig.weights_computed = True
    seconds["weights"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    clip_notes = {}
    if clips and t_rig is not None and t_rig.clips:
        from ..retarget.pipeline import retarget

        names = sorted(t_rig.clips)
        for i, clip_name in enumerate(names):
            band("clips")(i / len(names))
            try:
                step = scaled(band("clips"), i / len(names), (i + 1) / len(names))
                rig.clips[clip_name] = retarget(t_rig, t_rig.clips[clip_name], rig,
                                                progress=step)
                clip_notes[clip_name] = "retargeted"
            except ValueError as exc:  # a clip the retargeting cannot carry: say why
                clip_notes[clip_name] = f"left out: {exc}"
    seconds["clips"] = time.perf_counter() - t0
    band("clips")(1.0)
    seconds["total"] = time.perf_counter() - t_all
    report = AutorigReport(source, t_name, orientation, place, checks, seconds, emb.cost,
                           list(emb.placed), clip_notes, t_pose, list(emb.outside))
    rig.meta.autorig_report = report
    report.embedded = np.array(emb.positions)
    report.sure = bool(confidence.sure)
    report.reasons = list(confidence.reasons)
    report.doubtful = list(confidence.doubtful)
    report.orientations = [t.describe() for t in tried]
    report.hints = _turned(hints, place)
    rig.meta.notes["autorig"] = (f"template {t_name}; orientation {orientation.describe()}")
    return rig
