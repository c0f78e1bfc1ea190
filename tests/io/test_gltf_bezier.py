"""Bezier tracks written to glTF: CUBICSPLINE with the exact tangents where the curves are
Hermites in time (read back, sampling equals the curves' within 1e-6), STEP for constant
curves, else resampled as LINEAR within the stated tolerance with a warning."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from builders import cylinder_rig
from rigedit.animation import Clip, Track
from rigedit.animation.curve import Curve
from rigedit.io.gltf_bezier import TOLERANCE, BezierResampledWarning
from rigedit.io.gltf_read import load_gltf
from rigedit.io.gltf_write import save_gltf

TIMES = np.linspace(0, 1.6, 161)


def round_trip(tmp_path, tracks, recwarn=None):
    rig = cylinder_rig(with_clip=False)
    rig.clips = {"c": Clip("c", rig.skeleton, tracks, duration=2.0)}
    back = load_gltf(save_gltf(rig, tmp_path / "b.glb"))
    return rig.clips["c"], back.clips["c"]


def hermite_curves():
    """Curves whose segments are all Hermites in time, with keys at different times."""
    a = Curve([0, 0.5, 1.2], [0, 1, -0.5]).with_interpolation([1], "linear")
    b = Curve([0.1, 0.7, 1.5], [2, 2.5, 2], left_type="auto", right_type="auto")
    c = Curve([0, 1.5], [1, 1], "constant")     # flat: a hold is a Hermite too
    return a, b, c


def test_hermite_curves_are_written_as_cubicspline_exactly(tmp_path):
    track = Track.from_curves("translation", hermite_curves())
    clip, back = round_trip(tmp_path, {("j1", "translation"): track})
    got = back.tracks[("j1", "translation")]
    assert got.interpolation == "cubic_spline"
    np.testing.assert_allclose(got.times, track.times, atol=1e-6)
    err = max(np.abs(got.sample(t) - track.sample(t)).max() for t in TIMES)
    assert err < 1e-6


def test_constant_curves_are_written_as_step(tmp_path):
    curves = [Curve([0, 0.5, 1], [0, 1, 2], "constant"), Curve([0], [1.0]),
              Curve([0.25], [3.0])]
    track = Track.from_curves("scale", curves)
    _, back = round_trip(tmp_path, {("j1", "scale"): track})
    got = back.tracks[("j1", "scale")]
    assert got.interpolation == "step"
    for t in TIMES:
        np.testing.assert_allclose(got.sample(t), track.sample(t), atol=1e-6)


@pytest.mark.parametrize("case", ["free_handles", "steps_mixed", "rotation"])
def test_other_bezier_tracks_are_resampled_within_the_tolerance(tmp_path, case):
    a, b, c = hermite_curves()
    if case == "free_handles":
        a = a.with_handle(0, "right", (0.05, 2.0))     # a handle at another time span
        channel, curves = "translation", (a, b, c)
    elif case == "steps_mixed":
        channel, curves = "translation", (a.with_interpolation([0], "constant"), b, c)
    else:
        q = Rotation.from_rotvec(np.radians([[0, 0, 0], [40, 10, 0], [0, 90, 30],
                                             [10, 0, 170]])).as_quat()
        curves = Track("rotation", [0, 0.4, 1.0, 1.5], q, "slerp").with_interpolation(
            "bezier").curves
        channel = "rotation"
    track = Track.from_curves(channel, curves)
    with pytest.warns(BezierResampledWarning, match="resampled as LINEAR: "):
        _, back = round_trip(tmp_path, {("j1", channel): track})
    got = back.tracks[("j1", channel)]
    assert got.interpolation in ("linear", "slerp")
    errs = []
    for t in np.linspace(0, 1.6, 801):
        x, y = track.sample(t), got.sample(t)
        if channel == "rotation":
            errs.append(np.degrees(2 * np.arccos(min(1.0, abs(float(np.dot(x, y)))))))
        elif case == "steps_mixed" and np.any(np.abs(t - a.times[1]) < 2e-4):
            continue    # the jump is a key 1e-4 s before the step
        else:
            errs.append(np.abs(x - y).max())
    # the tolerance holds at sample midpoints; between, a little more (2x covers it here)
    assert max(errs) < 2 * TOLERANCE[channel] + 1e-6


def test_bvh_export_samples_bezier_curves_between_keys(tmp_path):
    from rigedit.io.bvh_write import bvh_frame_times
    rig = cylinder_rig()
    clip = rig.clips["bend"]          # keys at 0, 0.5, 1: a BVH at the key rate has 3 frames
    assert len(bvh_frame_times(clip)[0]) == 3
    curves = clip.tracks[("j1", "rotation")].with_interpolation("bezier").curves
    clip.set_track("j1", "rotation", Track.from_curves(
        "rotation", [c.with_handle_type(range(3), "auto_clamped") for c in curves]))
    times, dt = bvh_frame_times(clip)
    assert dt == pytest.approx(0.5 / 15) and len(times) == 31
    # the frames hold the curve's values (eased by the auto-clamped handles), not a line
    z = [clip.sample(t).get_euler("j1", degrees=True)[2] for t in times[:16]]
    assert z[3] < 60 * times[3] / 0.5 - 1 and z[15] == pytest.approx(60, abs=1e-6)


def test_khronos_validator_accepts_bezier_exports(tmp_path):
    import json
    import subprocess
    import warnings

    from test_gltf_write import _validator
    script = _validator()
    a, b, c = hermite_curves()
    q = Rotation.from_rotvec(np.radians([[0, 0, 0], [40, 10, 0], [0, 90, 30]])).as_quat()
    tracks = {("j0", "translation"): Track.from_curves("translation", (a, b, c)),
              ("j1", "scale"): Track.from_curves("scale", [Curve([0, 1], [1, 2], "constant")] * 3),
              ("j2", "rotation"): Track("rotation", [0, 0.5, 1.0], q).with_interpolation("bezier")}
    rig = cylinder_rig(with_clip=False)
    rig.clips = {"c": Clip("c", rig.skeleton, tracks, duration=2.0)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BezierResampledWarning)
        out = save_gltf(rig, tmp_path / "b.glb")
    run = subprocess.run(["node", script, str(out)], capture_output=True, text=True, timeout=120)
    report = json.loads(run.stdout)
    assert report["issues"]["numErrors"] == 0 and report["issues"]["numWarnings"] == 0, \
        report["issues"]["messages"][:5]
    import pygltflib
    samplers = pygltflib.GLTF2().load(str(out)).animations[0].samplers
    assert {s.interpolation for s in samplers} == {"CUBICSPLINE", "STEP", "LINEAR"}
