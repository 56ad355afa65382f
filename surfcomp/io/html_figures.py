# SPDX-License-Identifier: LGPL-2.1-or-later
"""The figures of the HTML report (:mod:`surfcomp.io.html_report`): maps, histograms and the
simulation's bar chart as matplotlib Figures on the Agg canvas (no pyplot state), and
:func:`png` to encode one.

The report's figures have a fixed layout: axes and colorbar at explicit positions (margins in
inches) wide enough for the labels of any face in mm and any deviation in µm, instead of
matplotlib's constrained layout. Constrained layout measures every text at each save and,
with a layout engine set, ``savefig`` draws each figure twice; the fixed layout draws it once,
which halves the time of a report. The colorbar sits beside the map as drawn (after the equal
aspect shrank it), as constrained layout placed it. The titles sit at a given height (none
of the figures has tick labels above its axes, which matplotlib would otherwise look for at
every draw). :func:`simulation_maps_figure` (several maps in one figure, e.g. for the
README) keeps constrained layout. A report's maps are drawn by one :class:`MapPainter`.
"""

import base64
import io

import numpy as np

from ..core import colormap

#: the maps' colours: scheme name and range (mm) or None for each map's symmetric range
DEFAULT_STYLE = {"scheme": colormap.DEFAULT_SCHEME, "range": None}

#: resolution of the embedded PNGs
DPI = 90


def png(fig):
    """``fig`` as a base64 PNG (str) at :data:`DPI`: RGB (the figures are opaque), zlib
    level 4, which encodes in half the time of PIL's default 6 for a few % more bytes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    canvas = FigureCanvasAgg(fig)
    dpi = fig.dpi
    fig.set_dpi(DPI)
    canvas.draw()
    img = Image.frombuffer("RGBA", canvas.get_width_height(), canvas.buffer_rgba(),
                           "raw", "RGBA", 0, 1).convert("RGB")
    fig.set_dpi(dpi)  # as savefig does: a reused figure is laid out at its own dpi again
    buf = io.BytesIO()
    img.save(buf, format="png", compress_level=4)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _axes(fig, left, bottom, right, top):
    """Axes filling ``fig`` but for the given margins (inches)."""
    w, h = fig.get_size_inches()
    return fig.add_axes((left / w, bottom / h, 1 - (left + right) / w, 1 - (bottom + top) / h))


def _figure(size):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size)  # no layout engine: the callers place the axes
    FigureCanvasAgg(fig)
    return fig


def _tick_width(axis):
    """The widest major tick label of ``axis`` as it will be drawn (inches)."""
    renderer = axis.figure.canvas.get_renderer()
    widths = [t.get_window_extent(renderer).width for t in axis.get_majorticklabels()
              if t.get_text()]
    return max(widths, default=0.0) / axis.figure.dpi


def _place_map(fig, ax, cax):
    """Place a map's axes and colorbar: the margins fit the tick labels of both (measured
    as drawn), the colorbar 0.85 of the map's slot high, beside the map as the equal aspect
    shrinks it."""
    w, h = fig.get_size_inches()
    # label, its pad, tick length and pad, the ticks (inches); bottom and top fixed
    left = 0.1 + 0.2 + 0.1 + _tick_width(ax.yaxis)
    right = 0.2 + 0.16 + 0.1 + _tick_width(cax.yaxis) + 0.1 + 0.2 + 0.05
    bottom, top = 0.55, 0.3
    ax.set_position((left / w, bottom / h, 1 - (left + right) / w, 1 - (bottom + top) / h))
    ax.apply_aspect()
    pos, slot = ax.get_position(), ax.get_position(original=True)
    cax.set_position((pos.x1 + 0.2 / w, slot.y0 + 0.075 * slot.height, 0.16 / w,
                      0.85 * slot.height))


def _cmap(scheme):
    from matplotlib.colors import LinearSegmentedColormap

    cmap = LinearSegmentedColormap.from_list(scheme, colormap.scheme(scheme))
    cmap.set_under(colormap.OUT_OF_RANGE_COLORS["below"])
    cmap.set_over(colormap.OUT_OF_RANGE_COLORS["above"])
    cmap.set_bad(colormap.NAN_COLOR)
    return cmap


def _map_kind(x, y):
    """How a map is drawn: ``'points'`` (scattered), ``'grid'`` (nominal x, y) or
    ``'index'`` (grid index, no finite coordinates)."""
    if x.ndim == 1:
        return "points"
    if np.all(np.isfinite(x)) and np.all(np.isfinite(y)) and min(x.shape) > 1:
        return "grid"
    return "index"


def _map_colours(values_um, symmetric, style):
    """The colour keywords of a map and its colorbar's ``extend``."""
    finite = values_um[np.isfinite(values_um)]
    lim = float(np.max(np.abs(finite))) if finite.size else 1.0
    lim = lim or 1.0
    if not symmetric:
        return dict(cmap="viridis"), "neither"
    if style.get("range") is not None:
        lo, hi = (1e3 * float(r) for r in style["range"])
        return dict(vmin=lo, vmax=hi, cmap=_cmap(style["scheme"])), "both"
    return dict(vmin=-lim, vmax=lim, cmap=_cmap(style["scheme"])), "neither"


def _draw_map(ax, kind, x, y, values_um, kw):
    """Draw one map's data on ``ax``; returns (mappable, the artists drawn)."""
    if kind == "points":  # scattered points: Delaunay triangles of the nominal x, y
        mesh = ax.tripcolor(x, y, values_um, shading="gouraud", **kw)
        return mesh, [mesh] + ax.plot(x, y, ".", color="k", markersize=1.5)
    if kind == "grid":
        mesh = ax.pcolormesh(x, y, np.ma.masked_invalid(values_um), shading="gouraud", **kw)
        return mesh, [mesh]
    mesh = ax.imshow(values_um.T, origin="lower", **kw)
    return mesh, [mesh]


def _label_map(ax, kind):
    if kind == "index":
        ax.set_xlabel("grid row")
        ax.set_ylabel("grid column")
    else:
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_aspect("equal", adjustable="box")


class MapPainter:
    """Draws the report's maps one after the other into a fixed-layout figure reused for
    every map of the same kind and colorbar (its axes, ticks and texts made once: creating
    them was a third of a report's render time); :meth:`png` gives each map's PNG as
    :func:`map_figure` would have drawn it."""

    def __init__(self):
        self._figures = {}

    def figure(self, x, y, values_um, title, symmetric=True, style=None):
        """The map in its (reused) figure, ready to encode; valid until the next call."""
        kind = _map_kind(x, y)
        kw, extend = _map_colours(values_um, symmetric, style or DEFAULT_STYLE)
        key = (kind, extend, (style or DEFAULT_STYLE)["scheme"] if symmetric else None)
        entry = self._figures.get(key)
        if entry is None:
            fig = _figure((5.2, 4.2))
            ax = _axes(fig, 0.6, 0.55, 1.05, 0.3)  # placed by _place_map once drawn on
            mesh, artists = _draw_map(ax, kind, x, y, values_um, kw)
            _label_map(ax, kind)
            cb = fig.colorbar(mesh, cax=fig.add_axes((0.8, 0.1, 0.03, 0.8)), extend=extend)
            cb.set_label("µm (along the outward normal)")
            entry = self._figures[key] = {"fig": fig, "ax": ax, "cb": cb}
        else:
            fig, ax, cb = entry["fig"], entry["ax"], entry["cb"]
            for artist in entry["artists"]:
                artist.remove()
            ax.ignore_existing_data_limits = True  # the limits of the new data alone
            mesh, artists = _draw_map(ax, kind, x, y, values_um, kw)
            cb.update_normal(mesh)
        entry["artists"] = artists
        _place_map(fig, ax, cb.ax)
        ax.set_title(title, fontsize=11, y=1.0)  # y given: no search for room above ticks
        return fig

    def png(self, x, y, values_um, title, symmetric=True, style=None):
        """:func:`png` of the map (base64 str)."""
        return png(self.figure(x, y, values_um, title, symmetric, style))


def map_figure(x, y, values_um, title, symmetric=True, fig=None, ax=None, style=None):
    """A colour map of ``values_um`` over the nominal ``x``, ``y`` (mm) with its colorbar:
    (n, m) grids as a Gouraud-shaded mesh, (N,) scattered points on their Delaunay
    triangles, grids without finite coordinates by grid index. In a new fixed-layout figure
    unless ``fig`` and ``ax`` are given (then the colorbar is placed by ``fig``'s layout)."""
    if ax is None:
        return MapPainter().figure(x, y, values_um, title, symmetric, style)
    kind = _map_kind(x, y)
    kw, extend = _map_colours(values_um, symmetric, style or DEFAULT_STYLE)
    mesh, _ = _draw_map(ax, kind, x, y, values_um, kw)
    _label_map(ax, kind)
    cb = fig.colorbar(mesh, ax=ax, shrink=0.85, extend=extend)
    cb.set_label("µm (along the outward normal)")
    ax.set_title(title, fontsize=11)
    return fig


class HistPainter:
    """:func:`hist_figure` drawn one histogram after the other into one reused figure (its
    axes, ticks and labels made once); each as a figure of its own would look."""

    def __init__(self):
        self._fig = self._ax = self._bars = None

    def figure(self, values_um, title, color):
        """The histogram in the (reused) figure, ready to encode; valid until the next call."""
        if self._fig is None:
            self._fig = _figure((5.0, 3.4))
            self._ax = _axes(self._fig, 0.7, 0.5, 0.15, 0.3)
            self._ax.set_xlabel("µm")
            self._ax.set_ylabel("points")
        else:
            self._bars.remove()
            self._ax.ignore_existing_data_limits = True  # the limits of the new bars alone
        ax = self._ax
        v = values_um[np.isfinite(values_um)]
        self._bars = ax.hist(v, bins=min(60, max(10, int(np.sqrt(v.size)))), color=color,
                             edgecolor="white")[2]
        ax.set_title("%s (mean %.2f µm, std %.2f µm)"
                     % (title, v.mean(), v.std(ddof=1) if v.size > 1 else 0.0),
                     fontsize=10, y=1.0)
        return self._fig


def hist_figure(values_um, title, color):
    """The distribution of the finite ``values_um`` with their mean and std in the title."""
    return HistPainter().figure(values_um, title, color)


def bar_chart(sim):
    """Std and ISO 1101 profile error per method of a simulation, mean over the replicas
    with min..max bars."""
    cols = [("Before", sim["before"])] + [(m["label"], m) for m in sim["methods"]]
    fig = _figure((7.5, 3.6))
    axes = [_axes(fig, 0.55, 0.62, 4.0, 0.25), _axes(fig, 4.15, 0.62, 0.35, 0.25)]
    x = np.arange(len(cols))
    for ax, key, title in zip(axes, ("std", "profile"),
                              ("Standard deviation", "Profile error ISO 1101")):
        vals = np.array([[r["all"][key] for r in c["replicas"]] for _, c in cols], dtype=object)
        mean = np.array([np.mean(v) for v in vals]) * 1e3
        lo = mean - np.array([np.min(v) for v in vals]) * 1e3
        hi = np.array([np.max(v) for v in vals]) * 1e3 - mean
        ax.bar(x, mean, yerr=[lo, hi], capsize=4, color="#88aacc")
        ax.set_xticks(x, [h for h, _ in cols], rotation=30, ha="right", fontsize=8)
        ax.set_ylabel("µm")
        ax.set_title(title + " (bars: min..max over replicas)", fontsize=9, y=1.0)
    return fig


def simulation_maps_figure(maps, columns=4, title=None):
    """All :func:`surfcomp.io.html_report.simulation_maps` in one matplotlib Figure
    (``columns`` maps per row), e.g. for the README; each map on its own symmetric scale in
    um."""
    from matplotlib.figure import Figure

    rows = -(-len(maps) // columns)
    fig = Figure(figsize=(4.6 * columns, 3.7 * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, columns)).ravel()
    for ax, m in zip(axes, maps):
        v = np.asarray(m["values"]) * 1e3
        map_figure(np.asarray(m["x"]), np.asarray(m["y"]), v,
                   "%s (std %.2f µm)" % (m["title"], np.std(v, ddof=1)), fig=fig, ax=ax)
    for ax in axes[len(maps):]:
        ax.set_axis_off()
    if title:
        fig.suptitle(title)
    return fig
