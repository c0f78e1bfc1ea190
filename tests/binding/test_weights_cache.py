"""The weights cache (rigedit/binding/weights_cache.py): a second load of a folder without
weights.npz reads the weights the first computed; a changed mesh, a corrupt file or another
method misses; the size bound evicts the least recently used; off is off."""
import os
import warnings

import numpy as np
import pytest

import rigedit
import rigedit.rig
from builders import write_elk_folder
from rigedit.binding import weights_cache
from rigedit.io.data import WeightsComputedWarning


@pytest.fixture
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("RIGEDIT_CACHE_DIR", str(folder))
    monkeypatch.delenv("RIGEDIT_CACHE_MAX_MB", raising=False)
    return folder


@pytest.fixture
def elk(tmp_path):
    return write_elk_folder(tmp_path / "elk")


def _load(path, method=None):
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        rig = rigedit.load_rig(path, weights_method=method)
    said = [str(w.message) for w in seen if issubclass(w.category, WeightsComputedWarning)]
    return rig, said


def _no_compute(monkeypatch):
    def fail(*args, **kwargs):
        raise AssertionError("weights computed although they were cached")
    monkeypatch.setattr(rigedit.rig, "compute_weights", fail)


def test_second_load_reads_the_cache(cache, elk, monkeypatch):
    first, said = _load(elk)
    assert "computed weights" in said[0]
    assert len(list(cache.glob("*.npz"))) == 1
    _no_compute(monkeypatch)
    second, said = _load(elk)
    assert "from the cache" in said[0]
    assert second.weights_computed   # not from a file of the rig's
    np.testing.assert_array_equal(second.binding.indices, first.binding.indices)
    np.testing.assert_array_equal(second.binding.weights, first.binding.weights)


def test_a_changed_mesh_or_method_misses(cache, elk, monkeypatch):
    _load(elk)
    obj = next(elk.rglob("*.obj"))
    lines = obj.read_text().splitlines()
    i = next(k for k, line in enumerate(lines) if line.startswith("v "))
    x, y, z = (float(s) for s in lines[i].split()[1:4])
    lines[i] = f"v {x + 0.01} {y} {z}"
    obj.write_text("\n".join(lines) + "\n")
    calls = []
    real = rigedit.rig.compute_weights
    monkeypatch.setattr(rigedit.rig, "compute_weights",
                        lambda *a, **k: calls.append(a[2]) or real(*a, **k))
    _load(elk)
    _load(elk, method="idw")
    assert calls == ["heat", "idw"]
    assert len(list(cache.glob("*.npz"))) == 3


def test_the_key_covers_mesh_skeleton_and_method(elk):
    rig, _ = _load(elk)
    v, f, sk = rig.vertices, rig.faces, rig.skeleton
    key = weights_cache.weights_key(v, f, sk, "heat")
    assert key == weights_cache.weights_key(v.copy(), f.copy(), sk, "heat")
    moved = v.copy()
    moved[0, 0] += 1e-12
    assert weights_cache.weights_key(moved, f, sk, "heat") != key
    assert weights_cache.weights_key(v, f[::-1], sk, "heat") != key
    assert weights_cache.weights_key(v, f, sk, "idw") != key
    assert weights_cache.weights_key(v, f, sk, "heat", max_influences=3) != key
    sk.bind_matrices[1, 0, 3] += 0.01
    assert weights_cache.weights_key(v, f, sk, "heat") != key


@pytest.mark.parametrize("damage", ["cut", "garbage", "other key", "bad index"])
def test_a_corrupt_file_is_recomputed(cache, elk, monkeypatch, damage):
    first, _ = _load(elk)
    path = next(cache.glob("*.npz"))
    if damage == "cut":
        path.write_bytes(path.read_bytes()[:200])
    elif damage == "garbage":
        path.write_bytes(os.urandom(4000))
    else:
        key = "0" * 64 if damage == "other key" else path.stem
        idx = first.binding.indices.copy()
        if damage == "bad index":
            idx[0, 0] = 999
        np.savez(path, key=np.array(key), indices=idx, weights=first.binding.weights)
    calls = []
    real = rigedit.rig.compute_weights
    monkeypatch.setattr(rigedit.rig, "compute_weights",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    again, said = _load(elk)
    assert calls == [1] and "computed weights" in said[0]
    np.testing.assert_allclose(again.binding.weights, first.binding.weights)
    _no_compute(monkeypatch)   # and the file was replaced by a good one
    _load(elk)


def test_the_bound_evicts_the_least_recently_used(cache, monkeypatch):
    cache.mkdir()
    idx = np.zeros((1000, 4), np.int32)
    w = np.full((1000, 4), 0.25)
    paths = [weights_cache.store_weights(f"{k:064x}", idx, w) for k in range(3)]
    size = paths[0].stat().st_size
    for age, p in zip((300, 200, 100), paths):   # 0 is the oldest
        t = p.stat().st_mtime - age
        os.utime(p, (t, t))
    assert weights_cache.load_weights(f"{0:064x}", 1000, 1) is not None   # 0 used again
    removed = weights_cache.evict(cache, limit=2 * size)
    assert removed == [paths[1]]
    assert sorted(cache.glob("*.npz")) == sorted([paths[0], paths[2]])
    # a store keeps the folder within RIGEDIT_CACHE_MAX_MB, the new file kept
    monkeypatch.setenv("RIGEDIT_CACHE_MAX_MB", str(1.5 * size / 2 ** 20))
    new = weights_cache.store_weights(f"{9:064x}", idx, w)
    assert list(cache.glob("*.npz")) == [new]


def test_off_and_unwritable(tmp_path, monkeypatch, elk):
    monkeypatch.setenv("RIGEDIT_CACHE_DIR", "off")
    assert weights_cache.cache_folder() is None
    _load(elk)
    assert not list(tmp_path.rglob("*.npz"))
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("RIGEDIT_CACHE_DIR", str(blocker / "weights"))
    rig, said = _load(elk)      # no error: the cache is skipped
    assert "computed weights" in said[0] and len(rig.binding.weights) == len(rig.vertices)


def test_default_folder(monkeypatch, tmp_path):
    monkeypatch.delenv("RIGEDIT_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert weights_cache.cache_folder() == tmp_path / "rigedit" / "weights"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert weights_cache.cache_folder() == \
        __import__("pathlib").Path.home() / ".cache" / "rigedit" / "weights"


_WORKER = """
import sys
import numpy as np
from rigedit.binding import weights_cache as wc
seed = int(sys.argv[1])
idx = np.zeros((2000, 4), np.int32)
bad = hits = 0
for i in range(60):
    k = (seed * 7 + i) % 5            # five keys shared by the workers
    w = np.zeros((2000, 4))
    w[:, k % 4] = 1.0                 # each key's own weights
    key = f"{k:064x}"
    wc.store_weights(key, idx, w)
    for other in (k, (k + 1) % 5):
        got = wc.load_weights(f"{other:064x}", 2000, 1)
        hits += got is not None
        if got is not None and not np.all(got[1][:, other % 4] == 1.0):
            bad += 1
print(bad, hits)
"""


def test_concurrent_processes_never_see_a_part_of_an_entry(cache):
    """Three processes store and read five keys with a bound of about three entries, so they
    evict each other's files all the while: no error, and every hit is a whole entry."""
    import subprocess
    import sys

    env = dict(os.environ, RIGEDIT_CACHE_MAX_MB=str(3.5 * 2000 * 4 * 12 / 2 ** 20))
    procs = [subprocess.Popen([sys.executable, "-c", _WORKER, str(s)], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for s in range(3)]
    outs = [p.communicate(timeout=120) for p in procs]
    assert [p.returncode for p in procs] == [0, 0, 0], [e for _, e in outs]
    counts = [[int(n) for n in o.split()] for o, _ in outs]
    assert [bad for bad, _ in counts] == [0, 0, 0]
    assert sum(hits for _, hits in counts) > 60, counts   # read, not only evicted (of 360)
    left = list(cache.glob("*.npz"))
    assert 1 <= len(left) <= 4 and not list(cache.glob(".*.tmp"))
