"""Any mesh to an animated character: ``rigedit.autorig`` (issue 11, section 1).

The pipeline, each stage timed in ``rig.autorig_report.seconds`` (:mod:`.report`):

1. **load/check** (:mod:`.mesh_check`): read the mesh, weld it; a mesh that is not one closed
   body (open, non-manifold, many parts) gets a watertight proxy of its volume, which the
   orientation and the embedding use (the weights stay on the real mesh);
2. **orient** (:mod:`.orient`): up and forward given, or a few hypotheses guessed
   (:func:`.orient.hypotheses`); in each the mesh is turned into rigedit's frame (+Y up,
   facing +Z), keeps its units, and is moved to stand on y = 0 centred over the origin in
   x and z (``report.transform``, input -> rig);
3. **embedding** (:mod:`rigedit.embedding`, Baran and Popovic's Pinocchio): every template
   joint placed inside the mesh, in each hypothesis; each result checked as a rigger would
   (:mod:`.confidence`) and scored, the best kept (:mod:`.embed_trials`,
   :mod:`.orient_search`). A failed check or a runner-up within the margin makes the result
   NOT SURE (``report.sure``, ``report.reasons``, ``report.doubtful``);
4. **skeleton** (:mod:`.joint_frames`): the template's names, hierarchy and deform flags on
   the embedded positions, each joint's frame turned as its bone is, so bone rolls stay as
   the template's animator made them and the template's clips mean the same motion;
5. **weights**: bone heat (or another method of :mod:`rigedit.binding.weights`) on the whole
   mesh, small parts included;
6. **clips**: each template clip through :func:`rigedit.rigging.retarget.pipeline.retarget` (bones
   made to point as the template's in model space, root motion scaled by leg length, feet
   held during contacts), so the character walks at once.
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ...progress import adapt, scaled
from .embed_trials import Trials, embed_best, turned_hints, verdict
# build_skeleton and AutorigReport were this module's before they were split off: they
# stay importable from here, as load_template and template_poses are
from .joint_frames import build_skeleton
from .mesh_check import check_mesh, read_mesh
from .orient import check_axes, hypotheses
from .report import AutorigReport
from .templates import load_template, template_poses, upright

__all__ = ["autorig", "AutorigReport", "load_template", "template_poses", "build_skeleton",
           "STAGES"]

#: Progress bands of the stages (start, end) as fractions of the whole run.
STAGES = {"load/check": (0.0, 0.05), "orient": (0.05, 0.1), "embedding": (0.1, 0.6),
          "skeleton": (0.6, 0.62), "weights": (0.62, 0.85), "clips": (0.85, 1.0)}


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
    stages = _Stages(progress)
    with stages.timed("load/check") as band:
        band(0.0)
        check_axes(up, forward)          # a usage error before any file is read
        t_rig, t_sk, t_name = load_template(template)
        poses = template_poses(t_sk, t_rig, t_name)
        source, vertices, faces, surface = _read(mesh)
        checks = check_mesh(vertices, faces, source)
    with stages.timed("orient") as band:
        band(0.0)
        body_v, body_f = checks.embedding_mesh()     # the body, or a watertight proxy of it
        stands_tall = upright(poses[0][0])
        frames = hypotheses(body_v, body_f, upright=stands_tall, up=up, forward=forward)
    with stages.timed("embedding") as band:
        trials = Trials(vertices, body_v, body_f, poses, _template_mesh(t_rig), hints,
                        stands_tall, source, len(frames), band)
        tried, (emb, place, t_sk, t_pose) = embed_best(trials, frames, t_name)
        orientation, confidence = verdict(tried[0], tried, frames, stands_tall)
    stages.seconds.update((f"embedding/{k}", v) for k, v in emb.seconds.items())
    with stages.timed("skeleton"):
        skeleton = build_skeleton(t_sk, emb.positions)
        skeleton.deform[[skeleton.names.index(n) for n in emb.outside]] = False
    with stages.timed("weights") as band:
        rig = _weighted_rig(skeleton, vertices @ place[:3, :3].T + place[:3, 3], faces,
                            weights, source, surface, band)
    with stages.timed("clips") as band:
        clip_notes = _template_clips(rig, t_rig, band) if clips else {}
    stages.band("clips")(1.0)
    stages.seconds["total"] = time.perf_counter() - stages.start
    rig.meta.autorig_report = AutorigReport(
        source, t_name, orientation, place, checks, stages.seconds, emb.cost,
        list(emb.placed), clip_notes, t_pose, list(emb.outside),
        embedded=np.array(emb.positions), hints=turned_hints(hints, place),
        sure=bool(confidence.sure), reasons=list(confidence.reasons),
        doubtful=list(confidence.doubtful), orientations=[t.describe() for t in tried])
    rig.meta.notes["autorig"] = (f"template {t_name}; orientation {orientation.describe()}")
    return rig


class _Stages:
    """The run's stages (:data:`STAGES`): each one's band of ``progress``, and its wall
    seconds (``seconds``, in the order run; ``start``: when the run began)."""

    def __init__(self, progress):
        self.tell = adapt(progress)
        self.seconds = {}
        self.start = time.perf_counter()

    def band(self, stage):
        """The progress callable(fraction) of ``stage``'s band."""
        lo, hi = STAGES[stage]
        return scaled(self.tell, lo, hi, stage)

    @contextmanager
    def timed(self, stage):
        """Time the block as ``stage`` (not when it raises); it gets the stage's band."""
        t0 = time.perf_counter()
        yield self.band(stage)
        self.seconds[stage] = time.perf_counter() - t0


def _weighted_rig(skeleton, rig_v, faces, weights, source, surface, progress):
    """The new character: ``skeleton`` and the mesh placed (``rig_v`` (V, 3), ``faces``),
    its skin weights computed by ``weights`` (the method)."""
    from ...binding.weights import compute_weights
    from ...rig import Rig

    idx, w = compute_weights(rig_v, skeleton, weights, faces=faces, progress=progress)
    rig = Rig(skeleton, rig_v, faces, idx, w, name=Path(source).stem if source != "mesh"
              else "autorig", up="y", weights_method=weights, surface=surface)
    rig.weights_computed = True
    return rig


def _read(mesh):
    """``(source, vertices (V, 3), faces (F, 3), surface)`` of a mesh file or a pair of
    arrays (``source`` names it: the path, or ``"mesh"``; no surface for arrays)."""
    if isinstance(mesh, (str, Path)):
        vertices, faces, surface = read_mesh(mesh, with_surface=True)
        return str(mesh), vertices, faces, surface
    vertices, faces = _arrays(mesh)
    return "mesh", vertices, faces, None


def _template_mesh(t_rig):
    """The template's own mesh in its rest pose, ``(vertices, faces)``, or None."""
    if t_rig is not None and len(t_rig.vertices) and len(t_rig.faces):
        return (t_rig.skin(t_rig.rest_pose()), t_rig.faces)   # the rest pose's, as the joints
    return None


def _template_clips(rig, t_rig, progress):
    """Each template clip retargeted onto ``rig`` (into ``rig.clips``): ``{clip: "retargeted"
    or why it was left out}``, empty for a template without clips."""
    if t_rig is None or not t_rig.clips:
        return {}
    from ..retarget.pipeline import retarget

    notes = {}
    names = sorted(t_rig.clips)
    for i, clip_name in enumerate(names):
        progress(i / len(names))
        try:
            step = scaled(progress, i / len(names), (i + 1) / len(names))
            rig.clips[clip_name] = retarget(t_rig, t_rig.clips[clip_name], rig, progress=step)
            notes[clip_name] = "retargeted"
        except ValueError as exc:  # a clip the retargeting cannot carry: say why
            notes[clip_name] = f"left out: {exc}"
    return notes
