# SPDX-License-Identifier: LGPL-2.1-or-later
"""Coin scene of a colour map: coloured face mesh, coloured point markers, labels at the
extremes and a colour-bar legend drawn over the 3D view (FreeCAD GUI only).

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

#: legend placement in normalised device coordinates (-1 .. 1 across the view): the bar's
#: x extent, the labels' x, and the vertical region the legends share (stacked top down)
BAR_X = (0.74, 0.79)
LABEL_X = 0.805
REGION_Y = (-0.92, 0.86)
#: room above a bar for its title (NDC)
TITLE_ROOM = 0.14
#: pixels kept free around the navigation cube
CUBE_MARGIN = 16


def legend_layout(slot=0, slots=1, clear_top_px=0, clear_bottom_px=0, view_height=1000):
    """Where legend ``slot`` of ``slots`` sits (NDC): ``bar_x``, ``bar_y``, ``label_x``,
    ``title_y``. The legends of the visible maps share the region on the right, one
    above the other, so they never overlap; ``clear_top_px``/``clear_bottom_px`` keep
    the region clear of the navigation cube in a view ``view_height`` pixels high."""
    h = max(float(view_height), 100.0)
    y0 = max(REGION_Y[0], -1.0 + 2.0 * clear_bottom_px / h)
    y1 = min(REGION_Y[1], 1.0 - 2.0 * clear_top_px / h)
    step = (y1 - y0) / max(int(slots), 1)
    top = y1 - slot * step
    bar = (top - step + 0.05, top - TITLE_ROOM)
    return {"bar_x": BAR_X, "bar_y": bar, "label_x": LABEL_X, "title_y": top - 0.04,
            "slot": slot, "slots": slots}


@dataclass
class MapStyle:
    """Display choices of a map (all lengths in mm).

    ``vmin``/``vmax`` None: symmetric range around zero from the values;
    ``tolerance`` ``(lower, upper)`` switches to the tolerance-band colouring, with a
    ``warning`` band (fraction of the tolerance, :func:`surfcomp.core.colormap.warning_limits`);
    ``stepped`` draws one flat colour per legend step; ``out_of_range`` gives values
    outside a manual range their own colours (with arrows on the legend); ``note`` is a
    second title line (the sign convention of a correction map).
    """

    scheme: str = colormap.DEFAULT_SCHEME
    vmin: float = None
    vmax: float = None
    tolerance: tuple = None
    warning: float = None
    unit: str = "mm"
    levels: int = 10
    stepped: bool = False
    out_of_range: bool = True
    show_points: bool = True
    show_labels: bool = True
    show_legend: bool = True
    point_size: int = 7
    note: str = ""
    layout: dict = None

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


def _gate_for_picking(gate, action):
    """SoCallback: close ``gate`` (an SoSwitch) to pick actions, open it to all others.
    The field changes without notification: no redraw is scheduled by the traversal."""
    want = coin.SO_SWITCH_NONE if action.isOfType(coin.SoPickAction.getClassTypeId()) \
        else coin.SO_SWITCH_ALL
    if gate.whichChild.getValue() != want:
        gate.enableNotify(False)
        gate.whichChild = want
        gate.enableNotify(True)


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

        # legend: drawn last, over everything, in its own fixed camera, outside bounding boxes;
        # left out of picking (the gate): a camera node sets the pick ray of the whole pick
        # action, not only below its separator, so a pick through the legend's camera would
        # miss every object drawn after the map (a tool path could not be selected), and a
        # hit on the legend is no point of the map anyway
        self.legend_switch = coin.SoSwitch()
        self.legend = coin.SoAnnotation()
        self.legend_switch.addChild(self.legend)
        self._legend_gate = coin.SoSwitch()
        self._legend_gate.whichChild = coin.SO_SWITCH_ALL
        self._legend_gate.addChild(self.legend_switch)
        guard = coin.SoCallback()
        guard.setCallback(_gate_for_picking, self._legend_gate)
        skip = coin.SoType.fromName(coin.SbName("SoSkipBoundingGroup")).createInstance()
        skip.addChild(guard)
        skip.addChild(self._legend_gate)

        for node in (self.surface, self.markers_switch, self.labels_switch, self.flags, skip):
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
        self.legend.removeAllChildren()
        self.flags.removeAllChildren()
        self.range = None

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
        self._draw_legend(style, vmin, vmax)

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
        for idx, word in ((i_max, "max"), (i_min, "min")):
            if idx is None:
                continue
            self.labels.addChild(_text(pts[idx], "  %s %s" % (word, colormap.format_value(
                vals[idx], style.unit))))
        self.extreme_indices = (i_max, i_min)

    def set_flags(self, flags):
        """Flag labels: ``[(point (3,), text)]`` in the map's coordinates."""
        self.flags.removeAllChildren()
        for point, text in flags:
            self.flags.addChild(_flag(point, text))

    def _draw_legend(self, style, vmin, vmax):
        leg = self.legend
        leg.removeAllChildren()
        self.legend_switch.whichChild = 0 if style.show_legend else -1
        lay = style.layout or legend_layout()
        self.legend_layout = lay
        cam = coin.SoOrthographicCamera()
        cam.viewportMapping = coin.SoCamera.LEAVE_ALONE
        cam.position.setValue(0.0, 0.0, 1.0)
        cam.height = 2.0
        cam.nearDistance = 0.5
        cam.farDistance = 1.5
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        leg.addChild(cam)
        leg.addChild(light)
        data = colormap.legend(vmin, vmax, style.scheme, style.unit, style.levels,
                               style.tolerance, stepped=style.stepped, warning=style.warning)
        y0, y1 = lay["bar_y"]
        x0, x1 = lay["bar_x"]

        def y_of(f):
            return y0 + f * (y1 - y0)

        quads = []
        for (f0, c0), (f1, c1) in zip(data["stops"][:-1], data["stops"][1:]):
            if f1 > f0:
                quads.append(([(x0, y_of(f0)), (x1, y_of(f0)), (x1, y_of(f1)), (x0, y_of(f1))],
                              [c0, c0, c1, c1]))
        values = self._marker_values if self._marker_values is not None else self._values
        if style.out_of_range and style.manual() and style.tolerance is None:
            # arrows past the ends: the colours of values outside the manual range
            below = colormap.OUT_OF_RANGE_COLORS["below"]
            above = colormap.OUT_OF_RANGE_COLORS["above"]
            xm, a = 0.5 * (x0 + x1), 0.035
            quads.append(([(x0, y0 - 0.005), (x1, y0 - 0.005), (xm, y0 - a), (xm, y0 - a)],
                          [below] * 4))
            quads.append(([(x0, y1 + 0.005), (x1, y1 + 0.005), (xm, y1 + a), (xm, y1 + a)],
                          [above] * 4))
            fr = colormap.band_fractions(values, vmin, vmax)
            leg.addChild(_text((x0 - 0.01, y0 - a, 0.0), "< %.1f %%" % fr["below"], size=13,
                               justification=coin.SoText2.RIGHT))
            leg.addChild(_text((x0 - 0.01, y1 + 0.01, 0.0), "> %.1f %%" % fr["above"], size=13,
                               justification=coin.SoText2.RIGHT))
        leg.addChild(_quads(quads))
        leg.addChild(_polyline([(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]))
        for f, text in data["labels"]:
            leg.addChild(_text((lay["label_x"], y_of(f) - 0.01, 0.0), text))
        if style.tolerance is not None:
            # percent of the measured points in each block, left of the bar
            fr = colormap.band_fractions(values, *style.tolerance, warning=style.warning)
            words = {"below": "below", "inside": "in", "above": "above", "warning": "warn"}
            done = set()
            for name, f0, f1 in data["blocks"]:
                if name in done:
                    continue
                done.add(name)
                leg.addChild(_text((x0 - 0.01, y_of(0.5 * (f0 + f1)) - 0.01, 0.0),
                                   "%s %.1f %%" % (words[name], fr[name]), size=13,
                                   justification=coin.SoText2.RIGHT))
        title = self._title + (" [%s]" % colormap.UNIT_TEXT[style.unit] if self._title else "")
        if style.tolerance is not None:
            title += " - tolerance band"
        leg.addChild(_text((x1, lay["title_y"], 0.0), title, size=17,
                           justification=coin.SoText2.RIGHT))
        if style.note:
            leg.addChild(_text((x1, lay["title_y"] - 0.05, 0.0), style.note, size=14,
                               justification=coin.SoText2.RIGHT))


def _quads(quads):
    """One face set of quadrilaterals ``[(4 xy corners, 4 rgb)]`` with per-vertex colours."""
    coords, colors, index = [], [], []
    for corners, cols in quads:
        k = len(coords)
        coords += [(x, y, 0.0) for x, y in corners]
        colors += list(cols)
        index += [k, k + 1, k + 2, k + 3, -1]
    sep = coin.SoSeparator()
    c3 = coin.SoCoordinate3()
    c3.point.setValues(0, len(coords), coords)
    bc = coin.SoBaseColor()
    bc.rgb.setValues(0, len(colors), colors)
    mb = coin.SoMaterialBinding()
    mb.value = coin.SoMaterialBinding.PER_VERTEX_INDEXED
    fs = coin.SoIndexedFaceSet()
    fs.coordIndex.setValues(0, len(index), index)
    fs.materialIndex.setValues(0, len(index), index)
    for node in (c3, bc, mb, fs):
        sep.addChild(node)
    return sep


def _polyline(points, color=(0.0, 0.0, 0.0)):
    sep = coin.SoSeparator()
    c3 = coin.SoCoordinate3()
    c3.point.setValues(0, len(points), [(x, y, 0.01) for x, y in points])
    col = coin.SoBaseColor()
    col.rgb.setValue(*color)
    line = coin.SoLineSet()
    line.numVertices.setValue(len(points))
    for node in (c3, col, line):
        sep.addChild(node)
    return sep


def _flag(point, text):
    """A flag at a measured point: a black dot and its text over everything."""
    sep = coin.SoSeparator()
    c3 = coin.SoCoordinate3()
    c3.point.setValue(*map(float, point))
    col = coin.SoBaseColor()
    col.rgb.setValue(0.0, 0.0, 0.0)
    style = coin.SoDrawStyle()
    style.pointSize = 9
    for node in (col, style, c3, coin.SoPointSet()):
        sep.addChild(node)
    label = _text(point, "", size=14)
    # on the line below the point: the min/max label may sit on the point's own line
    label.getChild(3).string.setValues(0, 2, ["", "  " + text])
    sep.addChild(label)
    return sep
