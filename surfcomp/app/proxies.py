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


def migrate(obj, table, version):
    """Bring an object restored from an older document to the current property set and
    ``version``; return the names of the properties that were added."""
    added = add_properties(obj, table)
    if obj.Version < version:
        obj.Version = version
    return added


class Proxy:
    """No state on the proxy (``dumps``/``loads`` for FreeCAD 1.x, ``__getstate__``/
    ``__setstate__`` for 0.20 return None); properties upgraded on restore."""

    PROPERTIES = ()
    VERSION = 1

    def __init__(self, obj):
        add_properties(obj, self.PROPERTIES)
        obj.Proxy = self

    def dumps(self):
        return None

    def loads(self, state):
        return None

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None

    def onDocumentRestored(self, obj):
        migrate(obj, self.PROPERTIES, self.VERSION)
