"""The command line's side of the hardened readers and writers (issue 19, section 4):
``--allow-outside-uris``, a SIGTERM while VTK imports, stale temporary videos."""
import builtins
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from builders import cylinder_rig
from gltf_builder import two_bone
from rigedit.cli.main import main
from rigedit.io import save_rig_folder
from testpaths import REPO


def _hidden(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def _outside_gltf(tmp_path):
    """A .gltf in ``tmp_path/f`` whose buffer uri is an absolute path (its own .bin)."""
    folder = tmp_path / "f"
    folder.mkdir()
    b, _ = two_bone()
    path = b.write(folder / "char.gltf", "external")
    doc = json.loads(path.read_text())
    doc["buffers"][0]["uri"] = str(folder / "char data.bin")
    path.write_text(json.dumps(doc))
    return path


def test_outside_uris_refused_unless_allowed(tmp_path, capsys):
    path = _outside_gltf(tmp_path)
    out = tmp_path / "out.glb"
    assert main(["export", str(path), "-o", str(out)]) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if "warning" not in line]
    assert len(err) == 1 and err[0].startswith(f"rigedit: error: {path}: buffer 0: "), err
    assert "--allow-outside-uris" in err[0] and not out.exists()
    assert main(["export", str(path), "-o", str(out), "--allow-outside-uris"]) == 0
    assert out.is_file()
    assert main(["info", str(path), "--allow-outside-uris"]) == 0
    assert main(["info", str(path)]) == 2   # the option holds for one run only


def test_allow_outside_uris_through_the_api(tmp_path):
    import rigedit
    from rigedit.errors import RigFileError

    path = _outside_gltf(tmp_path)
    with pytest.raises(RigFileError, match="allow it with --allow-outside-uris"):
        rigedit.load_rig(path)
    assert len(rigedit.load_rig(path, allow_outside_uris=True).vertices) == 8
    # a permission, not a need: harmless with a format that has no uris
    rig_dir = tmp_path / "rig"
    save_rig_folder(rig_dir, cylinder_rig())
    assert len(rigedit.load_rig(rig_dir, allow_outside_uris=True).vertices) > 0


# ---------------------------------------------------------------------------- SIGTERM
def test_sigterm_while_vtk_imports_is_held_until_the_import_is_done(tmp_path, capsys,
                                                                   monkeypatch):
    """A SIGTERM arriving in the middle of the recorder's import (VTK) must not break into
    it: the import completes, then the command stops with 143 and one line."""
    rig_dir = tmp_path / "rig"
    save_rig_folder(rig_dir, cylinder_rig())
    monkeypatch.delitem(sys.modules, "rigedit.render.recorder", raising=False)
    real_import = builtins.__import__
    sent = []

    def signalling_import(name, *args, **kwargs):
        if name.endswith("render.recorder") and not sent:
            sent.append(name)
            os.kill(os.getpid(), signal.SIGTERM)   # handled at the next bytecode: in the import
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", signalling_import)
    out = tmp_path / "v.mp4"
    assert main(["render", "bend", "--rig", str(rig_dir), "-o", str(out), "--size",
                 "64x64"]) == 143
    assert sent and hasattr(sys.modules.get("rigedit.render.recorder"), "record_clip")
    assert capsys.readouterr().err.splitlines() == ["rigedit: interrupted by SIGTERM"]
    assert not out.exists() and _hidden(tmp_path) == []


def _render(rig_dir, out, duration="0.5"):
    return subprocess.Popen([sys.executable, "-m", "rigedit", "render", "bend", "--rig",
                             str(rig_dir), "-o", str(out), "--duration", duration, "--size",
                             "64x64", "--fps", "30"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO,
                            env=dict(os.environ, OMP_NUM_THREADS="1"))


def test_sigterm_early_in_a_render_never_crashes(tmp_path):
    """SIGTERM at several moments of a render's start (interpreter start, imports, the
    first frames): exit 143 with one line (or a death by the signal itself before the
    handler exists, or a finished render), never SIGSEGV, never a temporary video left."""
    rig_dir = tmp_path / "rig"
    save_rig_folder(rig_dir, cylinder_rig())
    out = tmp_path / "v.mp4"
    outcomes = []
    for delay in (0.3, 0.8, 1.3, 1.8, 2.3, 2.8):
        proc = _render(rig_dir, out)
        time.sleep(delay)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
        outcomes.append(proc.returncode)
        assert proc.returncode in (143, -signal.SIGTERM, 0), (delay, proc.returncode, err)
        if proc.returncode == 143:
            # rigedit's own words are one line; VTK may log its own warnings beside them (a
            # busy X server under CI: "bad X server connection"), which are not a crash
            ours = [line for line in err.splitlines() if line.startswith("rigedit:")]
            assert ours == ["rigedit: interrupted by SIGTERM"], err
            assert "Traceback" not in err and "Fatal Python error" not in err, err
        assert _hidden(tmp_path) == [], delay
    assert -signal.SIGSEGV not in outcomes


def test_a_killed_renders_temporary_video_is_removed_by_the_next(tmp_path):
    rig_dir = tmp_path / "rig"
    save_rig_folder(rig_dir, cylinder_rig())
    out_dir = tmp_path / "videos"
    out_dir.mkdir()
    out = out_dir / "v.mp4"
    proc = _render(rig_dir, out, duration="60")
    try:
        deadline = time.monotonic() + 120
        while not _hidden(out_dir) and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        stale = _hidden(out_dir)
        assert stale and stale[0].startswith(f".v.mp4.pid{proc.pid}-"), stale
    finally:
        proc.kill()
        proc.wait()
    assert _hidden(out_dir) == stale          # SIGKILL: no clean-up ran
    live = out_dir / f".v.mp4.pid{os.getpid()}-keep.mp4"   # a running process's: kept
    live.write_bytes(b"")
    other = out_dir / ".w.mp4.pid999999999-x.mp4"         # another target's: not ours
    other.write_bytes(b"")
    assert main(["render", "bend", "--rig", str(rig_dir), "-o", str(out), "--size", "64x64",
                 "--duration", "0.2"]) == 0
    assert out.is_file() and _hidden(out_dir) == sorted([live.name, other.name])


def test_a_video_that_cannot_be_written_is_one_line_naming_it(tmp_path, capsys, monkeypatch):
    import errno

    from rigedit.render import video_writer

    def full(self, frame):
        raise OSError(errno.ENOSPC, "No space left on device")
    rig_dir = tmp_path / "rig"
    save_rig_folder(rig_dir, cylinder_rig())
    monkeypatch.setattr(video_writer.VideoWriter, "append", full)
    out = tmp_path / "v.mp4"
    assert main(["render", "bend", "--rig", str(rig_dir), "-o", str(out), "--size", "64x64",
                 "--duration", "0.3"]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"rigedit: error: {out}: cannot write: No space left on device"]
    assert not out.exists() and _hidden(tmp_path) == []
