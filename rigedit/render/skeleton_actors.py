"""The skeleton's actors: one line per bone, and what a rig without a mesh shows instead.

A rig with a mesh draws its bones as thin lines (hidden unless asked for); a mesh-less rig
(a BVH skeleton) draws them bolder, with a ball per deforming joint and a segment to each
End-Site tail, so it reads on its own. :class:`~rigedit.render.scene.RigScene` owns these
actors and moves them each frame. Never imports Qt.
"""
from __future__ import annotations

import numpy as np
import pyvista as pv

__all__ = ["BONE_COLOR", "add_bones", "BareSkeleton"]

BONE_COLOR = "#2f6fd6"


def add_bones(plotter, skeleton, bold=False):
    """Add one line per bone at the bind pose.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    skeleton : Skeleton
    bold : bool
        Wider lines, for a skeleton shown without a mesh.

    Returns
    -------
    bones : pyvista.PolyData
        One point per joint (its position), one line per bone.
    actor : vtk.vtkActor
    """
    # No line from a non-deforming root (a ground-level carrier) to its children: that
    # "bone" moves no skin and would cut through the body down to the floor.
    sk = skeleton
    carrier = (sk.parents < 0) & ~sk.deform
    child = np.flatnonzero((sk.parents >= 0) & ~carrier[np.maximum(sk.parents, 0)])
    lines = np.column_stack([np.full(len(child), 2), sk.parents[child], child]).ravel()
    bones = pv.PolyData(sk.bind_matrices[:, :3, 3].copy())
    if len(child):
        bones.lines = lines
    actor = plotter.add_mesh(bones, color=BONE_COLOR, line_width=5 if bold else 3,
                             render_lines_as_tubes=False, name="rig-bones",
                             reset_camera=False)
    return bones, actor


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
