# SPDX-License-Identifier: LGPL-2.1-or-later
"""What covers a shown map in a CAM document, and how the map wins (FreeCAD GUI only).

A CAM Job draws a stock box around its model. Around the map's face it hides the map (a
document made by the command line leaves it opaque) or tints it (the GUI's transparent
stock), and a click on the map selects the box in front, whose selection highlight then
paints the face. While a map is shown with ``HideStock`` on, the stocks whose boxes meet its
face's are left out of the drawing and of picking: their Coin switch draws nothing. Their
``Visibility`` is not touched (the document is not modified, nothing enters the undo
history); hiding or showing a stock by hand draws it again as FreeCAD's own switch is set
then. The Job's model copy and the corrected face need nothing here: the map is drawn in
front of them (:mod:`surfcomp.app.mapmesh`).

Picking: FreeCAD's selection node handles a click before the 3D view's event callbacks
(:mod:`surfcomp.gui.readout`), on the press and again on the release. :func:`hold_selection`
keeps the map selected alone until the click that flagged it has been released.
"""

import time

import FreeCADGui
from PySide import QtCore, QtGui

#: stocks hidden for a map: (document name, object name) -> the switch's child before
_HIDDEN = {}
#: the longest hold (seconds), also where the release is not seen (FreeCAD 1.0)
HOLD_SECONDS = 2.0
#: milliseconds after the release that the map is still put back (the release's selection)
RELEASE_MS = 100


def _jobs(doc):
    """The CAM Jobs of ``doc`` (objects with a model, a stock and operations)."""
    return [o for o in doc.Objects
            if all(p in o.PropertiesList for p in ("Model", "Stock", "Operations"))]


def _box(obj):
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull():
        return None
    return shape.BoundBox


def _map_box(obj):
    """The bounding box of the map's nominal face in document coordinates."""
    nominal = getattr(obj, "Nominal", None)
    box = _box(nominal) if nominal is not None else None
    if box is None:
        return None
    face = getattr(obj, "FaceName", "") or ""
    faces = nominal.Shape.Faces
    k = int(face[4:]) if face.startswith("Face") and face[4:].isdigit() else 0
    return faces[k - 1].BoundBox if 1 <= k <= len(faces) else box


def stocks_covering(obj):
    """The stocks of the CAM Jobs of ``obj``'s document whose boxes meet its map's (a stock
    made for an earlier model may end below the face's top: it still covers the rest)."""
    box = _map_box(obj)
    if box is None:
        return []
    out = []
    for job in _jobs(obj.Document):
        stock = job.Stock
        sbox = _box(stock) if stock is not None else None
        if sbox is not None and sbox.intersect(box):
            out.append(stock)
    return out


def _showing(vobj):
    """True when ``vobj`` (a compensation's view) shows its map and hides the stock."""
    return (vobj is not None and "HideStock" in vobj.PropertiesList and vobj.HideStock and
            vobj.Visibility and vobj.DisplayMode == "Map" and
            not getattr(vobj.Proxy, "_deleted", False))


def update(doc):
    """Hide the stocks around the shown maps of ``doc``; draw again those no map covers."""
    if doc is None:
        return
    from ..app import features

    want = {}
    for obj in doc.Objects:
        if features.is_compensation(obj) and _showing(obj.ViewObject):
            for stock in stocks_covering(obj):
                want[(doc.Name, stock.Name)] = stock
    for key, stock in want.items():
        switch = stock.ViewObject.SwitchNode
        if key not in _HIDDEN and switch.whichChild.getValue() != -1:
            _HIDDEN[key] = switch.whichChild.getValue()
            switch.whichChild = -1
    for key in [k for k in _HIDDEN if k[0] == doc.Name and k not in want]:
        child = _HIDDEN.pop(key)
        stock = doc.getObject(key[1])
        if stock is None or stock.ViewObject is None:
            continue
        switch = stock.ViewObject.SwitchNode
        if switch.whichChild.getValue() == -1 and stock.Visibility:
            switch.whichChild = child


def hidden(doc):
    """Names of the stocks of ``doc`` hidden for its maps (for scripts and tests)."""
    return sorted(name for d, name in _HIDDEN if d == doc.Name)


class _Hold(QtCore.QObject):
    """Selection observer: from a press on a map until its release has been handled, a
    selection (the selection node's, of what lay in front, or of an element of the map's
    mesh) is replaced by the whole map alone. The release is seen by an event filter on
    the application, installed for the click only."""

    def __init__(self):
        super().__init__()
        self.target = None
        self.since = 0.0
        self.filtering = False

    def addSelection(self, doc, obj, sub, pnt):
        if self.target is None:
            return
        if time.monotonic() - self.since > HOLD_SECONDS:
            self.finish(restore=False)
            return
        # also for the map itself: FreeCAD 1.1 reports a mesh element the map's shape lacks
        # (Vertex-3670) as the whole object here, but keeps the element in the selection
        QtCore.QTimer.singleShot(0, self.restore)

    def restore(self):
        t = self.target
        if t is None:
            return
        sel = [(s.DocumentName, s.ObjectName, tuple(s.SubElementNames))
               for s in FreeCADGui.Selection.getSelectionEx("", 0)]
        if sel != [t + ((),)]:
            FreeCADGui.Selection.clearSelection()
            FreeCADGui.Selection.addSelection(*t)

    def start(self, target):
        self.target = target
        self.since = time.monotonic()
        if not self.filtering:
            QtGui.QApplication.instance().installEventFilter(self)
            self.filtering = True
        QtCore.QTimer.singleShot(0, self.restore)
        QtCore.QTimer.singleShot(int(1000 * HOLD_SECONDS), self._expire)

    def _expire(self):
        if self.target is not None and time.monotonic() - self.since >= HOLD_SECONDS:
            self.finish(restore=False)      # what was chosen since stays

    def eventFilter(self, _obj, event):
        if event.type() == QtCore.QEvent.MouseButtonRelease and self.target is not None:
            # after the release's own selection (handled now) and its correction
            QtCore.QTimer.singleShot(RELEASE_MS, self.finish)
        return False

    def finish(self, restore=True):
        if restore:
            self.restore()
        self.target = None
        if self.filtering:
            QtGui.QApplication.instance().removeEventFilter(self)
            self.filtering = False


_OBSERVER = []


def hold_selection(obj):
    """Select the map ``obj`` alone now and keep it so through the rest of the click."""
    if not _OBSERVER:
        _OBSERVER.append(_Hold())
        FreeCADGui.Selection.addObserver(_OBSERVER[0])
    _OBSERVER[0].start((obj.Document.Name, obj.Name))


def end_hold():
    """A press elsewhere: what it selects stays selected."""
    if _OBSERVER and _OBSERVER[0].target is not None:
        _OBSERVER[0].target = None
        _OBSERVER[0].finish()


def forget(doc_name):
    """Forget the stocks of a closed document."""
    for key in [k for k in _HIDDEN if k[0] == doc_name]:
        _HIDDEN.pop(key)
