"""The FBX 7.4 document FBX out writes: objects with ids, their connections, and the sections
around them (header extension, global settings, documents, definitions, takes).

What the nodes mean follows the structure FBX files have (as read by ufbx and written by
Blender's exporter): every object is a node under ``Objects`` named ``"<name>\\x00\\x01<Class>"``
with an int64 id; ``Connections`` holds ``C "OO" child parent`` (object to object) and
``C "OP" child parent "property"`` (object to a property); typed properties sit in a
``Properties70`` node, one ``P`` per property: name, type, data type, flags, values.
"""
from __future__ import annotations

from collections import Counter

from .fbx_binary import CREATION_TIME, FILE_ID, VERSION, Int64, Node

__all__ = ["Scene", "properties70", "TICKS_PER_SECOND", "ticks", "TIME_MODES"]

#: FBX time unit (``KTime``): ticks per second.
TICKS_PER_SECOND = 46186158000
#: Frame rate -> FBX ``TimeMode`` enum value (FbxTime::EMode).
TIME_MODES = {120.0: 1, 100.0: 2, 60.0: 3, 50.0: 4, 48.0: 5, 30.0: 6, 25.0: 10, 24.0: 11}

# P types: property kind -> (type, data type, flags) as FBX writes them
_P_KINDS = {
    "int": ("int", "Integer", ""), "bool": ("bool", "", ""), "enum": ("enum", "", ""),
    "double": ("double", "Number", ""), "number": ("Number", "", "A"),
    "color": ("Color", "", "A"), "colorrgb": ("ColorRGB", "Color", ""),
    "vector": ("Vector3D", "Vector", ""), "time": ("KTime", "Time", ""),
    "string": ("KString", "", ""), "url": ("KString", "XRefUrl", ""),
    "lcl_t": ("Lcl Translation", "", "A"), "lcl_r": ("Lcl Rotation", "", "A"),
    "lcl_s": ("Lcl Scaling", "", "A"), "object": ("object", "", ""),
}


def ticks(seconds):
    """FBX ``KTime`` of ``seconds`` (rounded to the nearest tick)."""
    return Int64(round(float(seconds) * TICKS_PER_SECOND))


def properties70(*entries):
    """A ``Properties70`` node of ``(name, kind, *values)`` entries (kinds: see _P_KINDS)."""
    node = Node("Properties70")
    for name, kind, *values in entries:
        node.add("P", name, *_P_KINDS[kind], *values)
    return node


class Scene:
    """Objects and connections of one FBX file, encoded by :meth:`nodes`.

    Parameters
    ----------
    up : {"y", "z"}
        The vertical axis of the data (written as ``UpAxis`` with a right-handed frame:
        Y up with +Z front, or Z up with -Y front).
    unit_cm : float
        Centimetres per file unit (``UnitScaleFactor``): 1 for centimetres, 100 for metres.
    fps : float
        The scene's frame rate (``TimeMode``), one of :data:`TIME_MODES`.
    """

    def __init__(self, up="y", unit_cm=1.0, fps=30.0):
        self.up, self.unit_cm, self.fps = up, float(unit_cm), float(fps)
        self.objects = []
        self.connections = []
        self.takes = []          # (name, duration seconds)
        self._next = 1_000_000   # ids: any nonzero int64; sequential keeps files reproducible

    def add(self, kind, name, cls, subtype=""):
        """A new object node ``kind`` (``Model``, ``Geometry``...) named ``name`` of class
        ``cls`` (``Model``, ``Geometry``, ``NodeAttribute``, ``SubDeformer``...); returns
        ``(id, node)``."""
        if "\x00" in name:
            raise ValueError(f"expected a name without NUL characters, got {name!r}")
        self._next += 1
        uid = Int64(self._next)
        node = Node(kind, uid, f"{name}\x00\x01{cls}", subtype)
        self.objects.append(node)
        return uid, node

    def connect(self, child, parent, prop=None):
        """``child`` under ``parent`` (0: the scene root), or onto its property ``prop``."""
        child, parent = Int64(child), Int64(parent)
        if prop is None:
            self.connections.append(("OO", child, parent))
        else:
            self.connections.append(("OP", child, parent, prop))

    # ------------------------------------------------------------------ the file's sections
    def _header(self):
        head = Node("FBXHeaderExtension")
        head.add("FBXHeaderVersion", 1003)
        head.add("FBXVersion", VERSION)
        head.add("EncryptionType", 0)
        stamp = head.add("CreationTimeStamp")
        # a fixed date: the same rig writes the same bytes (CreationTime below must stay the
        # one the file id was made for anyway)
        for key, value in (("Version", 1000), ("Year", 1970), ("Month", 1), ("Day", 1),
                           ("Hour", 10), ("Minute", 0), ("Second", 0), ("Millisecond", 0)):
            stamp.add(key, value)
        head.add("Creator", "rigedit")
        return head

    def _global_settings(self):
        up, front = (1, (2, 1)) if self.up == "y" else (2, (1, -1))
        node = Node("GlobalSettings")
        node.add("Version", 1000)
        span = max((d for _, d in self.takes), default=0.0)
        node.append(properties70(
            ("UpAxis", "int", up), ("UpAxisSign", "int", 1),
            ("FrontAxis", "int", front[0]), ("FrontAxisSign", "int", front[1]),
            ("CoordAxis", "int", 0), ("CoordAxisSign", "int", 1),
            ("OriginalUpAxis", "int", up), ("OriginalUpAxisSign", "int", 1),
            ("UnitScaleFactor", "double", self.unit_cm),
            ("OriginalUnitScaleFactor", "double", self.unit_cm),
            ("AmbientColor", "colorrgb", 0.0, 0.0, 0.0),
            ("DefaultCamera", "string", "Producer Perspective"),
            ("TimeMode", "enum", TIME_MODES[self.fps]), ("TimeProtocol", "enum", 2),
            ("SnapOnFrameMode", "enum", 0),
            ("TimeSpanStart", "time", Int64(0)), ("TimeSpanStop", "time", ticks(span)),
            ("CustomFrameRate", "double", -1.0)))
        return node

    def _documents(self):
        docs = Node("Documents")
        docs.add("Count", 1)
        doc = docs.add("Document", Int64(1), "Scene", "Scene")
        active = self.takes[0][0] if self.takes else ""
        doc.append(properties70(("SourceObject", "object"),
                                ("ActiveAnimStackName", "string", active)))
        doc.add("RootNode", Int64(0))
        return docs

    def _definitions(self):
        counts = Counter(node.name for node in self.objects)
        defs = Node("Definitions")
        defs.add("Version", 100)
        defs.add("Count", sum(counts.values()) + 1)
        defs.add("ObjectType", "GlobalSettings").add("Count", 1)
        for kind, count in counts.items():
            defs.add("ObjectType", kind).add("Count", count)
        return defs

    def _connections(self):
        node = Node("Connections")
        for c in self.connections:
            node.add("C", *c)
        return node

    def _takes(self):
        node = Node("Takes")
        node.add("Current", self.takes[0][0] if self.takes else "")
        for name, duration in self.takes:
            take = node.add("Take", name)
            take.add("FileName", f"{name}.tak")
            take.add("LocalTime", Int64(0), ticks(duration))
            take.add("ReferenceTime", Int64(0), ticks(duration))
        return node

    def nodes(self):
        """The file's top-level nodes, in the order FBX files have them."""
        objects = Node("Objects")
        objects.children = list(self.objects)
        return [self._header(), Node("FileId", FILE_ID), Node("CreationTime", CREATION_TIME),
                Node("Creator", "rigedit"), self._global_settings(), self._documents(),
                Node("References"), self._definitions(), objects, self._connections(),
                self._takes()]
