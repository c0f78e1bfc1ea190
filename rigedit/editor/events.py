"""What the Document tells its views: one small frozen dataclass per kind of change.

A view registers with :meth:`Listeners.listen` and receives the event objects; views written
before the events were typed register with :meth:`Listeners.subscribe` and receive
``callback(name, **info)`` as before (``name`` is the event's :attr:`Event.name`, ``info`` its
fields), so both kinds can be served by one document while the window switches. Listeners are
called in the order they registered, whichever kind they are: the timeline registers before the
window and must hear a change first.

Pure Python: no Qt.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import ClassVar, Optional, Tuple

__all__ = ["Event", "RigReplaced", "PoseChanged", "RestChanged", "WeightsChanged",
           "SelectionChanged", "TimeChanged", "ClipChanged", "KeysChanged", "ModeChanged",
           "UndoChanged", "MorphChanged", "Listeners", "from_name"]


@dataclass(frozen=True)
class Event:
    """Base of the document's events. ``name`` is the string the old listeners receive."""

    name: ClassVar[str] = ""

    def info(self):
        """The keyword arguments of the old string notification (the event's fields)."""
        return asdict(self)


@dataclass(frozen=True)
class RigReplaced(Event):
    """A new rig was opened (everything changed; the history was cleared)."""

    name: ClassVar[str] = "rig"


@dataclass(frozen=True)
class PoseChanged(Event):
    """The current pose changed.

    Attributes
    ----------
    joints : tuple of int or None
        The joints that changed, when known; None for any or all.
    """

    name: ClassVar[str] = "pose"
    joints: Optional[Tuple[int, ...]] = None


@dataclass(frozen=True)
class RestChanged(Event):
    """The skeleton's rest pose or flags changed (a rest move, a deform flag), and with it
    the binding when ``weights`` is true."""

    name: ClassVar[str] = "rest"
    weights: bool = True

    def info(self):
        return {}   # the old "rest" notification carried nothing


@dataclass(frozen=True)
class WeightsChanged(Event):
    """The skin weights changed and the skeleton did not (a stroke, a recompute, a load)."""

    name: ClassVar[str] = "rest"


@dataclass(frozen=True)
class SelectionChanged(Event):
    """The selected joint changed (``joint``: index or None)."""

    name: ClassVar[str] = "selection"
    joint: Optional[int] = None


@dataclass(frozen=True)
class TimeChanged(Event):
    """The current time changed (``time``: seconds)."""

    name: ClassVar[str] = "time"
    time: float = 0.0


@dataclass(frozen=True)
class ClipChanged(Event):
    """The current clip or the clip list changed (``name``: the current clip or None)."""

    name: ClassVar[str] = "clip"
    # the field is ``clip``, the old keyword ``name`` (see info): a dataclass field may not
    # shadow the class's ``name``
    clip: Optional[str] = None

    def info(self):
        return {"name": self.clip}


@dataclass(frozen=True)
class KeysChanged(ClipChanged):
    """The keys, tracks, duration or interpolation of clip ``clip`` changed. Old listeners
    hear it as ``"clip"``, as they did when the timeline announced its key edits that way."""


@dataclass(frozen=True)
class ModeChanged(Event):
    """The editing mode changed (``mode``: ``"pose"`` or ``"edit"``)."""

    name: ClassVar[str] = "mode"
    mode: str = "pose"


@dataclass(frozen=True)
class MorphChanged(Event):
    """The morph target weights shown changed (a slider, an undo, the clip sampled).

    Attributes
    ----------
    weights : tuple of float
        (M,) the weights now, in the order of ``rig.morphs.names``.
    """

    name: ClassVar[str] = "morph"
    weights: Tuple[float, ...] = ()


@dataclass(frozen=True)
class UndoChanged(Event):
    """The history or the saved state changed.

    Attributes
    ----------
    undo_label, redo_label : str
        What Undo and Redo would do ("" when nothing).
    modified : bool
        Whether there are unsaved changes.
    """

    name: ClassVar[str] = "undo"
    undo_label: str = ""
    redo_label: str = ""
    modified: bool = False

    def info(self):
        return {}   # the old "undo" notification carried nothing


#: The typed event for each old string name, for code that still emits strings.
_BY_NAME = {"rig": RigReplaced, "pose": PoseChanged, "rest": RestChanged,
            "selection": SelectionChanged, "time": TimeChanged, "clip": ClipChanged,
            "mode": ModeChanged, "undo": UndoChanged, "morph": MorphChanged}


def from_name(event, /, **info):
    """The typed event of an old string notification (``document.emit("clip", name=...)``).

    Raises
    ------
    ValueError
        For a name no event has.
    """
    try:
        cls = _BY_NAME[event]
    except KeyError:
        raise ValueError(f"unknown document event {event!r}; expected one of "
                         f"{sorted(_BY_NAME)}") from None
    if cls is ClipChanged:
        return ClipChanged(info.get("name"))
    if cls is PoseChanged:
        joints = info.get("joints")
        return PoseChanged(None if joints is None else tuple(int(j) for j in joints))
    if cls is UndoChanged:
        return UndoChanged()
    return cls(**info)


class Listeners:
    """The document's listeners, old and new kinds in one ordered list."""

    def __init__(self):
        self._entries = []   # (callback, typed)

    def listen(self, callback):
        """Call ``callback(event)`` with each :class:`Event`; returns ``callback``."""
        self._entries.append((callback, True))
        return callback

    def subscribe(self, callback):
        """Call ``callback(name, **info)`` on each change (the old protocol); returns it."""
        self._entries.append((callback, False))
        return callback

    def remove(self, callback):
        """Stop calling ``callback`` (either kind); unknown callbacks are ignored."""
        self._entries = [e for e in self._entries if e[0] is not callback and e[0] != callback]

    def emit(self, event):
        """Tell every listener about ``event``, in registration order. A listener added or
        removed by a listener takes effect from the next event."""
        info = None
        for callback, typed in list(self._entries):
            if typed:
                callback(event)
            else:
                if info is None:
                    info = event.info()
                callback(event.name, **info)
