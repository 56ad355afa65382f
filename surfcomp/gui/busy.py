# SPDX-License-Identifier: LGPL-2.1-or-later
"""Long recomputes without a frozen window: a modal progress dialog over a child process.

:func:`recompute` computes what the document needs; its CAM operations are computed by a
child process (:class:`surfcomp.app.recompute.ChildRecompute`) while this process waits in
Qt's event loop, so the window keeps painting. A modal progress dialog keeps the user from
editing the document meanwhile, shows which object is computed and for how long, and its
Cancel button or Esc stops the child at once (:class:`surfcomp.errors.Cancelled`; the
document was not changed, so nothing is recomputed). No numerics here.
"""

import time

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from ..app import progress
from ..app.recompute import ChildRecompute
from ..errors import Cancelled, ComputationError
from . import fcgui

translate = FreeCAD.Qt.translate

#: how often the dialog looks at the child (ms)
POLL_MS = 50


def _dialog(title):
    dlg = QtGui.QProgressDialog(FreeCADGui.getMainWindow())
    dlg.setWindowTitle(title)
    dlg.setObjectName("SurfCompRecompute")
    dlg.setCancelButtonText(translate("SurfComp", "Cancel"))
    dlg.setRange(0, 0)      # busy: the time one operation takes is not known in advance
    dlg.setMinimumDuration(0)
    dlg.setAutoClose(False)
    dlg.setAutoReset(False)
    dlg.setWindowModality(QtCore.Qt.WindowModal)
    dlg.setMinimumWidth(420)
    return dlg


def wait(job, dlg):
    """Let ``job`` (started) run to its end under ``dlg`` (shown), the event loop running.

    Raises
    ------
    Cancelled
        The user pressed Esc or Cancel: the child was stopped.
    """
    loop = QtCore.QEventLoop()
    state = {"cancelled": False}

    def cancel():
        if not state["cancelled"]:
            state["cancelled"] = True
            job.cancel()
            loop.quit()

    def poll():
        if not job.poll():
            loop.quit()
            return
        done, total, current, seconds = job.status()
        dlg.setLabelText(translate("SurfComp", "Computing %s (object %d of %d): %.0f s")
                         % (current or "...", min(done + 1, total), total, seconds))

    dlg.canceled.connect(cancel)
    dlg.rejected.connect(cancel)
    timer = QtCore.QTimer()
    timer.setInterval(POLL_MS)
    timer.timeout.connect(poll)
    poll()
    timer.start()
    try:
        if job.poll():
            fcgui.run_modal(loop)
    finally:
        timer.stop()
        dlg.canceled.disconnect(cancel)
        dlg.rejected.disconnect(cancel)
    if state["cancelled"]:
        raise Cancelled("interrupted by the user; nothing was changed")


#: between two steps that block the window, it paints when this long has passed (s)
PAINT_AFTER = 0.15
_painted = [0.0]


def _paint(force=False):
    """Let the window paint between two steps that block it for a moment, user input left
    waiting (twice: the first pass runs the timers, whose repaint requests the second pass
    paints); only when :data:`PAINT_AFTER` has passed since, as a repaint of the 3D view
    with long tool paths costs time too."""
    if not force and time.monotonic() - _painted[0] < PAINT_AFTER:
        return
    for _ in range(2):
        QtGui.QApplication.processEvents(QtCore.QEventLoop.ExcludeUserInputEvents)
    _painted[0] = time.monotonic()


def recompute(doc, title):
    """Recompute what ``doc`` needs, each object once; the CAM operations in a child
    process while the window stays responsive. Returns the names of the objects
    recomputed.

    Raises
    ------
    Cancelled
        Esc or Cancel during the operations' recompute: the document is unchanged (the
        caller undoes its own change, see :func:`surfcomp.app.recompute.settle_after_undo`).
    """
    job = ChildRecompute(doc)
    if not job.needed():
        return progress.recompute_with_progress(doc, title, job.todo)
    dlg = _dialog(title)
    dlg.setLabelText(translate("SurfComp", "Saving a copy of the document for the recompute"))
    dlg.show()
    try:
        _paint(force=True)
        job.start(between=_paint)
        wait(job, dlg)
        dlg.setLabelText(translate("SurfComp", "Taking over the results"))
        _paint(force=True)
        try:
            return job.finish(between=_paint)
        except ComputationError as exc:
            FreeCAD.Console.PrintWarning("SurfComp: %s\nRecomputing in this process instead.\n"
                                         % exc)
    finally:
        dlg.close()
        dlg.deleteLater()
    return progress.recompute_with_progress(doc, title, job.todo)
