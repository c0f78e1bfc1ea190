"""Contact sheets of a rig's clips (off-screen pyvista), for looking at the characters."""
from __future__ import annotations

import numpy as np

VIEWS = {"side": (1, 0, 0), "front": (0, 0, 1), "three_quarter": (0.8, 0.35, 0.8),
         "back_quarter": (-0.7, 0.3, -0.8), "top": (0.01, 1, 0.2)}


def render_frames(verts_list, faces, views, size=(320, 260), color="tan", extra=None):
    """Render each vertex array from each view direction; returns list of rows of images."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    faces_pv = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
    mesh = pv.PolyData(np.asarray(verts_list[0], float), faces_pv)
    allv = np.concatenate(verts_list)
    lo, hi = allv.min(0), allv.max(0)
    centre = (lo + hi) / 2
    radius = np.linalg.norm(hi - lo) / 2
    pl = pv.Plotter(off_screen=True, window_size=size)
    pl.set_background("white")
    # The default light kit leaves surfaces that face down-forward (a shin in the swing) dark;
    # a dim headlight keeps every visible surface readable.
    pl.add_light(pv.Light(light_type="headlight", intensity=0.45))
    pl.add_mesh(mesh, color=color, smooth_shading=True, specular=0.3)
    floor = pv.Plane(center=(centre[0], 0, centre[2]), direction=(0, 1, 0),
                     i_size=(hi[0] - lo[0]) + 2, j_size=(hi[2] - lo[2]) + 2, i_resolution=20,
                     j_resolution=20)
    pl.add_mesh(floor, color="lightgray", style="wireframe", opacity=0.5)
    rows = []
    for view in views:
        row = []
        d = np.asarray(VIEWS.get(view, view), float)
        d /= np.linalg.norm(d)
        for v in verts_list:
            mesh.points = np.asarray(v, float)
            mesh.compute_normals(inplace=True, cell_normals=False, split_vertices=False)
            pl.camera.focal_point = centre
            pl.camera.position = centre + d * radius * 3.0
            pl.camera.up = (0, 1, 0) if abs(d[1]) < 0.9 else (0, 0, 1)
            pl.camera.view_angle = 40
            pl.render()
            row.append(pl.screenshot(return_img=True))
        rows.append(row)
    pl.close()
    return rows


def sheet(rows, path, labels=None):
    """Assemble rows of images into one PNG."""
    import imageio.v3 as iio

    img = np.concatenate([np.concatenate(r, axis=1) for r in rows], axis=0)
    iio.imwrite(path, img)
    return img.shape


def clip_sheet(rig, clip_name, path, n=6, views=("side", "front", "three_quarter"),
               follow_root=True, size=(300, 240)):
    """Contact sheet of ``n`` times of a clip from several views. With ``follow_root`` the
    root's forward motion is subtracted so the character stays framed (the floor grid stays)."""
    clip = rig.clips[clip_name]
    times = np.linspace(0, clip.duration, n, endpoint=False)
    vs = []
    for t in times:
        pose = clip.sample(t)
        v = rig.skin(pose)
        if follow_root:
            v = v - [0, 0, pose.translation[0][2] - rig.skeleton.rest_translation[0][2]]
        vs.append(v)
    rows = render_frames(vs, rig.faces, views, size=size)
    return sheet(rows, path)
