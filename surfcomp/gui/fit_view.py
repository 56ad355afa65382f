# SPDX-License-Identifier: LGPL-2.1-or-later
"""Keep a task panel's result in sight: its options scroll, the task view does not.

FreeCAD's task view gives a panel the height the panel asks for and scrolls when that is
more than it shows. A panel with many options above its Apply button and result box (the
Align measurements panel: 612 px on FreeCAD 0.20, 597 px on 1.1, in a task view that shows
about 400 px of it in a 1280x800 window) then hides the result below the fold, and the
user scrolls down after every Apply. Here the options sit in a scroll area of their own
whose height follows the task view: all of them when there is room, fewer (scrolling) when
there is not, so Apply and the result box stay visible.
"""

from PySide import QtCore, QtGui

#: room left under the panel in the task view (the task box's frame and margin)
BELOW = 16


def options_area(widget):
    """A frameless scroll area around ``widget`` that scrolls vertically only and is as
    wide as ``widget`` needs."""
    area = QtGui.QScrollArea()
    area.setWidget(widget)
    area.setWidgetResizable(True)
    area.setFrameShape(QtGui.QFrame.NoFrame)
    area.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarAlwaysOff)
    area.setMinimumWidth(widget.minimumSizeHint().width()
                         + area.verticalScrollBar().sizeHint().width())
    return area


def _task_view(widget):
    """The scroll area (FreeCAD's task view) ``widget`` is shown in, or None."""
    w = widget.parentWidget()
    while w is not None and not isinstance(w, QtGui.QScrollArea):
        w = w.parentWidget()
    return w


class FitInView(QtCore.QObject):
    """Sizes ``area`` (an :func:`options_area` inside ``form``) so that ``form`` ends in
    the visible part of the task view, ``least`` pixels high at the least (then the task
    view scrolls, as before) and no higher than its options need."""

    def __init__(self, form, area, least):
        super().__init__(form)
        self.form, self.area, self.least = form, area, least
        self.view = None
        form.installEventFilter(self)

    def eventFilter(self, obj, event):
        kind = event.type()
        if obj is self.form and kind in (QtCore.QEvent.Show, QtCore.QEvent.Resize):
            if self.view is None:
                self.view = _task_view(self.form)
                if self.view is not None:
                    self.view.viewport().installEventFilter(self)
            self.fit()
        elif self.view is not None and obj is self.view.viewport() \
                and kind == QtCore.QEvent.Resize:
            self.fit()
        return False

    def fit(self):
        """Give the options the height the task view has left for them: what is below the
        form's top, less what the form needs besides the options. From the form's size
        hint, not its height: FreeCAD 1.1's task box gives the form its new height some
        events later, and a height read in between made the options grow and shrink in turn."""
        if self.view is None or self.view.widget() is None:
            return
        top = self.form.mapTo(self.view.widget(), QtCore.QPoint(0, 0)).y()
        rest = self.form.sizeHint().height() - self.area.height()
        full = self.area.widget().sizeHint().height() + 2 * self.area.frameWidth()
        room = self.view.viewport().height() - top - rest - BELOW
        height = max(self.least, min(full, room))
        if height != self.area.height():
            self.area.setFixedHeight(height)
