"""Auto-rigging: any mesh to an animated character (numpy + scipy).

:mod:`.pipeline` (:func:`autorig`): :mod:`.mesh_check`, :mod:`.orient` (with :mod:`.mirror`
and :mod:`.ground`), :mod:`.orient_search` and :mod:`.confidence`, :mod:`.templates`, then
:mod:`rigedit.embedding`, weights from :mod:`rigedit.binding` and the template's clips through
:mod:`rigedit.rigging.retarget`.
"""
from .pipeline import AutorigReport, autorig

__all__ = ["autorig", "AutorigReport"]
