"""A decimated stand-in for a big skinned mesh, drawn while the character moves.

Software OpenGL draws about 3 million triangles a second at 1280x720 here, so a mesh of
500,000 triangles cannot follow a drag at 10 frames/s. As professional tools do, the view
then draws a *proxy* while a joint is dragged or a clip plays: the mesh simplified by vertex
clustering (``vtkQuadricClustering``: each cell of a grid over the mesh becomes one vertex at
its quadric-optimal position, so it runs in a fraction of a second where quadric decimation
took 12 s on 630k triangles), skinned with weights taken from the full mesh, and the full mesh
again once the motion stops. :class:`~rigedit.render.scene.RigScene` holds one and switches.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyvista as pv
import vtk
from scipy.spatial import cKDTree

from ..model.skinning import SkinBinding

__all__ = ["SkinProxy", "ProxyActor", "build_proxy", "PROXY_MIN_FACES", "PROXY_TARGET_FACES"]

#: Meshes with more triangles than this get a proxy: the bundled characters (50-60k
#: triangles) drag at 15-20 frames/s in full here, a mesh 3x their size would not.
PROXY_MIN_FACES = 150_000
#: About how many triangles the proxy has: the bundled quadruped's size.
PROXY_TARGET_FACES = 60_000


@dataclass
class SkinProxy:
    """A simplified copy of a skinned mesh, bound to the same joints.

    Attributes
    ----------
    vertices : (P, 3) float64
        Bind-space positions (the full mesh's frame).
    faces : (G, 3) int64
    source : (P,) int64
        For each proxy vertex, the full-mesh vertex its skin weights were copied from.
    binding : SkinBinding
        The proxy's own binding: the full mesh's influences of the ``source`` vertices.
    full_faces : int
        Triangles of the mesh it stands in for.
    """

    vertices: np.ndarray
    faces: np.ndarray
    source: np.ndarray
    binding: SkinBinding
    full_faces: int

    @property
    def num_faces(self):
        return len(self.faces)

    def rebind(self, binding):
        """The same proxy bound with ``binding``'s influences (the full mesh's, re-bound)."""
        return SkinProxy(self.vertices, self.faces, self.source,
                         _copy_influences(binding, self.vertices, self.source),
                         self.full_faces)


def _copy_influences(binding, points, source):
    """A SkinBinding of ``points`` (P, 3) with the influences of ``binding``'s vertices
    ``source`` (P,)."""
    return SkinBinding(points, binding.indices[source], binding.weights[source],
                       binding.num_joints)


def _cluster(vertices, faces, target_faces):
    """(vertices, faces) of the mesh simplified by vertex clustering to about
    ``target_faces`` triangles: grid cells sized so that a surface of the mesh's area, tiled
    by two triangles per cell, has that many; coarsened if the result is much bigger."""
    mesh = pv.PolyData(np.asarray(vertices, float),
                       np.hstack([np.full((len(faces), 1), 3), faces]).ravel())
    area = float(mesh.area)
    lo, hi = np.min(vertices, axis=0), np.max(vertices, axis=0)
    cell = np.sqrt(2.0 * area / target_faces)
    out = None
    for _ in range(4):
        divisions = np.maximum(2, np.ceil((hi - lo) / cell).astype(int))
        clusters = vtk.vtkQuadricClustering()
        clusters.SetInputData(mesh)
        clusters.AutoAdjustNumberOfDivisionsOff()
        clusters.SetNumberOfDivisions(*(int(d) for d in divisions))
        clusters.UseInputPointsOff()   # each cell's optimal point, not an input vertex
        clusters.Update()
        out = pv.wrap(clusters.GetOutput())
        if out.n_cells <= 1.5 * target_faces:
            break
        cell *= np.sqrt(out.n_cells / target_faces)
    tri = out.triangulate()
    cells = tri.faces.reshape(-1, 4)[:, 1:].astype(np.int64)
    return np.asarray(tri.points, dtype=np.float64), cells


def build_proxy(binding, faces, target_faces=PROXY_TARGET_FACES):
    """A :class:`SkinProxy` of a bound mesh.

    Parameters
    ----------
    binding : SkinBinding
        The full mesh's binding: its rest vertices and influences.
    faces : (F, 3) int
    target_faces : int
        About how many triangles the proxy has.

    Returns
    -------
    SkinProxy
        Each proxy vertex takes the influences of the nearest full-mesh vertex (in the bind
        pose): clustering places a proxy vertex inside the patch of full vertices it
        replaces, so the nearest one lies on that patch and moves as the patch does.
    """
    rest = np.asarray(binding.rest_vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    points, cells = _cluster(rest, faces, target_faces)
    _, source = cKDTree(rest).query(points)
    source = np.asarray(source, dtype=np.int64)
    return SkinProxy(points, cells, source, _copy_influences(binding, points, source),
                     len(faces))


class ProxyActor:
    """A :class:`SkinProxy` drawn in a plotter: hidden until :meth:`set_visible`, sharing the
    full mesh actor's property (colour, display mode) and texture; its normals are skinned
    with its vertices.

    Parameters
    ----------
    plotter : pyvista.Plotter
    proxy : SkinProxy
    mesh_actor : vtkActor
        The full mesh's actor.
    texture : pyvista.Texture, optional
    tcoords : (V, 2) float, optional
        The full mesh's texture coordinates (each proxy vertex takes its source's).
    """

    def __init__(self, plotter, proxy, mesh_actor, texture=None, tcoords=None):
        self.plotter = plotter
        self.proxy = proxy
        faces = np.hstack([np.full((len(proxy.faces), 1), 3), proxy.faces]).ravel()
        mesh = pv.PolyData(proxy.vertices.astype(np.float32), faces)
        rest_normals = _vtk_normals(mesh)
        proxy.binding.bind_normals(rest_normals)
        mesh.point_data.set_array(rest_normals.astype(np.float32), "Normals")
        mesh.point_data.active_normals_name = "Normals"
        if tcoords is not None:
            mesh.active_texture_coordinates = np.asarray(tcoords)[proxy.source]
        self.mesh = mesh
        self.actor = plotter.add_mesh(mesh, name="rig-proxy", reset_camera=False,
                                      pickable=False, smooth_shading=True)
        self.actor.SetProperty(mesh_actor.GetProperty())
        if texture is not None:
            self.actor.SetTexture(texture)
        self.actor.SetVisibility(False)

    def set_visible(self, on):
        self.actor.SetVisibility(bool(on))

    def skin(self, palette, method="lbs"):
        """Skin the proxy with ``palette`` (J, 4, 4) into its actor's points and normals."""
        binding = self.proxy.binding
        if method == "dqs":   # its normals blended linearly: only seen while moving
            normals = binding.skin_with_normals(palette)[1].copy()
            points = binding.skin(palette, method="dqs")
        else:
            points, normals = binding.skin_with_normals(palette)
        self.mesh.point_data["Normals"][:] = normals
        self.mesh.GetPointData().GetNormals().Modified()
        self.mesh.points[:] = points
        self.mesh.GetPoints().Modified()
        self.mesh.Modified()

    def remove(self):
        self.plotter.remove_actor(self.actor, render=False)


def _vtk_normals(mesh):
    """(N, 3) point normals of ``mesh`` as the scene's normals filter computes them."""
    normals = vtk.vtkPolyDataNormals()
    normals.SetInputData(mesh)
    normals.SplittingOff()
    normals.ConsistencyOff()
    normals.AutoOrientNormalsOff()
    normals.ComputeCellNormalsOff()
    normals.Update()
    return np.asarray(pv.wrap(normals.GetOutput()).point_data["Normals"])
