# SPDX-License-Identifier: LGPL-2.1-or-later
"""The workbench's modal questions and messages, in one place.

Commands never call Qt dialogs directly: they call these functions, so scripts and the
GUI tests can replace them (e.g. ``dialogs.show_error = recorder``) and run every command
without a blocking dialog.
"""

import FreeCAD
import FreeCADGui
from PySide import QtGui

translate = FreeCAD.Qt.translate


def _parent():
    return FreeCADGui.getMainWindow()


def show_error(title, message):
    """Show an error the way the CLI words it (``file:line:column: what is wrong``)."""
    FreeCAD.Console.PrintError("%s: %s\n" % (title, message))
    QtGui.QMessageBox.critical(_parent(), title, message)


def show_info(title, message):
    QtGui.QMessageBox.information(_parent(), title, message)


def ask_open_file(title, filters):
    """A file to open, or None when the user cancels."""
    path, _ = QtGui.QFileDialog.getOpenFileName(_parent(), title, "", filters)
    return path or None


def ask_save_file(title, filters, default=""):
    """A file to write, or None when the user cancels."""
    path, _ = QtGui.QFileDialog.getSaveFileName(_parent(), title, default, filters)
    return path or None


def ask_stock(title, value, deviation=None):
    """The mirror method's stock from the explained stock dialog, checked against the
    measured ``deviation`` (mm): ``(stock in mm, confirmed)``, or None when cancelled.
    ``confirmed`` is True when the user confirmed a stock that does not fit the measured
    mean."""
    from .panels import StockDialog

    dlg = StockDialog(title, value, deviation, _parent())
    return dlg.answer() if run_dialog(dlg) else None


def run_dialog(dialog):
    """Run a modal dialog; True when accepted."""
    from .fcgui import run_modal

    return run_modal(dialog) == QtGui.QDialog.Accepted
