# SPDX-License-Identifier: LGPL-2.1-or-later
"""View provider of the probe operation: FreeCAD draws a ``Path::FeaturePython``'s moves
(rapids red, feeds green) only once a view provider proxy gives it a display mode.

Registered as a creation and restore hook of :mod:`surfcomp.app.features`, and a document
observer gives the operations of an opened document theirs when it is activated (FreeCAD
0.20 may restore the object before its view object), so operations made by the command, by
a script or headless (opened later in the GUI) all get it.
"""

import FreeCAD

from .. import paths
from ..app import features
from ..app.probe_op import is_probe_operation
from ..app.proxies import Stateless

MODE = "Waypoints"


class ViewProviderProbeOperation(Stateless):
    """No state: ``dumps``/``loads`` return None."""

    def __init__(self, vobj):
        vobj.Proxy = self

    def attach(self, vobj):
        self.scene = True

    def getDisplayModes(self, vobj):
        return [MODE]

    def getDefaultDisplayMode(self):
        return MODE

    def setDisplayMode(self, mode):
        return mode

    def getIcon(self):
        return paths.icon("SurfComp_AddProbeOperation.svg")


def attach(obj):
    """Give a probe operation its view provider and display mode (idempotent); True when it
    got one."""
    vobj = getattr(obj, "ViewObject", None)
    if (not is_probe_operation(obj) or vobj is None
            or isinstance(vobj.Proxy, ViewProviderProbeOperation)):
        return False
    proxy = ViewProviderProbeOperation(vobj)
    if not hasattr(proxy, "scene"):  # an existing view object: FreeCAD does not attach
        proxy.attach(vobj)
    modes = list(vobj.getEnumerationsOfProperty("DisplayMode") or [])
    if MODE not in modes:  # the enumeration was made before the proxy existed
        vobj.DisplayMode = modes + [MODE]
    vobj.DisplayMode = MODE
    return True


class _Observer:
    def slotActivateDocument(self, doc):
        for obj in doc.Objects:
            attach(obj)


for _hooks in (features.NEW_OBJECT_HOOKS, features.RESTORED_HOOKS):
    if attach not in _hooks:
        _hooks.append(attach)
_OBSERVER = []
if not _OBSERVER:
    _OBSERVER.append(_Observer())
    FreeCAD.addDocumentObserver(_OBSERVER[0])
