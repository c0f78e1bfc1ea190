"""The editor without Qt: the document, undo, typed events and every editing command.

:mod:`.document` (the single source of truth of an editing session: it samples the clips and
applies every edit), :mod:`.events` (what it tells its views), :mod:`.undo`, :mod:`.recovery`
(autosave files), and the commands, listed in :mod:`.commands`: open and save
(:mod:`.files`), joint drags (:mod:`.drag`), key and clip edits (:mod:`.key_commands`,
:mod:`.clip_commands` on :mod:`.clip_edits`; the timeline's :mod:`.timeline_keys`), the
auto-key (:mod:`.auto_key`), weight strokes (:mod:`.weight_stroke`), recomputed weights
(:mod:`.recompute`) and deform flags (:mod:`.deform`). A whole editing session can be scripted
and tested without a display. Nothing here imports Qt, pyvista or VTK.
"""
