"""The rig's actors in a pyvista plotter: the skinned mesh, its normals, bones, floor, proxy.

Used by the interactive view and the off-screen recorder alike; never imports Qt. The mesh
is added once and its points are updated in place each frame
(docs/architecture.md, pitfalls). The camera presets and framing are
:mod:`rigedit.render.camera`'s, the bone actors :mod:`rigedit.render.skeleton_actors`'s,
the mesh's colours and display modes :mod:`rigedit.render.mesh_look`'s.
"""
from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.vtkFiltersCore import vtkPolyDataNormals

from ..model.kinematics import skinning_matrices
from . import mesh_look
from ..model.carrier import figure_root
from .camera import figure_joints, frame_view, front_vector, rest_points, up_vector
from .floor import Floor
from .proxy import ProxyActor, faces_to_vtk, write_skin
from .skeleton_actors import BareSkeleton, add_bones

__all__ = ["RigScene", "faces_to_vtk", "normals_filter"]


def normals_filter(polydata):
    """``vtkPolyDataNormals`` on ``polydata`` as the scene runs it: smooth point normals
    only (no split vertices, no cell normals), the triangles' winding taken as it is."""
    normals = vtkPolyDataNormals()
    normals.SetInputData(polydata)
    normals.SplittingOff()
    normals.ConsistencyOff()
    normals.AutoOrientNormalsOff()
    normals.ComputeCellNormalsOff()
    return normals


class RigScene:
    """Actors showing one rig in a plotter.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    rig : Rig
    show_skeleton : bool
    show_floor : bool
    skinning : {"lbs", "dqs"}
    skinned_normals : bool
        Normals blended with the vertices in one pass (``SkinBinding.skin_with_normals``)
        instead of recomputed by ``vtkPolyDataNormals`` each frame: exact in the rest pose,
        within shading noise when posed (README, Speed), with either skinning method (the
        DQS kernel turns each rest normal by the vertex's blended rotation).
    floor_style : {"plane", "lines"}
        The floor as a textured plane (the editor) or its grid lines alone (the recorder;
        see :func:`rigedit.render.floor.add_floor`).

    Attributes
    ----------
    mesh : pyvista.PolyData
        The skinned surface; its points are the current pose (updated in place).
    bones : pyvista.PolyData
        One line per bone; points are the joint positions.
    """

    def __init__(self, plotter, rig, show_skeleton=True, show_floor=True, skinning="lbs",
                 skinned_normals=True, floor_style="plane"):
        self.plotter = plotter
        self.rig = rig
        #: The skinning method of every update: "lbs" or "dqs" (``SkinBinding.skin``)
        self.skinning = skinning
        self._use_skinned_normals = bool(skinned_normals)  # see use_skinned_normals
        self._normals_binding = None  # the binding whose rest normals were computed
        self.up = up_vector(rig.up)
        self.front = front_vector(rig.up)
        #: False for a rig with no mesh (a BVH skeleton): no mesh actor, the skeleton drawn
        #: bolder with its joints as balls so it reads on its own
        self.has_mesh = len(rig.vertices) > 0
        self.mesh = pv.PolyData(rig.vertices.astype(np.float32).copy(),
                                faces_to_vtk(rig.faces) if len(rig.faces) else None)
        self.mesh_actor = None
        if self.has_mesh:
            # The filter gives the binding its rest normals (once, see _bind_rest_normals);
            # it feeds the mapper only when the normals are not skinned (a few ms a frame)
            self._normals = normals_filter(self.mesh)
            look = mesh_look.surface_look(rig, self.mesh)
            self.mesh_actor = plotter.add_mesh(self._normals, smooth_shading=True,
                                               specular=0.25, specular_power=20,
                                               name="rig-mesh", **look)
            self._texture = look.get("texture")
            self._connect_normals()
        sk = rig.skeleton
        #: (J,) bool: carrier roots (joints that only carry the figure), drawn thin and dim
        self.carriers, _ = figure_joints(rig)
        self.bones, self.bone_actor, self.carrier_actor = add_bones(
            plotter, sk, bold=not self.has_mesh, carriers=self.carriers)
        self.set_skeleton_visible(show_skeleton or not self.has_mesh)
        #: The joint balls and tails of a rig with no mesh, or None
        self.bare_skeleton = None if self.has_mesh else BareSkeleton(plotter, rig)
        #: The :class:`~rigedit.render.floor.Floor`, or None; it follows the figure's root
        #: (the hips below any carrier root) in whole cells as the pose moves
        self.floor = self._add_floor(floor_style) if show_floor else None
        self.floor_actor = None if self.floor is None else self.floor.grid_actor
        self._floor_joint = figure_root(sk.parents, self.carriers)
        self.display_mode = "solid"
        self.weights_shown = False
        self._weight_lut = None
        self.joint_positions = sk.bind_matrices[:, :3, 3].copy()
        #: A :class:`~rigedit.render.proxy.SkinProxy` drawn instead of the mesh while
        #: :attr:`proxy_shown` (see :meth:`attach_proxy`), or None
        self.proxy = self.proxy_actor = None
        self.proxy_shown = False
        self._model = None   # the last model matrices shown, to skin on a switch
        self.view("front")

    # ------------------------------------------------------------------ actors
    @property
    def use_skinned_normals(self):
        """Normals blended in the skinning pass from rest normals (VTK's, computed once)
        instead of ``vtkPolyDataNormals`` on every changed frame; setting it reconnects the
        mesh's mapper to the chosen source at once."""
        return self._use_skinned_normals

    @use_skinned_normals.setter
    def use_skinned_normals(self, on):
        self._use_skinned_normals = bool(on)
        self._connect_normals()

    @property
    def skinned_normals(self):
        """Whether the shown normals are skinned with the vertices (else VTK's filter)."""
        return self.has_mesh and self.use_skinned_normals

    def _connect_normals(self):
        """Feed the mapper the mesh itself (its "Normals" array skinned by each update) or
        the normals filter's output (recomputed from the points), as :attr:`skinned_normals`
        says."""
        if self.mesh_actor is None:
            return
        mapper = self.mesh_actor.GetMapper()
        data = self.mesh.point_data
        if self.skinned_normals:
            if "Normals" not in data:
                # until the next update: the filter's normals of the current points, or
                # the rest normals when the filter never ran
                shown = self._normals.GetOutput().GetPointData().GetNormals()
                n = self.mesh.n_points
                data.set_array(np.array(pv.convert_array(shown), np.float32)
                               if shown is not None and shown.GetNumberOfTuples() == n
                               else np.zeros((n, 3), np.float32), "Normals")
            data.active_normals_name = "Normals"
            self._bind_rest_normals()
            mapper.SetInputData(self.mesh)
        else:
            # VTK 9.7's vtkPolyDataNormals passes normals already on its input through
            # instead of computing them: the filter must see none
            if "Normals" in data:
                data.remove("Normals")
            mapper.SetInputConnection(self._normals.GetOutputPort())
        self.mesh.Modified()

    def _bind_rest_normals(self):
        """Give the rig's binding rest normals from the same filter (run once on the
        bind-space vertices), so that in the rest pose the shading is the filter's exactly
        and, posed, each normal turns with its vertex's blend. Done again when the document
        replaced the binding (a re-bind)."""
        binding = self.rig.binding
        if binding is self._normals_binding:
            return
        rest = pv.PolyData(np.asarray(binding.rest_vertices, dtype=np.float32),
                           self.mesh.GetPolys())
        self._normals.SetInputData(rest)
        self._normals.Update()
        rest_normals = np.array(pv.wrap(self._normals.GetOutput()).point_data["Normals"])
        binding.bind_normals(rest_normals)
        self._rest_normals = rest_normals
        self._normals.SetInputData(self.mesh)
        if self._normals_binding is None:  # the mesh still shows the bind-space vertices
            self.mesh.point_data["Normals"][:] = rest_normals
        self._normals_binding = binding

    def rest_points(self, samples=12):
        """(N, 3) points the default camera and the floor are fitted to
        (:func:`rigedit.render.camera.rest_points` of the rig)."""
        return rest_points(self.rig, samples)

    def _add_floor(self, style):
        points = self.rest_points()
        return Floor(self.plotter, points.min(axis=0), points.max(axis=0),
                     1 if self.rig.up == "y" else 2, self.up, style=style)

    def set_skeleton_visible(self, visible):
        for actor in (self.bone_actor, self.carrier_actor):
            if actor is not None:
                actor.SetVisibility(bool(visible))

    def put_bones_on(self, renderer, width):
        """Draw the bone lines on ``renderer`` (the editor's overlay, over the mesh), the
        bones ``width`` pixels wide and a carrier's a third of that."""
        self.bone_actor.GetProperty().SetLineWidth(width)
        self.plotter.renderer.RemoveActor(self.bone_actor)
        renderer.AddActor(self.bone_actor)
        if self.carrier_actor is not None:
            self.carrier_actor.GetProperty().SetLineWidth(max(1.0, width / 3.0))
            self.plotter.renderer.RemoveActor(self.carrier_actor)
            renderer.AddActor(self.carrier_actor)

    def set_floor_visible(self, visible):
        for name in ("rig-floor", "rig-grid"):
            actor = self.plotter.actors.get(name)
            if actor is not None:
                actor.SetVisibility(bool(visible))

    # ------------------------------------------------------------------ display modes
    def set_display_mode(self, mode):
        """Show the mesh ``"solid"``, ``"translucent"`` (see-through, with its wireframe, so
        joints inside stay visible) or ``"wireframe"``
        (:func:`rigedit.render.mesh_look.set_display_mode`)."""
        mesh_look.set_display_mode(self.mesh_actor, mode)
        self.display_mode = mode

    def show_weights(self, weights):
        """Colour the mesh by one joint's influence (weight paint view), or back to its plain
        colour when ``weights`` is None.

        Parameters
        ----------
        weights : (V,) float in [0, 1], or None
        """
        if self.mesh_actor is None:  # nothing to paint on a mesh-less rig
            self.weights_shown = False
            return
        mapper = self.mesh_actor.GetMapper()
        if weights is None:
            mapper.ScalarVisibilityOff()
            self.weights_shown = False
            if self._texture is not None:
                self.mesh_actor.SetTexture(self._texture)
            return
        if self._texture is not None:  # the heat map alone, not tinted by the texture
            self.mesh_actor.SetTexture(None)
        w = np.asarray(weights, dtype=np.float32).reshape(-1)
        if w.shape[0] != self.mesh.n_points:
            raise ValueError(f"expected {self.mesh.n_points} weights, got {w.shape[0]}")
        self.mesh.point_data["weight"] = w
        self.mesh.Modified()
        if self._weight_lut is None:
            self._weight_lut = mesh_look.weight_lut()
        mesh_look.color_by_weight(mapper, self._weight_lut)
        self.weights_shown = True

    # ------------------------------------------------------------------ proxy
    def attach_proxy(self, proxy):
        """Draw ``proxy`` (a :class:`~rigedit.render.proxy.SkinProxy` of this rig's mesh)
        instead of the mesh while :meth:`show_proxy` says so. The same proxy re-bound
        (:meth:`SkinProxy.rebind`, after a rest move) keeps its actor."""
        self.show_proxy(False)
        self._bind_rest_normals()
        if self.proxy is not None and proxy.faces is self.proxy.faces:
            self.proxy_actor.rebind(proxy, self._rest_normals)
        else:
            self.detach_proxy()
            tcoords = self.mesh.active_texture_coordinates if self._texture is not None \
                else None
            self.proxy_actor = ProxyActor(self.plotter, proxy, self.mesh_actor,
                                          self._rest_normals, self._texture, tcoords)
        self.proxy = proxy

    def detach_proxy(self):
        """Drop the proxy; the mesh is drawn again."""
        self.show_proxy(False)
        if self.proxy_actor is not None:
            self.proxy_actor.remove()
        self.proxy = self.proxy_actor = None

    def show_proxy(self, on):
        """Draw the proxy (``True``) or the full mesh; the one shown is skinned to the last
        pose at once. Returns whether that changed what is drawn."""
        on = bool(on) and self.proxy is not None
        if on == self.proxy_shown:
            return False
        self.proxy_shown = on
        self.proxy_actor.set_visible(on)
        self.mesh_actor.SetVisibility(not on)
        if self._model is not None:
            self.update_from_matrices(self._model)
        return True

    # ------------------------------------------------------------------ per frame
    def update(self, pose):
        """Skin ``pose`` and write it into the existing actors (no re-add, no render).

        Returns
        -------
        model_matrices : (J, 4, 4) float64
        """
        model = self.rig.joint_matrices(pose)
        self.update_from_matrices(model)
        return model

    def update_from_matrices(self, model, skin=True):
        """Same as :meth:`update` from model matrices already computed; ``skin=False``
        moves the bones only (the mesh keeps its points)."""
        self._model = np.array(model, dtype=float)
        if not self.has_mesh:
            self.bare_skeleton.update(model)
        elif skin and self.proxy_shown:
            self.proxy_actor.skin(skinning_matrices(self.rig.skeleton, model), self.skinning,
                                  self.rig.binding.morph_weights)
        elif skin:
            palette = skinning_matrices(self.rig.skeleton, model)
            if self.skinned_normals:
                self._bind_rest_normals()
                write_skin(self.mesh, *self.rig.binding.skin_with_normals(
                    palette, method=self.skinning))
            else:
                write_skin(self.mesh, self.rig.binding.skin(palette, method=self.skinning))
        self.joint_positions[:] = model[:, :3, 3]
        if self.floor is not None:
            self.floor.follow(self.joint_positions[self._floor_joint])
        self.bones.points[:] = self.joint_positions
        self.bones.GetPoints().Modified()
        self.bones.Modified()

    # ------------------------------------------------------------------ camera
    def view(self, name="front", angle=0.0, distance=None, target=None, points=None):
        """Point the camera at the character and frame it: :func:`frame_view
        <rigedit.render.camera.frame_view>` (which documents the parameters) with this rig's
        up and front, ``points`` a sample of the rest mesh's vertices when omitted (a
        recorder passes the vertices of several frames of its clip)."""
        if points is None:
            points = self.rest_points()
        frame_view(self.plotter, self.up, self.front, points, name, angle, distance, target)
        self._view = (name, angle, distance)

    def follow(self, offset):
        """Shift the camera by ``offset`` (3,) model units, to track root motion."""
        cam = self.plotter.camera
        cam.focal_point = np.asarray(cam.focal_point) + offset
        cam.position = np.asarray(cam.position) + offset
        self.plotter.reset_camera_clipping_range()
