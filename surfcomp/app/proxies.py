# SPDX-License-Identifier: LGPL-2.1-or-later
"""What every surfcomp document-object proxy shares (STYLE: state lives in properties).

A property table is a tuple of ``(type, name, group, tooltip, default, editor_mode)``;
objects get every missing property when created and when restored from an older
document, and carry a ``Version`` property.
"""


def add_properties(obj, table):
    """Add every missing property of ``table`` (new objects and old documents alike);
    return the names added."""
    added = []
    for typ, name, group, tip, default, mode in table:
        if name in obj.PropertiesList:
            continue
        obj.addProperty(typ, name, group, tip)
        if typ == "App::PropertyEnumeration":
            setattr(obj, name, default)
            setattr(obj, name, default[0])
        elif default is not None:
            setattr(obj, name, default)
        if mode:
            obj.setEditorMode(name, mode)
        added.append(name)
    return added


def rename_properties(obj, renamed):
    """Move the values of renamed properties (``{old: new}``, the new ones already added)
    and remove the old ones; return the old names moved."""
    moved = []
    for old, new in renamed.items():
        if old in obj.PropertiesList and new in obj.PropertiesList:
            setattr(obj, new, getattr(obj, old))
            obj.removeProperty(old)
            moved.append(old)
    return moved


def migrate(obj, table, version, renamed=None):
    """Bring an object restored from an older document to the current property set and
    ``version`` (``renamed``: ``{old name: new name}`` whose values move); return the names
    of the properties that were added."""
    added = add_properties(obj, table)
    rename_properties(obj, renamed or {})
    if obj.Version < version:
        obj.Version = version
    return added


class Stateless:
    """A proxy with nothing to save: FreeCAD's pickling hooks, in both spellings (0.20 calls
    ``dumps``/``loads``, 1.x ``__getstate__``/``__setstate__``)."""

    def dumps(self):
        return None

    def loads(self, state):
        return None

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None


class Proxy(Stateless):
    """No state on the proxy (``dumps``/``loads`` for FreeCAD 1.x, ``__getstate__``/
    ``__setstate__`` for 0.20 return None); properties upgraded on restore."""

    PROPERTIES = ()
    VERSION = 1
    #: ``{old name: new name}`` of renamed properties (moved on restore)
    RENAMED = {}

    def __init__(self, obj):
        add_properties(obj, self.PROPERTIES)
        obj.Proxy = self

    def onDocumentRestored(self, obj):
        migrate(obj, self.PROPERTIES, self.VERSION, self.RENAMED)
