# SPDX-License-Identifier: LGPL-2.1-or-later
"""What differs between FreeCAD 0.20, 1.0 and 1.1 in the GUI, detected, in one place.

- the navigation cube: 0.20 keeps its corner under ``Preferences/View``, 1.x under
  ``Preferences/NaviCube`` (with its size ``CubeSize``); the viewer reports whether it is
  shown (``isEnabledNaviCube``) where that exists;
- the status bar: the main window's, reached through Qt (``statusBar()``) where FreeCAD
  offers no call of its own;
- modal dialogs: ``exec`` (Qt6) or ``exec_`` (Qt5);
- the 3D view's widget size and mouse picking (``getObjectsInfo``, all versions since 0.19);
- Coin vectors from pivy: ``SbVec2s.getValue()`` gives a list with pivy 0.6.8/0.6.10 as
  built for FreeCAD 0.20 and 1.0, but a bare ``short *`` with the pivy of FreeCAD 1.1
  (Debian sid, newer SWIG); indexing works with all of them (``event_position``).
"""

import FreeCAD
import FreeCADGui

VIEW = "User parameter:BaseApp/Preferences/View"
NAVICUBE = "User parameter:BaseApp/Preferences/NaviCube"
#: navigation cube corners as FreeCAD numbers them
TOP_LEFT, TOP_RIGHT, BOTTOM_LEFT, BOTTOM_RIGHT = range(4)
DEFAULT_CUBE_SIZE = 132


def active_view():
    """The active 3D view, or None (no document, or a non-3D view in front)."""
    doc = FreeCADGui.ActiveDocument
    view = getattr(doc, "ActiveView", None) if doc is not None else None
    return view if view is not None and hasattr(view, "getSize") else None


def navicube(view=None):
    """``(shown, corner, size_px)`` of the navigation cube of ``view`` (default active)."""
    view = view or active_view()
    shown = FreeCAD.ParamGet(VIEW).GetBool("ShowNaviCube", True)
    viewer = view.getViewer() if view is not None and hasattr(view, "getViewer") else None
    if viewer is not None and hasattr(viewer, "isEnabledNaviCube"):
        shown = bool(viewer.isEnabledNaviCube())
    corner = FreeCAD.ParamGet(NAVICUBE).GetInt("CornerNaviCube", -1)       # 1.x
    if corner < 0:
        corner = FreeCAD.ParamGet(VIEW).GetInt("CornerNaviCube", TOP_RIGHT)  # 0.20
    size = FreeCAD.ParamGet(NAVICUBE).GetInt("CubeSize", -1)
    if size <= 0:
        size = FreeCAD.ParamGet(VIEW).GetInt("NaviWidgetSize", DEFAULT_CUBE_SIZE)
    return shown, corner, size


def legend_clearance(view=None):
    """``(top_px, bottom_px, height_px)``: the room the legend (on the right) keeps free of
    the navigation cube in ``view``."""
    from .mapscene import CUBE_MARGIN

    view = view or active_view()
    height = view.getSize()[1] if view is not None else 1000
    shown, corner, size = navicube(view)
    if not shown or corner in (TOP_LEFT, BOTTOM_LEFT):
        return 0, 0, height
    room = size + CUBE_MARGIN
    return (room, 0, height) if corner == TOP_RIGHT else (0, room, height)


def event_position(event):
    """``(x, y)``: the pixel of a Coin event (``SoEvent.getPosition()``, origin bottom left).

    Indexed, not ``getValue()``: that returns an opaque pointer with some pivy builds."""
    pos = event.getPosition()
    return int(pos[0]), int(pos[1])


def status_bar():
    """The main window's status bar (a QStatusBar)."""
    return FreeCADGui.getMainWindow().statusBar()


def show_status(text, msecs=0):
    status_bar().showMessage(text, msecs)


def status_text():
    return status_bar().currentMessage()


def run_modal(dialog):
    """Run a modal dialog (Qt6 dropped the ``exec_`` alias); its result code."""
    run = getattr(dialog, "exec", None) or dialog.exec_
    return run()
