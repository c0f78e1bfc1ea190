"""The editor without Qt: the document, undo, typed events and every editing command.

:mod:`.document` (the single source of truth of an editing session: it samples the clips and
applies every edit), :mod:`.events` (what it tells its views), :mod:`.undo`, :mod:`.recovery`
(autosave files), and the commands, listed in :mod:`.commands`: open, save, export and the
weights file (:mod:`.files`), an auto-rig or re-embed opened (:mod:`.autorig`), a retargeted
motion imported (:mod:`.import_motion`), joint drags (:mod:`.drag`), key and clip edits (:mod:`.key_commands`,
:mod:`.clip_commands` on :mod:`.clip_edits`; the timeline's :mod:`.timeline_keys`), the
auto-key (:mod:`.auto_key`), weight strokes (:mod:`.weight_stroke`), recomputed weights
(:mod:`.recompute`) and deform flags (:mod:`.deform`). The timeline's clock and mode names
(:mod:`.playback`), the code-built demo rig (:mod:`.demo`) and the kernels' warm-up
(:mod:`.warm_up`) are here too: the UI reaches io, binding, rigging, animation and the model
only through this package (the ``editor-door`` contract in ``.importlinter``). A whole
editing session can be scripted and tested without a display. Nothing here imports Qt,
pyvista or VTK.
"""
