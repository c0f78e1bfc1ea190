"""rigedit.io.gltf_compress: what the bound is checked on (``as_read``) is what rigedit's glTF
reader gets from the written file, and a clip over the bound as read is compressed again."""
from __future__ import annotations

import numpy as np
import pytest

import rigedit
from rigedit.compression import measure_error
from rigedit.io import gltf_compress
from rigedit.io.gltf_compress import as_read, fit_clips, save_gltf_compressed_rig


@pytest.fixture(scope="module")
def rig():
    return rigedit.load_rig("humanoid")


def test_as_read_is_what_the_reader_gets(tmp_path, rig):
    keys, _, floats = fit_clips(rig.skeleton, rig.clips, max_error=2e-4)
    assert floats == set()
    out = tmp_path / "f.glb"
    save_gltf_compressed_rig(rig, out, max_error=2e-4)
    back = rigedit.load_rig(out)
    for name, clip in keys.items():
        expected = as_read(clip)
        for t in np.linspace(0, clip.duration, 53):
            a, b = expected.sample(t), back.clips[name].sample(t)
            np.testing.assert_allclose(b.translation, a.translation, atol=1e-12)
            np.testing.assert_allclose(b.scale, a.scale, atol=1e-12)
            dots = np.abs(np.sum(a.rotation * b.rotation, axis=1))
            assert np.all(dots > 1 - 1e-12)


def test_a_clip_over_the_bound_as_read_is_compressed_again(monkeypatch, rig):
    """The first compression is made to miss (its bound ignored: 20x looser); the fit sees
    the miss on the clip as read and compresses again until it holds."""
    calls = []
    real = gltf_compress.compress_clips

    def loose_first(skeleton, clips, max_error, **kw):
        calls.append(max_error)
        return real(skeleton, clips, max_error=max_error * (20 if len(calls) == 1 else 1),
                    **kw)

    monkeypatch.setattr(gltf_compress, "compress_clips", loose_first)
    keys, report, _ = fit_clips(rig.skeleton, {"walk": rig.clips["walk"]}, max_error=1e-4)
    assert len(calls) >= 2 and calls[1] < calls[0]
    assert report.clips[0].attempts == len(calls)
    err = measure_error(rig.skeleton, rig.clips["walk"], as_read(keys["walk"]))
    assert err.max() <= 1e-4 and report.max_error == pytest.approx(err.max())


def test_a_clip_no_compression_holds_is_written_with_float_rotations(tmp_path, monkeypatch,
                                                                     rig):
    """Where the glTF target gives up (the int16 grid alone errs more than the bound), the
    clip's own keys go out with float32 rotations, said in one warning, within the bound."""
    import pygltflib

    def gives_up(*args, **kw):
        raise ValueError("clip 'walk': cannot hold max_error (test)")

    monkeypatch.setattr(gltf_compress, "compress_clips", gives_up)
    out = tmp_path / "f.glb"
    with pytest.warns(UserWarning, match="'walk'.*float32 rotations"):
        report = save_gltf_compressed_rig(rig, out, ["walk"], max_error=1e-4)
    g = pygltflib.GLTF2().load(str(out))
    rotations = [g.accessors[a.samplers[c.sampler].output] for a in g.animations
                 for c in a.channels if c.target.path == "rotation"]
    assert rotations and all(acc.componentType == 5126 for acc in rotations)
    back = rigedit.load_rig(out)
    err = measure_error(rig.skeleton, rig.clips["walk"], back.clips["walk"])
    assert err.max() <= 1e-4 and report.max_error <= 1e-4
