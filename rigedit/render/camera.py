"""The camera: where a character's front and up are, presets that frame it, copying a view.

The interactive view (:meth:`RigScene.view <rigedit.render.scene.RigScene.view>`) and the
off-screen recorder (:func:`rigedit.render.recorder.record_clip`) point their cameras with
the same functions: :func:`frame_view` turns a preset ("front", "side", "top", "back") and an
angle into a camera placed at the distance where the given points just fit the window;
:func:`swept_points` gives the points a clip's motion covers so a recording frames the whole
motion; :func:`camera_state` and :func:`apply_camera` copy the editor's view into a recording.
What is framed and followed is the figure: a carrier root (:mod:`rigedit.model.carrier`: a
joint at the origin or on the floor that only carries the figure, which may walk metres away
from it) is neither framed nor followed (:func:`figure_joints`). Never imports Qt.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ..model.carrier import carrier_joints, figure_root

__all__ = ["up_vector", "front_vector", "turn_about", "horizontal", "joint_points",
           "rest_points", "frame_view", "fit_distance", "swept_points", "camera_state",
           "apply_camera", "figure_joints"]


def up_vector(up):
    """(3,) unit vector of the vertical axis ``"y"`` or ``"z"``."""
    return np.array([0.0, 1.0, 0.0]) if up == "y" else np.array([0.0, 0.0, 1.0])


def front_vector(up):
    """(3,) direction from the character towards a camera that sees its front.

    Y-up characters (glTF, the bundled ones) face +Z; Z-up ones (Blender exports such as the
    elk project) face -Y.
    """
    return np.array([0.0, 0.0, 1.0]) if up == "y" else np.array([0.0, -1.0, 0.0])


def turn_about(vector, axis, degrees):
    """``vector`` (3,) turned by ``degrees`` about the unit ``axis`` (right-handed)."""
    return Rotation.from_rotvec(np.radians(degrees) * np.asarray(axis, float)).apply(vector)


def horizontal(offset, up):
    """The part of ``offset`` (3,) perpendicular to the unit ``up`` axis."""
    return offset - np.dot(offset, up) * up


def joint_points(rig, model, carriers=None):
    """(J + T, 3) what a mesh-less rig shows of a pose: its joints and bone tails.

    Parameters
    ----------
    rig : Rig
    model : (J, 4, 4) float64
        Model matrices of the pose.
    carriers : (J,) bool, optional
        Joints to leave out, with their tails (carrier roots: :func:`figure_joints`).
    """
    if carriers is None or not np.any(carriers):
        return np.vstack([model[:, :3, 3], rig.posed_tails(model)[1]])
    owners, tails = rig.posed_tails(model)
    keep = ~np.asarray(carriers)
    return np.vstack([model[keep, :3, 3], tails[keep[np.asarray(owners, dtype=int)]]])


def figure_joints(rig, clip=None, samples=12):
    """The rig's carrier roots and the joint the camera follows (the figure's root).

    Parameters
    ----------
    rig : Rig
    clip : Clip, optional
        Carriers are judged over ``samples`` poses of it (a carrier may stand at the figure's
        feet at rest and metres away during the clip); the rest pose without one.

    Returns
    -------
    carriers : (J,) bool
    follow : int
        The joint whose horizontal motion the camera follows: the topmost carrier that
        travels with the figure (the bundled characters' root, on the floor under the hips:
        smoother than the hips' sway), else the first joint below the carriers (the hips,
        when the carrier stays behind at the origin), else joint 0.
    """
    sk = rig.skeleton
    pose = rig.rest_pose()
    if clip is None or not clip.tracks:
        poses = [rig.joint_matrices(pose)[:, :3, 3]]
    else:
        poses = [rig.joint_matrices(clip.sample(t, out=pose))[:, :3, 3]
                 for t in np.linspace(0.0, clip.duration, samples)]
    poses = np.stack(poses)
    up = up_vector(rig.up)
    carriers = carrier_joints(sk.parents, poses, up)
    root = figure_root(sk.parents, carriers)
    reach = 0.25 * (float(np.ptp(poses[:, ~carriers] @ up)) or 1.0)
    along = []
    for c in np.flatnonzero(carriers):
        gap = poses[:, c] - poses[:, root]
        if np.all(np.linalg.norm(gap - (gap @ up)[:, None] * up, axis=1) < reach):
            along.append(int(c))
    return carriers, along[0] if along else root


def rest_points(rig, samples=12):
    """(N, 3) points the default camera and the floor are fitted to: a sample of the
    mesh's vertices; for a rig without a mesh, its joints and bone tails over its first
    clip (a BVH skeleton's rest pose is arbitrary, its motion is what is shown), or at
    bind time when it has no clip."""
    if len(rig.vertices) > 0:
        # the skinned rest pose, not the bind-space vertices: a glTF mesh may be stored in
        # a frame of its own (CesiumMan's is Z up) that only its joints place
        return rig.skin(rig.rest_pose())[::max(1, len(rig.vertices) // 4000)]
    clip = next(iter(rig.clips.values()), None)
    carriers, _ = figure_joints(rig, clip, samples)
    if clip is None or not clip.tracks:
        return joint_points(rig, rig.skeleton.bind_matrices, carriers)
    pose = rig.rest_pose()
    return np.concatenate([joint_points(rig, rig.joint_matrices(clip.sample(t, out=pose)),
                                        carriers)
                           for t in np.linspace(0.0, clip.duration, samples)])


def frame_view(plotter, up, front, points, name="front", angle=0.0, distance=None,
               target=None):
    """Point ``plotter``'s camera at the character and frame it.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    up, front : (3,) float
        The character's unit vertical axis and the direction it faces
        (:func:`up_vector`, :func:`front_vector`).
    points : (N, 3) float
        What must be in frame (for example :func:`rest_points`, or :func:`swept_points`
        for a recording, so raised hands and swinging legs stay in frame).
    name : {"front", "side", "top", "back"}
    angle : float
        Degrees turned about the vertical axis (counter-clockwise seen from above).
    distance : float, optional
        Camera distance in units of the character's largest extent; by default the
        distance at which ``points`` just fit the window, plus a margin.
    target : (3,) float, optional
        Point looked at; the centre of the points' bounding box when omitted.
    """
    points = np.asarray(points, dtype=float)
    lo, hi = points.min(axis=0), points.max(axis=0)
    center = 0.5 * (lo + hi) if target is None else np.asarray(target, dtype=float)
    extent = float(np.max(hi - lo)) or 1.0
    side = np.cross(up, front)  # the character's left, seen from the front
    direction = {"front": front, "back": -front, "side": -side, "top": up}[name]
    if name != "top":
        direction = turn_about(direction, up, angle)
        direction = direction + 0.15 * up  # a little from above, as a person sees it
    direction = direction / np.linalg.norm(direction)
    cam_up = -front if name == "top" else up
    cam = plotter.camera
    if distance is None:
        dist = fit_distance(points, center, direction, cam_up, cam.view_angle,
                            plotter.window_size)
    else:
        dist = distance * extent
    cam.focal_point = center
    cam.position = center + direction * dist
    cam.up = cam_up
    plotter.reset_camera_clipping_range()


def fit_distance(points, center, direction, cam_up, view_angle, window_size, margin=1.08):
    """Distance along ``direction`` at which all ``points`` fit a viewport of
    ``window_size`` (width, height): a point at lateral offset ``a`` and depth ``z`` towards
    the camera needs ``a / tan + z``."""
    corners = points - center
    up = cam_up - np.dot(cam_up, direction) * direction
    up /= np.linalg.norm(up)
    right = np.cross(direction, up)
    width, height = window_size
    aspect = width / height if width > 1 and height > 1 else 4.0 / 3.0  # not shown yet
    tan_v = np.tan(np.radians(view_angle) / 2.0)
    tan_h = tan_v * aspect
    depth = corners @ direction  # corners nearer the camera need more room
    need_v = np.abs(corners @ up) / tan_v + depth
    need_h = np.abs(corners @ right) / tan_h + depth
    return margin * float(max(need_v.max(), need_h.max()))


def swept_points(rig, clip, times, samples=12, per_frame=3000):
    """Vertices the clip sweeps over the recorded times, with the figure root's horizontal
    motion taken out (the camera follows it: :func:`figure_joints`), to frame the whole
    motion. A rig without a mesh is framed by its joints (and bone tails) instead, carrier
    roots left out.

    Returns
    -------
    points : (N, 3) float64
    """
    step = max(1, len(rig.vertices) // per_frame)
    if clip is None:
        return rig.vertices[::step] if len(rig.vertices) else rig.bounds()
    up = up_vector(rig.up)
    carriers, follow = figure_joints(rig, clip, samples)
    pose = rig.rest_pose()
    pts, root0 = [], None
    for t in np.linspace(times[0], times[-1], min(samples, len(times))):
        clip.sample(t, out=pose)
        model = rig.joint_matrices(pose)
        root = model[follow, :3, 3]
        root0 = root if root0 is None else root0
        shown = rig.skin(pose)[::step] if len(rig.vertices) else \
            joint_points(rig, model, carriers)
        pts.append(shown - horizontal(root - root0, up))
    return np.concatenate(pts)


def camera_state(camera):
    """The parts of a VTK/pyvista camera that :func:`record_clip
    <rigedit.render.recorder.record_clip>` copies, as plain data."""
    return {"position": tuple(camera.position), "focal_point": tuple(camera.focal_point),
            "up": tuple(camera.up), "view_angle": float(camera.view_angle),
            "parallel_projection": bool(camera.parallel_projection),
            "parallel_scale": float(camera.parallel_scale)}


def apply_camera(camera, state):
    """Set a pyvista camera from :func:`camera_state`'s dictionary."""
    camera.position, camera.focal_point = state["position"], state["focal_point"]
    camera.up = state["up"]
    if "view_angle" in state:
        camera.view_angle = state["view_angle"]
    if state.get("parallel_projection"):
        camera.parallel_projection = True
        camera.parallel_scale = state.get("parallel_scale", camera.parallel_scale)
