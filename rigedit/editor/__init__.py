"""The editor without Qt: the document, undo, and the editing commands (plain Python).

:mod:`.document` (the single source of truth of an editing session), :mod:`.undo`,
:mod:`.recovery` (autosave files), and the edits the window's parts apply: joint drags
(:mod:`.drag`), key and clip edits (:mod:`.timeline_keys`, :mod:`.timeline_edits`) and weight
strokes (:mod:`.weight_stroke`). Nothing here imports Qt, pyvista or VTK.
"""
