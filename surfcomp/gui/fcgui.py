# SPDX-License-Identifier: LGPL-2.1-or-later
"""What differs between FreeCAD 0.20, 1.0 and 1.1 in the GUI, detected, in one place.

- the status bar: the main window's, reached through Qt (``statusBar()``) where FreeCAD
  offers no call of its own;
- modal dialogs: ``exec`` (Qt6) or ``exec_`` (Qt5);
- the 3D view's widget size and mouse picking (``getObjectsInfo``, all versions since 0.19);
- Coin vectors from pivy: ``SbVec2s.getValue()`` gives a list with pivy 0.6.8/0.6.10 as
  built for FreeCAD 0.20 and 1.0, but a bare ``short *`` with the pivy of FreeCAD 1.1
  (Debian sid, newer SWIG); indexing works with all of them (``event_position``).
"""

import FreeCADGui


def active_view():
    """The active 3D view, or None (no document, or a non-3D view in front)."""
    doc = FreeCADGui.ActiveDocument
    view = getattr(doc, "ActiveView", None) if doc is not None else None
    return view if view is not None and hasattr(view, "getSize") else None


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
