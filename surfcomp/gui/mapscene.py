# SPDX-License-Identifier: LGPL-2.1-or-later
"""Coin scene of a colour map: coloured face mesh, coloured point markers, labels at the
extremes and flags (FreeCAD GUI only); the colour bar legend it describes (``legend_data``)
is drawn in the legend panel (:mod:`surfcomp.gui.legend`).

No numerics here: colours, ranges and legend levels come from
:mod:`surfcomp.core.colormap`; the mesh and the values are given by the caller.

Use::

    scene = MapScene()
    scene.set_data(points, triangles, values, marker_points, marker_values, title="Deviation")
    scene.set_style(MapStyle(scheme="rainbow", unit="um"))
    some_separator.addChild(scene.root)

``set_style`` only recolours (no new geometry), so changing range, scheme or
tolerance band redraws at once.
"""

from dataclasses import dataclass

import numpy as np
from pivy import coin

from ..core import colormap


@dataclass
class MapStyle:
    """Display choices of a map (all lengths in mm).

    ``vmin``/``vmax`` None: symmetric range around zero from the values;
    ``tolerance`` ``(lower, upper)`` switches to the tolerance-band colouring, with a
    ``warning`` band (fraction of the tolerance, :func:`surfcomp.core.colormap.warning_limits`);
    ``stepped`` draws one flat colour per legend step; ``out_of_range`` gives values
    outside a manual range their own colours (with arrows on the legend); ``note`` is a
    second title line (the sign convention of a correction map); ``problems`` the settings
    the map is drawn without, and why (shown under the note, in red).
    """

    scheme: str = colormap.DEFAULT_SCHEME
    vmin: float = None
    vmax: float = None
    tolerance: tuple = None
    warning: float = None
    unit: str = "um"
    levels: int = 10
    stepped: bool = False
    out_of_range: bool = True
    show_points: bool = True
    show_labels: bool = True
    show_legend: bool = True
    point_size: int = 7
    note: str = ""
    problems: tuple = ()

    def manual(self):
        return self.vmin is not None and self.vmax is not None and self.vmax > self.vmin

    def range_for(self, values):
        """The colour range for ``values``: the style's own or the symmetric default."""
        if self.manual():
            return float(self.vmin), float(self.vmax)
        return colormap.symmetric_range(values)


def _colors(values, style, vmin, vmax):
    if style.tolerance is not None:
        return colormap.tolerance_colors(values, *style.tolerance, warning=style.warning)
    return colormap.map_colors(values, vmin, vmax, style.scheme,
                               levels=style.levels if style.stepped else None,
                               out_of_range=style.out_of_range and style.manual())


def _text(position, text, color=(0.0, 0.0, 0.0), size=15, justification=None):
    sep = coin.SoSeparator()
    tr = coin.SoTranslation()
    tr.translation.setValue(*map(float, position))
    col = coin.SoBaseColor()
    col.rgb.setValue(*color)
    font = coin.SoFont()
    font.size = size
    txt = coin.SoText2()
    txt.string.setValue(text)
    if justification is not None:
        txt.justification = justification
    for node in (tr, col, font, txt):
        sep.addChild(node)
    return sep


class MapScene:
    """The scene nodes of one colour map (see module docstring). ``root`` is the node
    to add to a view provider's display mode or to a scene graph."""

    def __init__(self):
        self.root = coin.SoSeparator()
        self.root.setName("SurfCompMap")
        self._style = MapStyle()
        self._values = None
        self._marker_values = None
        self._marker_points = None
        self._points = None
        self._mesh = None           # the (points, triangles) arrays drawn
        self._title = ""
        self.range = None
        self.legend_data = None
        self.label_anchors = []

        # the face mesh: unlit per-vertex colours, pushed back so markers stay in front
        self.surface = coin.SoSeparator()
        hints = coin.SoShapeHints()
        hints.vertexOrdering = coin.SoShapeHints.UNKNOWN_ORDERING
        self.surface_coords = coin.SoCoordinate3()
        self.surface_colors = coin.SoBaseColor()
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_VERTEX_INDEXED
        offset = coin.SoPolygonOffset()
        offset.factor = 1.0
        offset.units = 1.0
        self.faces = coin.SoIndexedFaceSet()
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        for node in (hints, light, offset, self.surface_coords, self.surface_colors, binding,
                     self.faces):
            self.surface.addChild(node)

        # measured points as coloured markers
        self.markers_switch = coin.SoSwitch()
        markers = coin.SoSeparator()
        self.marker_coords = coin.SoCoordinate3()
        self.marker_colors = coin.SoBaseColor()
        mbind = coin.SoMaterialBinding()
        mbind.value = coin.SoMaterialBinding.PER_VERTEX
        # GL points, not SoMarkerSet: bitmap markers cost seconds for 40 000 points
        self.marker_style = coin.SoDrawStyle()
        self.marker_style.pointSize = 7
        self.marker_set = coin.SoPointSet()
        for node in (light.copy(), self.marker_style, self.marker_coords, self.marker_colors,
                     mbind, self.marker_set):
            markers.addChild(node)
        self.markers_switch.addChild(markers)

        # labels at the largest positive and negative value
        self.labels_switch = coin.SoSwitch()
        self.labels = coin.SoAnnotation()      # drawn over the surface
        self.labels_switch.addChild(self.labels)

        # flags: labels the user placed at measured points (value and id)
        self.flags = coin.SoAnnotation()

        for node in (self.surface, self.markers_switch, self.labels_switch, self.flags):
            self.root.addChild(node)

    # -- data --------------------------------------------------------------------------
    def set_data(self, points, triangles, values, marker_points=None, marker_values=None,
                 title="", restyle=True):
        """New geometry and values.

        Parameters
        ----------
        points : ndarray, shape (N, 3)
            Mesh vertices (mm).
        triangles : ndarray of int, shape (M, 3)
            (The very ``points`` and ``triangles`` objects of the previous call are taken
            as the same mesh and not sent to Coin again: new values on the same mesh
            only recolour it.)
        values : ndarray, shape (N,)
            Value at every vertex (mm).
        marker_points : ndarray, shape (K, 3), optional
            Measured points drawn as markers, coloured by ``marker_values`` (K,).
        title : str
            Legend title (e.g. ``'Deviation'``).
        restyle : bool
            Recolour with the current style now (False: the caller sets a style next).
        """
        self._values = np.asarray(values, dtype=float).ravel()
        if self._mesh is None or self._mesh[0] is not points or self._mesh[1] is not triangles:
            # new geometry (the same mesh arrays again, a refiltered preview: only values)
            self._mesh = (points, triangles)
            points = np.ascontiguousarray(points, dtype=np.float32).reshape(-1, 3)
            tri = np.asarray(triangles, dtype=np.int32).reshape(-1, 3)
            self._points = points.astype(float)
            self.surface_coords.point.setNum(0)
            self.surface_coords.point.setValues(0, len(points), points)
            idx = np.concatenate([tri, -np.ones((len(tri), 1), dtype=np.int32)], axis=1).ravel()
            self.faces.coordIndex.setNum(0)
            self.faces.coordIndex.setValues(0, len(idx), idx.tolist())
            self.faces.materialIndex.setNum(0)
            self.faces.materialIndex.setValues(0, len(idx), idx.tolist())
        if marker_points is not None and len(marker_points):
            mp = np.ascontiguousarray(marker_points, dtype=np.float32).reshape(-1, 3)
            self._marker_points = mp.astype(float)
            self._marker_values = np.asarray(marker_values, dtype=float).ravel()
            self.marker_coords.point.setNum(0)
            self.marker_coords.point.setValues(0, len(mp), mp)
        else:
            self._marker_points = self._marker_values = None
            self.marker_coords.point.setNum(0)
        self._title = title
        if restyle:
            self.set_style(self._style)

    def clear(self):
        """Show nothing (no data)."""
        self._values = self._marker_values = self._marker_points = self._mesh = None
        for field in (self.surface_coords.point, self.faces.coordIndex,
                      self.faces.materialIndex, self.marker_coords.point):
            field.setNum(0)
        self.labels.removeAllChildren()
        self.flags.removeAllChildren()
        self.range = None
        self.legend_data = None

    # -- style ------------------------------------------------------------------------
    def set_style(self, style):
        """Recolour with ``style`` (:class:`MapStyle`); geometry is kept."""
        self._style = style
        if self._values is None:
            return
        ref = self._marker_values if self._marker_values is not None else self._values
        vmin, vmax = style.range_for(np.concatenate([self._values, ref]))
        self.range = (vmin, vmax)
        cols = _colors(self._values, style, vmin, vmax).astype(np.float32)
        self.surface_colors.rgb.setNum(0)
        self.surface_colors.rgb.setValues(0, len(cols), cols)
        self.markers_switch.whichChild = -1
        if self._marker_values is not None and style.show_points:
            mc = _colors(self._marker_values, style, vmin, vmax).astype(np.float32)
            self.marker_colors.rgb.setNum(0)
            self.marker_colors.rgb.setValues(0, len(mc), mc)
            self.marker_style.pointSize = float(style.point_size)
            self.markers_switch.whichChild = 0
        self._draw_labels(style)
        self.legend_data = self._legend(style, vmin, vmax) if style.show_legend else None

    def _draw_labels(self, style):
        self.labels.removeAllChildren()
        self.labels_switch.whichChild = 0 if style.show_labels else -1
        if self._marker_values is not None:
            pts, vals = self._marker_points, self._marker_values
        else:
            pts, vals = None, self._values
        if pts is None:
            pts = self._points
        i_max, i_min = colormap.extremes(vals)
        self.label_anchors = []
        for idx, word in ((i_max, "max"), (i_min, "min")):
            if idx is None:
                continue
            text = "  %s %s" % (word, colormap.format_value(vals[idx], style.unit))
            self.labels.addChild(_text(pts[idx], text))
            if style.show_labels:
                self.label_anchors.append((tuple(map(float, pts[idx])), text))

    def set_flags(self, flags):
        """Flags: ``[(point (3,), text, leader (3,), justification)]`` in the map's
        coordinates (:func:`surfcomp.gui.flags.layout`): a dot at the point, a leader line
        along ``leader`` and the text at its end, aligned 'right', 'left' or 'center'."""
        self.flags.removeAllChildren()
        for point, text, leader, justification in flags:
            self.flags.addChild(_flag(point, text, leader, justification))

    def _legend(self, style, vmin, vmax):
        """What the legend panel (:mod:`surfcomp.gui.legend`) draws for this map: the colour
        stops and labels of :func:`surfcomp.core.colormap.legend`, the title with its unit,
        the note, the percentages beside the bar (``side``) and the out-of-range arrows."""
        data = colormap.legend(vmin, vmax, style.scheme, style.unit, style.levels,
                               style.tolerance, stepped=style.stepped, warning=style.warning)
        values = self._marker_values if self._marker_values is not None else self._values
        side, arrows = [], None
        if style.out_of_range and style.manual() and style.tolerance is None:
            fr = colormap.band_fractions(values, vmin, vmax)
            arrows = {"below": tuple(colormap.OUT_OF_RANGE_COLORS["below"]),
                      "above": tuple(colormap.OUT_OF_RANGE_COLORS["above"])}
            side += [(0.0, "< %.1f %%" % fr["below"]), (1.0, "> %.1f %%" % fr["above"])]
        if style.tolerance is not None:
            # percent of the measured points in each block, left of the bar
            fr = colormap.band_fractions(values, *style.tolerance, warning=style.warning)
            words = {"below": "below", "inside": "in", "above": "above", "warning": "warn"}
            done = set()
            for name, f0, f1 in data["blocks"]:
                if name not in done:
                    done.add(name)
                    side.append((0.5 * (f0 + f1), "%s %.1f %%" % (words[name], fr[name])))
        title = self._title + (" [%s]" % colormap.UNIT_TEXT[style.unit] if self._title else "")
        if style.tolerance is not None:
            title += " - tolerance band"
        return {"title": title, "note": style.note, "problems": list(style.problems),
                "stops": data["stops"],
                "labels": data["labels"], "side": side, "arrows": arrows,
                "range": (vmin, vmax), "unit": style.unit}

def _flag(point, text, leader, justification):
    """A flag at a measured point: a black dot, a leader line and its text over everything."""
    sep = coin.SoSeparator()
    col = coin.SoBaseColor()
    col.rgb.setValue(0.0, 0.0, 0.0)
    style = coin.SoDrawStyle()
    style.pointSize = 9
    style.lineWidth = 1.5
    c3 = coin.SoCoordinate3()
    p = [float(c) for c in point]
    end = [a + float(b) for a, b in zip(p, leader)]
    c3.point.setValues(0, 2, [p, end])
    dot = coin.SoPointSet()
    dot.numPoints = 1
    line = coin.SoLineSet()
    line.numVertices.setValue(2)
    for node in (col, style, c3, dot, line):
        sep.addChild(node)
    just = {"right": coin.SoText2.RIGHT, "left": coin.SoText2.LEFT,
            "center": coin.SoText2.CENTER}[justification]
    pad = {"right": text + " ", "left": " " + text, "center": text}[justification]
    sep.addChild(_text(end, pad, size=14, justification=just))
    return sep
