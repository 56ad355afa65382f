# SPDX-License-Identifier: LGPL-2.1-or-later
"""What the view providers of the workbench's Path objects share (the probe operation and
the "Surface correction" dressup): FreeCAD draws a ``Path::FeaturePython``'s moves (rapids
red, feeds green) only once a view provider proxy gives it a display mode.

:func:`attach` gives an object its view provider, and :func:`watch` has a document observer
run an attach function on every object of a document when it is activated (FreeCAD 0.20
may restore an object before its view object; objects made by a script or headless get
theirs when their document is opened later in the GUI). The view provider classes stay in
their own modules, which saved documents name.
"""

import FreeCAD

from .. import paths
from ..app.proxies import Stateless

MODE = "Waypoints"


class PathViewProvider(Stateless):
    """No state: ``dumps``/``loads`` return None. ``ICON``: the icon file's name."""

    ICON = None

    def __init__(self, vobj):
        vobj.Proxy = self

    def attach(self, vobj):
        self.obj = vobj.Object

    def getDisplayModes(self, vobj):
        return [MODE]

    def getDefaultDisplayMode(self):
        return MODE

    def setDisplayMode(self, mode):
        return mode

    def getIcon(self):
        return paths.icon(self.ICON)


def attach(obj, is_kind, cls):
    """Give ``obj`` a ``cls`` view provider and its display mode when ``is_kind(obj)``
    (idempotent); True when it got one."""
    vobj = getattr(obj, "ViewObject", None)
    if not is_kind(obj) or vobj is None or isinstance(vobj.Proxy, cls):
        return False
    proxy = cls(vobj)
    if not hasattr(proxy, "obj"):       # an existing view object: FreeCAD does not attach
        proxy.attach(vobj)
    modes = list(vobj.getEnumerationsOfProperty("DisplayMode") or [])
    if MODE not in modes:               # the enumeration was made before the proxy existed
        vobj.DisplayMode = modes + [MODE]
    vobj.DisplayMode = MODE
    return True


_ATTACH = []        # the attach functions the observer runs
_OBSERVER = []


class _Observer:
    def slotActivateDocument(self, doc):
        for obj in doc.Objects:
            for fn in _ATTACH:
                fn(obj)


def watch(fn):
    """Run ``fn(obj)`` on every object of each document activated from now on (once)."""
    if fn not in _ATTACH:
        _ATTACH.append(fn)
    if not _OBSERVER:
        _OBSERVER.append(_Observer())
        FreeCAD.addDocumentObserver(_OBSERVER[0])
