"""Compatibility: the Document moved to :mod:`rigedit.editor.document`."""
from .editor.document import *  # noqa: F401,F403
from .editor.document import Document  # noqa: F401
