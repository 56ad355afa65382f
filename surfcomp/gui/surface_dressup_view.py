# SPDX-License-Identifier: LGPL-2.1-or-later
"""View provider of the "Surface correction" dressup (:mod:`surfcomp.app.dressup_surface`):
FreeCAD draws a ``Path::FeaturePython``'s moves only once a view provider proxy gives it a
display mode. The Add surface correction to operation command gives the new dressup one,
and a document observer gives the dressups of an opened document theirs when it is
activated (dressups made by a script or headless, opened later in the GUI). The base
operation shows under the dressup in the tree, as under CAM's own dressups.
"""

import FreeCAD

from .. import paths
from ..app.dressup_surface import DressupSurfaceCorrection
from ..app.proxies import Stateless

MODE = "Waypoints"


def is_surface_dressup(obj):
    return isinstance(getattr(obj, "Proxy", None), DressupSurfaceCorrection)


class ViewProviderSurfaceCorrection(Stateless):
    """No state: ``dumps``/``loads`` return None."""

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

    def claimChildren(self):
        base = getattr(getattr(self, "obj", None), "Base", None)
        return [base] if base is not None else []

    def getIcon(self):
        return paths.icon("SurfComp_AddSurfaceCorrection.svg")


def attach(obj):
    """Give a surface correction dressup its view provider and display mode (idempotent);
    True when it got one."""
    vobj = getattr(obj, "ViewObject", None)
    if (not is_surface_dressup(obj) or vobj is None
            or isinstance(vobj.Proxy, ViewProviderSurfaceCorrection)):
        return False
    proxy = ViewProviderSurfaceCorrection(vobj)
    if not hasattr(proxy, "obj"):       # an existing view object: FreeCAD does not attach
        proxy.attach(vobj)
    modes = list(vobj.getEnumerationsOfProperty("DisplayMode") or [])
    if MODE not in modes:               # the enumeration was made before the proxy existed
        vobj.DisplayMode = modes + [MODE]
    vobj.DisplayMode = MODE
    return True


class _Observer:
    def slotActivateDocument(self, doc):
        for obj in doc.Objects:
            attach(obj)


_OBSERVER = []
if not _OBSERVER:
    _OBSERVER.append(_Observer())
    FreeCAD.addDocumentObserver(_OBSERVER[0])
