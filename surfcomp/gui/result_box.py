# SPDX-License-Identifier: LGPL-2.1-or-later
"""The text box in which a task panel or dialog shows its result or error.

A word-wrapped label grows with its message, but the window around it does not follow: a
task box keeps the height it opened with, and a dialog the size it was shown at, so a
message longer than the one shown first was cut off, or pushed the widgets below it under
the dialog's buttons. The box here is read-only, wraps at the width it is given and
scrolls, ``lines`` lines high whatever the message, so the window's layout does not change
with it and every line of it can be read (and copied).
"""

from PySide import QtGui

#: colour of a message the user must act on
RED = "color: #c53030;"


def result_box(lines):
    """A read-only, wrapping, scrolling text box ``lines`` lines high (it takes no more of
    a dialog that grows, where the widget above or below it is the one to grow)."""
    box = QtGui.QPlainTextEdit()
    box.setReadOnly(True)
    box.setLineWrapMode(QtGui.QPlainTextEdit.WidgetWidth)
    # the frame, the document's margins and half a line: the box scrolls by whole lines,
    # so ``lines`` lines must fit with room to spare (a bold message's lines are taller)
    spacing = box.fontMetrics().lineSpacing()
    frame = 2 * box.frameWidth() + 2 * int(box.document().documentMargin())
    box.setFixedHeight(lines * spacing + frame + spacing // 2)
    return box


def show_message(box, text, bad=False, bold=False):
    """``text`` in ``box``: red when the user must act on it (``bad``), bold too with
    ``bold``; the box scrolled to its start."""
    box.setPlainText(text)
    style = (RED + (" font-weight: bold;" if bold else "")) if bad else ""
    box.setStyleSheet(style)
