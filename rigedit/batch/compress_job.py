"""The ``compress`` job: a rig's clips compressed with a guaranteed error (issue 20) into a
compact glTF (:func:`rigedit.io.gltf_compress.save_gltf_compressed_rig`, the bound checked
on the file as read), its ratio and error in the manifest."""
from __future__ import annotations

__all__ = ["compress_task"]


def compress_task(task, load, out, thumbnail):
    """Compress ``task["input"]``'s clips into ``out`` (.glb).

    Parameters
    ----------
    task : dict
        Its settings' ``max_error`` and ``shell`` are centimetres.
    load : callable(path) -> Rig
    out : Path
    thumbnail : callable(task, rig, clip)
        Makes the preview, here of the file as written (what ships).

    Returns
    -------
    (dict, list)
        The quality figures and the NOT SURE reasons (none: the bound is checked).
    """
    from ..errors import RigFileError
    from ..io.gltf_compress import save_gltf_compressed_rig

    s = task["settings"]
    rig = load(task["input"])
    if not rig.clips:
        raise RigFileError(task["input"], "expected clips to compress, got none")
    report = save_gltf_compressed_rig(rig, out, max_error=s["max_error"] / 100,
                                      shell=s["shell"] / 100)
    written = load(str(out))
    thumbnail(task, written, written.clips[sorted(written.clips)[0]] if written.clips else None)
    return {"clips": len(report.clips), "ratio": round(float(report.ratio), 2),
            "max error (cm)": round(100 * float(report.max_error), 5),
            "bound (cm)": s["max_error"], "raw (KB)": round(report.raw_bytes / 1024, 1),
            "compressed (KB)": round(report.compressed_bytes / 1024, 1)}, []
