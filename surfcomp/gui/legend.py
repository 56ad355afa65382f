# SPDX-License-Identifier: LGPL-2.1-or-later
"""The legend panel: one dock widget beside the 3D view with the colour bar of every shown
map of the active document, each under the name of its object (FreeCAD GUI only).

A dock keeps its own room: however many maps are shown, and however narrow the 3D view,
every bar keeps its height and its labels (the panel scrolls), and a task panel (the
Filter panel) never covers it. The legend's contents (colour stops, labels, percentages)
come from :func:`surfcomp.core.colormap.legend` through :class:`~surfcomp.gui.mapscene.
MapScene`; the points of a map that lie outside its trimmed face are listed under its bar.
"""

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

translate = FreeCAD.Qt.translate

OBJECT_NAME = "SurfCompLegends"
#: colour bar size and the margins of one entry (pixels)
BAR_WIDTH, BAR_HEIGHT = 26, 220
LEFT, TOP = 92, 8
#: the panel's narrowest width (pixels): the longest label beside the bar fits
MIN_WIDTH = 290
#: how many points outside the trim an entry lists by name
LISTED = 12


def _text_layout(font, text, width):
    """``text`` laid out in lines ``width`` pixels wide: broken between words, and inside a
    word only where the word is wider than the line (a long point id); with its height."""
    layout = QtGui.QTextLayout(text, font)
    option = QtGui.QTextOption()
    option.setWrapMode(QtGui.QTextOption.WrapAtWordBoundaryOrAnywhere)
    layout.setTextOption(option)
    layout.beginLayout()
    y = 0.0
    while True:
        line = layout.createLine()
        if not line.isValid():
            break
        line.setLineWidth(width)
        line.setPosition(QtCore.QPointF(0.0, y))
        y += line.height()
    layout.endLayout()
    return layout, y


class LegendEntry(QtGui.QWidget):
    """The legend of one map: its object's name and quantity, the note, the colour bar with
    its labels and percentages, and the points outside the trimmed face."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.key = None
        self.data = None
        self.name = ""
        self.outside = []
        self.setMinimumWidth(240)

    def set_legend(self, key, name, data, outside=()):
        self.key, self.name, self.data, self.outside = key, name, data, list(outside)
        self._fit_height()
        self.update()

    def _fit_height(self):
        """The height the entry needs at its width (its texts wrap): a taller entry makes
        the panel scroll."""
        h = self._height()
        if h != self.minimumHeight():
            self.setMinimumHeight(h)
            self.updateGeometry()

    def resizeEvent(self, event):
        super().resizeEvent(event)
        self._fit_height()

    def _lines(self):
        d = self.data
        return [self.name, d["title"]] + ([d["note"]] if d["note"] else []) + \
            list(d.get("problems", ()))

    def _line_height(self):
        return self.fontMetrics().height()

    def _bold(self):
        font = QtGui.QFont(self.font())
        font.setBold(True)
        return font

    def _wrapped(self, font, text, top):
        """The rectangle ``text`` takes wrapped to the entry's width, from row ``top``."""
        width = max(self.width(), self.minimumWidth()) - 16
        _layout, height = _text_layout(font, text, width)
        return QtCore.QRect(8, top, width, max(int(height + 0.999), self._line_height()))

    def text_blocks(self):
        """``[(text, font, QRect)]``: the name, quantity and note above the bar and the list
        of the points outside the trimmed face below it, each wrapped to the entry's width
        (also for tests)."""
        if self.data is None:
            return []
        out, y = [], TOP
        for k, line in enumerate(self._lines()):
            font = self._bold() if k == 0 else self.font()
            out.append((line, font, self._wrapped(font, line, y)))
            y = out[-1][2].bottom() + 1
        if self.outside:
            top = y + 14 + BAR_HEIGHT + 10 + self._line_height()
            out.append((self.outside_text(), self.font(),
                        self._wrapped(self.font(), self.outside_text(), top)))
        return out

    def bar_rect(self):
        """The colour bar in widget pixels (a QRect), also for tests."""
        head = self.text_blocks()[:len(self._lines())] if self.data is not None else []
        top = (head[-1][2].bottom() + 1 if head else TOP) + 14
        return QtCore.QRect(LEFT, top, BAR_WIDTH, BAR_HEIGHT)

    def y_of(self, fraction):
        """Widget row of ``fraction`` (0 bottom, 1 top) along the bar."""
        r = self.bar_rect()
        return r.bottom() - fraction * (r.height() - 1)

    def outside_text(self):
        """The list of the points outside the trimmed face ('' when none)."""
        if not self.outside:
            return ""
        names = ", ".join(self.outside[:LISTED])
        more = translate("SurfComp", " and %d more") % (len(self.outside) - LISTED) \
            if len(self.outside) > LISTED else ""
        return translate("SurfComp", "%d point(s) outside the trimmed face, not drawn on it "
                                     "(used for the correction): %s%s") % (
            len(self.outside), names, more)

    def _height(self):
        if self.data is None:
            return 40
        blocks = self.text_blocks()
        if self.outside:
            return blocks[-1][2].bottom() + 1 + self._line_height()
        return self.bar_rect().bottom() + 14 + self._line_height()

    def sizeHint(self):
        return QtCore.QSize(280, self._height())

    def texts(self):
        """Every text the entry draws (for tests and scripts)."""
        if self.data is None:
            return []
        d = self.data
        out = self._lines() + [t for _f, t in d["labels"]]
        out += [t for _f, t in d["side"]]
        if self.outside:
            out.append(self.outside_text())
        return out

    def paintEvent(self, _event):
        p = QtGui.QPainter(self)
        p.fillRect(self.rect(), QtGui.QColor(255, 255, 255))
        if self.data is None:
            p.end()
            return
        d = self.data
        lh = self._line_height()
        red = set(d.get("problems", ())) | ({self.outside_text()} if self.outside else set())
        for text, font, r in self.text_blocks():
            p.setFont(font)
            p.setPen(QtGui.QColor(150, 0, 0) if text in red else QtGui.QColor(0, 0, 0))
            _text_layout(font, text, r.width())[0].draw(p, QtCore.QPointF(r.topLeft()))
        p.setFont(self.font())
        p.setPen(QtGui.QColor(0, 0, 0))
        bar = self.bar_rect()
        self._paint_bar(p, bar, d)
        for f, text in d["labels"]:
            p.drawText(bar.right() + 8, int(self.y_of(f) + lh / 3), text)
        for f, text in d["side"]:
            w = p.fontMetrics().boundingRect(text).width()
            p.drawText(bar.left() - 8 - w, int(self.y_of(f) + lh / 3), text)
        p.end()

    def _paint_bar(self, p, bar, d):
        stops = d["stops"]
        for (f0, c0), (f1, c1) in zip(stops[:-1], stops[1:]):
            if f1 <= f0:
                continue
            y0, y1 = self.y_of(f0), self.y_of(f1)
            grad = QtGui.QLinearGradient(0, y0, 0, y1)
            grad.setColorAt(0.0, QtGui.QColor.fromRgbF(*c0))
            grad.setColorAt(1.0, QtGui.QColor.fromRgbF(*c1))
            p.fillRect(QtCore.QRectF(bar.left(), y1, bar.width(), y0 - y1 + 1), grad)
        for end, rgb in (d.get("arrows") or {}).items():
            y = bar.top() - 2 if end == "above" else bar.bottom() + 2
            tip = y - 10 if end == "above" else y + 10
            poly = QtGui.QPolygonF([QtCore.QPointF(bar.left(), y),
                                    QtCore.QPointF(bar.right() + 1, y),
                                    QtCore.QPointF(bar.center().x(), tip)])
            p.setBrush(QtGui.QColor.fromRgbF(*rgb))
            p.setPen(QtGui.QColor(0, 0, 0))
            p.drawPolygon(poly)
        p.setBrush(QtCore.Qt.NoBrush)
        p.setPen(QtGui.QColor(0, 0, 0))
        p.drawRect(bar)


class LegendPanel(QtGui.QWidget):
    """The entries, one above the other, in a scroll area."""

    def __init__(self, parent=None):
        super().__init__(parent)
        outer = QtGui.QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        self.scroll = QtGui.QScrollArea(self)
        self.scroll.setWidgetResizable(True)
        self.inner = QtGui.QWidget()
        self.column = QtGui.QVBoxLayout(self.inner)
        self.column.addStretch(1)
        self.scroll.setWidget(self.inner)
        outer.addWidget(self.scroll)
        self.entries = []

    def set_entries(self, items):
        """``[(key, name, legend data, outside point names)]``, top down."""
        while len(self.entries) > len(items):
            w = self.entries.pop()
            self.column.removeWidget(w)
            w.deleteLater()
        while len(self.entries) < len(items):
            w = LegendEntry(self.inner)
            self.column.insertWidget(len(self.entries), w)
            self.entries.append(w)
        for w, item in zip(self.entries, items):
            w.set_legend(*item)


def right_dock(object_name, title, widget_class, create=True):
    """The main window's dock ``object_name`` (the legend panel, the histogram), made on
    first use on the right around a new ``widget_class`` instance; None when missing and
    not ``create``."""
    mw = FreeCADGui.getMainWindow()
    found = mw.findChild(QtGui.QDockWidget, object_name)
    if found is not None or not create:
        return found
    d = QtGui.QDockWidget(title, mw)
    d.setObjectName(object_name)
    d.setWidget(widget_class(d))
    mw.addDockWidget(QtCore.Qt.RightDockWidgetArea, d)
    return d


def dock(create=True):
    """The legend dock of the main window (made on first use, on the right)."""
    d = right_dock(OBJECT_NAME, translate("SurfComp", "SurfComp legends"), LegendPanel,
                   create)
    if d is not None:
        d.widget().setMinimumWidth(MIN_WIDTH)
    return d


def entries(doc):
    """``[(key, name, legend data, outside point names)]`` of the shown maps of ``doc``
    whose legend is on, in the document's order."""
    out = []
    for obj in doc.Objects if doc is not None else ():
        proxy = getattr(getattr(obj, "ViewObject", None), "Proxy", None)
        item = getattr(proxy, "legend_entry", None)
        item = item() if callable(item) else None
        if item is not None:
            out.append(item)
    return out


def refresh():
    """Show the legends of the active document's shown maps (hide the panel without)."""
    items = entries(FreeCAD.ActiveDocument)
    d = dock(create=bool(items))
    if d is None:
        return None
    d.widget().set_entries(items)
    d.setVisible(bool(items))
    if items:
        d.raise_()
    return d


_PENDING = []


def schedule():
    """Refresh once the current event is done (many maps change in one step)."""
    if not _PENDING:
        _PENDING.append(True)
        QtCore.QTimer.singleShot(0, _run)


def _run():
    _PENDING.clear()
    refresh()
