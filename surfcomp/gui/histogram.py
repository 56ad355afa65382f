# SPDX-License-Identifier: LGPL-2.1-or-later
"""The histogram panel: the distribution of the shown map's measured values, each bar
coloured like the legend (same scheme, range, steps or tolerance band), with the counts
beyond the range at both ends. A dock widget beside the 3D view (FreeCAD GUI only).

The counts and colours come from :func:`surfcomp.core.colormap.histogram`.
"""

import FreeCAD
from PySide import QtCore, QtGui

from ..core import colormap

translate = FreeCAD.Qt.translate

BINS = 24
OBJECT_NAME = "SurfCompHistogram"


class HistogramWidget(QtGui.QWidget):
    """Paints one histogram (:func:`surfcomp.core.colormap.histogram` dict)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.data = None
        self.title = ""
        self.unit = "um"
        self.owner = None
        self.setMinimumSize(260, 200)

    def set_histogram(self, data, title, unit):
        self.data, self.title, self.unit = data, title, unit
        self.update()

    def bar_rects(self):
        """``[(QRectF, rgb)]`` of the bars in widget pixels (also for tests)."""
        if self.data is None:
            return []
        counts = self.data["counts"]
        top = max(int(counts.max()) if counts.size else 0, 1)
        w, h = self.width(), self.height()
        x0, x1, y0, y1 = 40.0, w - 40.0, h - 40.0, 30.0
        step = (x1 - x0) / max(len(counts), 1)
        out = []
        for k, (n, rgb) in enumerate(zip(counts, self.data["colors"])):
            height = (y0 - y1) * float(n) / top
            out.append((QtCore.QRectF(x0 + k * step, y0 - height, step, height), tuple(rgb)))
        return out

    def paintEvent(self, _event):
        p = QtGui.QPainter(self)
        p.fillRect(self.rect(), QtGui.QColor(255, 255, 255))
        p.setPen(QtGui.QColor(0, 0, 0))
        p.drawText(8, 18, self.title)
        if self.data is None:
            p.end()
            return
        for rect, rgb in self.bar_rects():
            p.fillRect(rect, QtGui.QColor.fromRgbF(*rgb))
            p.drawRect(rect)
        h, w = self.height(), self.width()
        edges = self.data["edges"]
        p.drawText(4, h - 20, colormap.format_value(edges[0], self.unit))
        right = colormap.format_value(edges[-1], self.unit)
        p.drawText(w - 8 - p.fontMetrics().horizontalAdvance(right)
                   if hasattr(p.fontMetrics(), "horizontalAdvance")
                   else w - 90, h - 20, right)
        total = max(self.data["total"], 1)
        p.drawText(4, h - 4, translate("SurfComp", "below range: %.1f %%")
                   % (100.0 * self.data["below"] / total))
        text = translate("SurfComp", "above range: %.1f %%") % (100.0 * self.data["above"] / total)
        p.drawText(w // 2, h - 4, text)
        p.end()


def dock(create=True):
    """The histogram dock of the main window (made on first use)."""
    from .legend import right_dock

    return right_dock(OBJECT_NAME, translate("SurfComp", "SurfComp histogram"),
                      HistogramWidget, create)


def show_map(vobj, scene):
    """Show the histogram of the map ``scene`` draws for the view object ``vobj``."""
    style = scene._style
    values = scene._marker_values if scene._marker_values is not None else scene._values
    if values is None or scene.range is None:
        return
    vmin, vmax = scene.range
    data = colormap.histogram(values, vmin, vmax, BINS, style.scheme, style.tolerance,
                              style.warning, style.levels if style.stepped else None)
    d = dock()
    title = "%s: %s [%s]" % (vobj.Object.Label, scene._title, colormap.UNIT_TEXT[style.unit])
    d.widget().set_histogram(data, title, style.unit)
    d.widget().owner = _key(vobj)
    d.show()
    return d


def _key(vobj):
    obj = vobj.Object
    return (obj.Document.Name, obj.Name)


def close_map(vobj):
    """Close the histogram panel when it shows the map of ``vobj`` (its Histogram was
    switched off, or the map hidden)."""
    d = dock(create=False)
    if d is not None and getattr(d.widget(), "owner", None) == _key(vobj) and d.isVisible():
        d.close()
