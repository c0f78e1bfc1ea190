"""The command on a library of awkward names: spaces, unicode, '#', '%', quotes, '<', a
leading dash, two files of one name in two folders, the same file three ways, OUTDIR inside
the library; then a resume."""
import json
import re
from pathlib import Path
from urllib.parse import unquote

import pytest
import rigedit
from batch_helpers import broken_bvh, litter, run_cli

NAMES = ["my hero", "héros_歩く", "-dash", "#1 hero", "100% hero", "it's \"q\"", "<b>x<\\b>",
         "a:b"]


@pytest.mark.slow
def test_awkward_names_end_to_end(tmp_path):
    lib = tmp_path / "lib"
    rig = rigedit.load_rig("humanoid")
    for i, name in enumerate(NAMES):
        rigedit.save_rig(rig, _mk(lib / f"d{i % 2}") / f"{name}.bvh", clips=["walk"])
    rigedit.save_rig(rig, _mk(lib / "d0") / "same.bvh", clips=["walk"])
    rigedit.save_rig(rig, _mk(lib / "d1") / "same.bvh", clips=["wave"])
    broken_bvh(lib / "d1", "<bad> #2.bvh")
    out = lib / "out"
    args = ["batch", "convert", lib, f"{lib}/d0/*.bvh", lib / "d1" / "same.bvh", "--to", "glb",
            "-o", out, "--workers", "1", "--no-thumbnails"]
    first = run_cli(*args)
    assert first.returncode == 1, first.stderr
    n = len(NAMES) + 3
    assert f"1 of {n} tasks failed" in first.stderr
    index = json.loads((out / "manifest.json").read_text())["tasks"]
    assert len(index) == n and len({e["task"] for e in index}) == n
    outs = [o for e in index for o in e["outputs"]]
    assert len(set(outs)) == n                     # the two same.bvh do not collide
    page = (out / "report.html").read_text()
    hrefs = re.findall(r'<a href="([^"]+)"', page)
    assert len(hrefs) == n - 1                     # every ok task links its output
    for href in hrefs:
        assert ":" not in href.split("/")[0] and "#" not in href
        assert (out / unquote(href)).is_file(), href
    assert page.count("<script") == 1 and "<b>" not in page
    assert litter(out) == []
    again = run_cli(*args, "--resume")
    assert again.returncode == 1                   # the broken one again, the rest skipped
    assert f"{n} tasks: 1 run, {n - 1} skipped" in again.stdout


def _mk(folder):
    Path(folder).mkdir(parents=True, exist_ok=True)
    return Path(folder)
