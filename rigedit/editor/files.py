"""Open and save: the document's rig read from and written to files.

Reading and writing go through the package's stable entry points, :func:`rigedit.load_rig` and
:func:`rigedit.save_rig` (a bundled name, a rig folder, glTF, BVH), so the editor does not
depend on how io is built inside. A file that cannot be read raises
:class:`~rigedit.errors.RigFileError` (a ``ValueError``) and leaves the document as it was.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["open_document", "open_rig", "save_rig_folder", "export_rig"]


def open_document(path=None, **options):
    """A new :class:`~rigedit.editor.document.Document` on the rig at ``path`` (the default
    character when None); ``options`` go to :func:`rigedit.load_rig`."""
    from .. import load_rig
    from .document import Document

    return Document(load_rig(path, **options))


def open_rig(document, path=None, **options):
    """Open the rig at ``path`` in ``document`` (history cleared; RigReplaced); returns it.

    Reading may take seconds (weights computed for a mesh without them): the window runs
    :func:`rigedit.load_rig` in a worker and hands the rig to ``Document.set_rig``.
    """
    from .. import load_rig

    rig = load_rig(path, **options)
    document.set_rig(rig)
    return rig


def save_rig_folder(document, path=None):
    """Write the rig folder to ``path`` (default: the folder it came from, ``rig.path``);
    the document then has no unsaved changes and remembers the folder.

    Returns
    -------
    Path
        The folder written.

    Raises
    ------
    ValueError
        Without a folder to write, for a bundled character's own folder (read-only) when no
        path is given, or for a path with a file suffix (see :func:`export_rig`).
    """
    from .. import ASSETS_DIR, save_rig

    rig = document.rig
    if path is None:
        path = rig.path
        if path is None:
            raise ValueError(f"{rig.name} has no folder yet: give one to save it into")
        if Path(ASSETS_DIR).resolve() in (Path(path).resolve(), *Path(path).resolve().parents):
            raise ValueError(f"{rig.name} is a bundled character (read-only): give a folder "
                             "to save it into")
    path = Path(path)
    if path.suffix and not path.is_dir():
        raise ValueError(f"expected a folder to save {rig.name} into, got the file {path} "
                         "(export writes files)")
    save_rig(rig, path)
    rig.path = path
    document.mark_saved()
    return path


def export_rig(document, path, clips=None):
    """Write the rig as ``.glb``/``.gltf`` (every clip, or ``clips``) or ``.bvh`` (the
    skeleton and the current clip); unlike a save, the document keeps its unsaved state."""
    from .. import save_rig

    if clips is None and Path(path).suffix.lower() == ".bvh" and document.current_clip:
        clips = [document.current_clip]
    return save_rig(document.rig, path, clips=clips)
