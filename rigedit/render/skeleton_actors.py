"""The skeleton's actors: one line per bone, and what a rig without a mesh shows instead.

A rig with a mesh draws its bones as thin lines (hidden unless asked for); a mesh-less rig
(a BVH skeleton) draws them bolder, with a ball per deforming joint and a segment to each
End-Site tail, so it reads on its own. :class:`~rigedit.render.scene.RigScene` owns these
actors and moves them each frame. Never imports Qt.
"""
from __future__ import annotations

import numpy as np
import pyvista as pv

__all__ = ["BONE_COLOR", "CARRIER_COLOR", "add_bones", "BareSkeleton"]

BONE_COLOR = "#2f6fd6"
#: A carrier root's "bone" (from the floor or the origin up to the hips): thin and dim, a
#: line that shows what carries the figure without reading as a limb. A mid grey, so it is
#: quiet over the editor's dark background and the recorder's light one alike
CARRIER_COLOR = "#7f8896"
#: Line widths in pixels: (bone, carrier's) with a mesh, and bold (a skeleton alone)
WIDTHS = {False: (3, 1), True: (5, 2)}


def add_bones(plotter, skeleton, bold=False, carriers=None):
    """Add one line per bone at the bind pose; a carrier's lines to its children in an
    actor of their own, thin and in :data:`CARRIER_COLOR`.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    skeleton : Skeleton
    bold : bool
        Wider lines, for a skeleton shown without a mesh.
    carriers : (J,) bool, optional
        Carrier roots (:func:`rigedit.render.camera.figure_joints`); a non-deforming root
        counts as one either way.

    Returns
    -------
    bones : pyvista.PolyData
        One point per joint (its position), one line per bone but the carriers', one dot
        (vertex cell) per joint but the carriers.
    actor : vtk.vtkActor
    carrier_actor : vtk.vtkActor or None
        The carriers' lines (``rig-carrier-bones``), sharing ``bones``' points; None for a
        rig without a carrier.
    """
    sk = skeleton
    carrier = (sk.parents < 0) & ~sk.deform
    if carriers is not None:
        carrier = carrier | np.asarray(carriers, dtype=bool)
    has_parent = sk.parents >= 0
    from_carrier = has_parent & carrier[np.maximum(sk.parents, 0)]
    bones = pv.PolyData(sk.bind_matrices[:, :3, 3].copy())
    width, thin = WIDTHS[bool(bold)]
    child = np.flatnonzero(has_parent & ~from_carrier)
    if len(child):
        bones.lines = _lines(sk.parents, child)
    if carrier.any():   # each joint is also a dot (pyvista's vertex cells): not a carrier
        kept = np.flatnonzero(~carrier)
        bones.verts = np.column_stack([np.ones(len(kept), int), kept]).ravel()
    actor = plotter.add_mesh(bones, color=BONE_COLOR, line_width=width,
                             render_lines_as_tubes=False, name="rig-bones",
                             reset_camera=False)
    carried = np.flatnonzero(from_carrier)
    carrier_actor = None
    if len(carried):
        lines = pv.PolyData()
        lines.SetPoints(bones.GetPoints())   # moved with the bones, no copy per frame
        lines.lines = _lines(sk.parents, carried)
        carrier_actor = plotter.add_mesh(lines, color=CARRIER_COLOR, line_width=thin,
                                         render_lines_as_tubes=False,
                                         name="rig-carrier-bones", reset_camera=False,
                                         pickable=False)
    return bones, actor, carrier_actor


def _lines(parents, child):
    """VTK line cells from each joint of ``child`` to its parent."""
    return np.column_stack([np.full(len(child), 2), parents[child], child]).ravel()


class BareSkeleton:
    """Joint balls and End-Site tail segments: what a mesh-less rig shows.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    rig : Rig

    Attributes
    ----------
    joints : pyvista.PolyData
        One point per deforming joint.
    joint_actor : vtk.vtkActor
    tails : pyvista.PolyData or None
        Two points per joint with a tail (the joint, then its tail), one line each.
    """

    def __init__(self, plotter, rig):
        self.rig = rig
        model = rig.skeleton.bind_matrices
        # no ball for a root that only carries the figure (it stays on the floor)
        self._balls = np.flatnonzero(rig.skeleton.deform)
        self.joints = pv.PolyData(model[self._balls, :3, 3].copy())
        self.joint_actor = plotter.add_mesh(self.joints, color=BONE_COLOR, point_size=11,
                                            render_points_as_spheres=True, name="rig-joints",
                                            reset_camera=False)
        self.tails = None
        joints, tails = rig.posed_tails(model)
        n = len(joints)
        if n:
            self.tails = pv.PolyData(np.vstack([model[joints, :3, 3], tails]))
            self.tails.lines = np.column_stack([np.full(n, 2), np.arange(n),
                                                np.arange(n) + n]).ravel()
            plotter.add_mesh(self.tails, color=BONE_COLOR, line_width=5, name="rig-tails",
                             reset_camera=False)

    def update(self, model):
        """Move the balls and tails to the pose of ``model`` (J, 4, 4) float64."""
        self.joints.points[:] = model[self._balls, :3, 3]
        self.joints.Modified()
        if self.tails is not None:
            joints, tails = self.rig.posed_tails(model)
            self.tails.points[:] = np.vstack([model[joints, :3, 3], tails])
            self.tails.Modified()
