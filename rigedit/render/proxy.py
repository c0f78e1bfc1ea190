"""A decimated stand-in for a big skinned mesh, drawn while the character moves.

Software OpenGL draws about 3 million triangles a second at 1280x720 here, so a mesh of
500,000 triangles cannot follow a drag at 10 frames/s. As professional tools do, the view
then draws a *proxy* while a joint is dragged or a clip plays: the mesh decimated with
``vtkDecimatePro`` keeping its topology (vertex clustering, ten times faster, left thousands
of holes and non-manifold edges in it, which showed as dark speckles all over the skin),
skinned with the weights of the vertices it kept, and the full mesh again once the motion
stops. Decimating 540k triangles takes several seconds, so the editor builds it in a worker
thread (VTK releases Python's lock while it runs); :class:`~rigedit.render.scene.RigScene`
holds one and switches.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyvista as pv
from vtkmodules.vtkFiltersCore import vtkDecimatePro
from scipy.spatial import cKDTree

from ..model.skinning import SkinBinding

__all__ = ["SkinProxy", "ProxyActor", "build_proxy", "faces_to_vtk", "write_skin",
           "PROXY_MIN_FACES", "PROXY_TARGET_FACES"]

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


def faces_to_vtk(faces):
    """(F, 3) triangles -> pyvista's flat ``[3, a, b, c, ...]`` cell array."""
    faces = np.asarray(faces, dtype=np.int64)
    return np.hstack([np.full((len(faces), 1), 3, dtype=np.int64), faces]).ravel()


def _copy_influences(binding, points, source):
    """A SkinBinding of ``points`` (P, 3) with the influences (and morph targets) of
    ``binding``'s vertices ``source`` (P,)."""
    morphs = None if binding.morphs is None else binding.morphs.subset(source)
    return SkinBinding(points, binding.indices[source], binding.weights[source],
                       binding.num_joints, morphs=morphs)


def _decimate(vertices, faces, target_faces):
    """(vertices, faces) of the mesh decimated to about ``target_faces`` triangles, its
    topology kept (no holes opened, no edges made non-manifold); the vertices are a subset
    of the input's."""
    mesh = pv.PolyData(np.asarray(vertices, float), faces_to_vtk(faces))
    decimate = vtkDecimatePro()
    decimate.SetInputData(mesh)
    decimate.SetTargetReduction(max(0.0, 1.0 - target_faces / max(len(faces), 1)))
    decimate.PreserveTopologyOn()
    decimate.SplittingOff()
    decimate.BoundaryVertexDeletionOff()
    decimate.Update()
    out = pv.wrap(decimate.GetOutput())
    cells = out.faces.reshape(-1, 4)[:, 1:].astype(np.int64)
    return np.asarray(out.points, dtype=np.float64), cells


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
        Each proxy vertex takes the influences of the nearest full-mesh vertex in the bind
        pose: the one it was (decimation keeps a subset of the vertices in place).
    """
    rest = np.asarray(binding.rest_vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    points, cells = _decimate(rest, faces, target_faces)
    _, source = cKDTree(rest).query(points)
    source = np.asarray(source, dtype=np.int64)
    return SkinProxy(points, cells, source, _copy_influences(binding, points, source),
                     len(faces))


def write_skin(mesh, points, normals=None):
    """Write skinned ``points`` (V, 3) and, if given, ``normals`` (V, 3) into ``mesh`` (a
    PolyData with a "Normals" point array then) in place, and mark them changed for VTK."""
    if normals is not None:
        mesh.point_data["Normals"][:] = normals
        mesh.GetPointData().GetNormals().Modified()
    mesh.points[:] = points
    mesh.GetPoints().Modified()
    mesh.Modified()


def _bind_normals(proxy, rest_normals):
    """Give ``proxy``'s binding its vertices' rest normals: the full mesh's ``rest_normals``
    (V, 3) of their source vertices, returned (P, 3) float64."""
    normals = np.asarray(rest_normals, dtype=np.float64)[proxy.source]
    proxy.binding.bind_normals(normals)
    return normals


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
    rest_normals : (V, 3) float
        The full mesh's unit rest normals: each proxy vertex takes its source vertex's, so
        the proxy shades as smoothly as the mesh in spite of its long, thin triangles.
    texture : pyvista.Texture, optional
    tcoords : (V, 2) float, optional
        The full mesh's texture coordinates (each proxy vertex takes its source's).
    """

    def __init__(self, plotter, proxy, mesh_actor, rest_normals, texture=None, tcoords=None):
        self.plotter = plotter
        self.proxy = proxy
        mesh = pv.PolyData(proxy.vertices.astype(np.float32), faces_to_vtk(proxy.faces))
        rest_normals = _bind_normals(proxy, rest_normals)
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

    def rebind(self, proxy, rest_normals):
        """Draw ``proxy``, this one's geometry re-bound (:meth:`SkinProxy.rebind`), in the
        same actor; ``rest_normals`` as in the constructor. Skinned by the next
        :meth:`skin`."""
        _bind_normals(proxy, rest_normals)
        self.proxy = proxy

    def set_visible(self, on):
        self.actor.SetVisibility(bool(on))

    def skin(self, palette, method="lbs", morph_weights=None):
        """Skin the proxy with ``palette`` (J, 4, 4) into its actor's points and normals,
        with the full mesh's ``morph_weights`` (M,) when it has morph targets."""
        if morph_weights is not None:
            self.proxy.binding.set_morph_weights(morph_weights)
        write_skin(self.mesh, *self.proxy.binding.skin_with_normals(palette, method=method))

    def remove(self):
        self.plotter.remove_actor(self.actor, render=False)

