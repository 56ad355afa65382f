# SPDX-License-Identifier: LGPL-2.1-or-later
"""What the workbench's task panels share: OK applies and closes as one undo step, Cancel
puts the document back, and the panel's buttons in both Qt generations."""

import FreeCADGui
from PySide import QtGui


def ok_cancel_buttons():
    """The task dialog's OK and Cancel buttons as FreeCAD wants them: Qt5 flags convert
    with int(), Qt6 (PySide6) flags are Python enums with .value."""
    buttons = QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel
    return buttons.value if hasattr(buttons, "value") else int(buttons)


class UndoTaskPanel:
    """A task panel whose changes are one undo step (``self.step``, an
    :class:`surfcomp.app.undo.UndoStep`): ``apply()`` writes them (False keeps the panel
    open with its message), OK commits, Cancel aborts. ``instance``: the open panel of the
    subclass, or None."""

    instance = None

    def apply(self):
        raise NotImplementedError

    def accept(self):
        if not self.apply():
            return False        # keep the panel open with the message
        self.step.commit()
        self._close()
        return True

    def reject(self):
        self.step.abort()
        self._close()
        return True

    def _close(self):
        type(self).instance = None
        FreeCADGui.Control.closeDialog()

    def getStandardButtons(self):
        return ok_cancel_buttons()
