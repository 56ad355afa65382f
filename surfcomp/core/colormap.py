# SPDX-License-Identifier: LGPL-2.1-or-later
"""Colour mapping of deviation values for the GUI's maps (numpy only, no FreeCAD, no Qt).

The GUI draws a value field (mm) on a face; everything numeric about that drawing
lives here: value -> RGB with a colour scheme, the tolerance-band colouring used by
inspection software, the symmetric default range, the legend's levels and labels,
the positions of the extreme values and the (u, v) grid tessellation of a face.

Colours are floats in [0, 1], arrays of shape (N, 3).
"""

import numpy as np

from ..errors import lookup
from .surface.bspline import evaluate_grid

#: colour schemes: control colours at equally spaced positions from the range's low
#: end (first row) to its high end (last row), interpolated linearly in RGB
SCHEMES = {
    # inspection-software rainbow: blue (below) - cyan - green (zero) - yellow - red (above)
    "rainbow": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [0.0, 1.0, 0.0],
                         [1.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
    # diverging: blue - white (zero) - red, readable for small deviations around zero
    "blue-white-red": np.array([[0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 0.0]]),
    # perceptually ordered (viridis samples at 0, 0.25, 0.5, 0.75, 1)
    "viridis": np.array([[0.267, 0.005, 0.329], [0.229, 0.322, 0.546], [0.128, 0.567, 0.551],
                         [0.369, 0.789, 0.383], [0.993, 0.906, 0.144]]),
}
DEFAULT_SCHEME = "rainbow"

#: tolerance-band colours: below the band, inside, above
TOLERANCE_COLORS = {"below": (0.0, 0.0, 1.0), "inside": (0.0, 0.8, 0.0), "above": (1.0, 0.0, 0.0)}

#: warning band colour (inside the tolerance, beyond the warning limit)
WARNING_COLOR = (1.0, 0.85, 0.0)

#: colour of values that are not a number (unmeasured nodes)
NAN_COLOR = (0.5, 0.5, 0.5)

#: colours of values outside a manual range (``out_of_range=True``): dark grey below,
#: light grey above, so a saturated map never passes for an end colour of the scheme
OUT_OF_RANGE_COLORS = {"below": (0.25, 0.25, 0.25), "above": (0.75, 0.75, 0.75)}

#: display units of the legend and labels: name -> factor from mm, number format
UNITS = {"mm": (1.0, "%+.4f"), "um": (1000.0, "%+.1f")}
#: how a unit is written
UNIT_TEXT = {"mm": "mm", "um": "\u00b5m"}

#: the smallest half range of an automatic range (mm), for an all-zero field
MIN_HALF_RANGE = 1e-6


def scheme(name):
    """Control colours (K, 3) of the scheme ``name`` (one of :data:`SCHEMES`)."""
    return lookup(SCHEMES, name, "colour scheme")


def symmetric_range(values):
    """The default range ``(-a, a)`` with ``a`` the largest absolute finite value (mm).

    Zero deviation stays green in the rainbow scheme and white in the diverging one.
    NaN values are ignored; an all-zero or all-NaN field gives ``a =`` :data:`MIN_HALF_RANGE`.
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    a = float(np.max(np.abs(v))) if v.size else 0.0
    a = max(a, MIN_HALF_RANGE)
    return -a, a


def map_colors(values, vmin, vmax, scheme_name=DEFAULT_SCHEME, levels=None,
               out_of_range=False):
    """RGB colours of ``values`` on the scheme spread linearly over ``[vmin, vmax]``.

    Parameters
    ----------
    values : array_like, shape (N,)
        Values (mm); NaN gives :data:`NAN_COLOR`.
    vmin, vmax : float
        Range (mm), ``vmin < vmax``.
    scheme_name : str
    levels : int, optional
        Stepped colours: the range split into ``levels`` equal steps, each drawn in the
        colour of its middle (as the stepped legend shows them); a value on the edge of two
        steps in the colour of the upper one.
    out_of_range : bool
        Values below ``vmin`` / above ``vmax`` take :data:`OUT_OF_RANGE_COLORS`; else the
        end colours of the scheme.

    Returns
    -------
    ndarray, shape (N, 3), floats in [0, 1]
    """
    if not vmax > vmin:
        raise ValueError("colour range needs vmin < vmax, got %r .. %r" % (vmin, vmax))
    ctrl = scheme(scheme_name)
    v = np.asarray(values, dtype=float).ravel()
    f = np.clip((v - vmin) / (vmax - vmin), 0.0, 1.0)
    if levels:
        # a value on a step's edge (a label of the legend) takes the step above it, the top
        # end the top step's: its position in steps is rounded off first, as (v - vmin) /
        # (vmax - vmin) of a round value lands a rounding error either side of the edge
        # (-0.01 of -0.05 .. 0.05 at 1.9999999999999996, +0.01 at 6.000000000000001)
        step = f * levels
        near = np.round(step)
        step = np.where(np.abs(step - near) < 1e-9, near, step)
        f = (np.minimum(np.floor(step), levels - 1) + 0.5) / levels
    pos = np.linspace(0.0, 1.0, len(ctrl))
    fin = np.isfinite(f)
    out = np.empty((v.size, 3))
    for c in range(3):
        out[:, c] = np.interp(np.where(fin, f, 0.0), pos, ctrl[:, c])
    if out_of_range:
        eps = 1e-9 * (vmax - vmin)
        with np.errstate(invalid="ignore"):
            out[v < vmin - eps] = OUT_OF_RANGE_COLORS["below"]
            out[v > vmax + eps] = OUT_OF_RANGE_COLORS["above"]
    out[~fin] = NAN_COLOR
    return out


def warning_limits(lower, upper, warning):
    """The warning limits inside a tolerance band: ``warning`` (0 .. 1) of each half of
    the band from its centre (0.8: the outer 20 % of the tolerance warn)."""
    mid = 0.5 * (lower + upper)
    return mid + warning * (lower - mid), mid + warning * (upper - mid)


def tolerance_colors(values, lower, upper, colors=None, warning=None):
    """Tolerance-band colouring: ``lower <= v <= upper`` inside, else below/above.

    Parameters
    ----------
    values : array_like, shape (N,)
        Values (mm); NaN gives :data:`NAN_COLOR`.
    lower, upper : float
        Band limits (mm), ``lower <= upper`` (e.g. -0.01, +0.01).
    colors : dict, optional
        ``below``/``inside``/``above``/``warning`` -> RGB (default :data:`TOLERANCE_COLORS`,
        :data:`WARNING_COLOR`).
    warning : float, optional
        Warning band (see :func:`warning_limits`): values inside the band but beyond the
        warning limits take the warning colour.

    Returns
    -------
    ndarray, shape (N, 3)
    """
    if lower > upper:
        raise ValueError("tolerance band needs lower <= upper, got %r .. %r" % (lower, upper))
    cols = dict(TOLERANCE_COLORS, warning=WARNING_COLOR, **(colors or {}))
    v = np.asarray(values, dtype=float).ravel()
    out = np.empty((v.size, 3))
    out[:] = cols["inside"]
    with np.errstate(invalid="ignore"):
        if warning is not None:
            w_lo, w_hi = warning_limits(lower, upper, warning)
            out[(v < w_lo) | (v > w_hi)] = cols["warning"]
        out[v < lower] = cols["below"]
        out[v > upper] = cols["above"]
    out[~np.isfinite(v)] = NAN_COLOR
    return out


def band_fractions(values, lower, upper, warning=None):
    """Percent of the finite ``values`` below, inside and above a band (and, with a
    ``warning`` band, inside it but beyond the warning limits).

    Returns
    -------
    dict
        ``below``, ``inside``, ``above`` (and ``warning``, part of ``inside``), in %;
        all 0 without a finite value.
    """
    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    n = max(v.size, 1)
    out = {"below": 100.0 * np.count_nonzero(v < lower) / n,
           "above": 100.0 * np.count_nonzero(v > upper) / n}
    out["inside"] = 100.0 * np.count_nonzero((v >= lower) & (v <= upper)) / n
    if warning is not None:
        w_lo, w_hi = warning_limits(lower, upper, warning)
        out["warning"] = 100.0 * np.count_nonzero(((v >= lower) & (v < w_lo)) |
                                                  ((v <= upper) & (v > w_hi))) / n
    return {k: float(x) for k, x in out.items()}


def histogram(values, vmin, vmax, bins=20, scheme_name=DEFAULT_SCHEME, tolerance=None,
              warning=None, levels=None):
    """Histogram of ``values`` over ``[vmin, vmax]`` coloured like the map's legend.

    Values outside the range are counted in ``below``/``above``, not in the bins. With
    stepped colours (``levels``) the number of bins is the multiple of ``levels`` nearest
    ``bins``, so each bin lies in one step.

    Returns
    -------
    dict
        ``edges`` (bins + 1,), ``counts`` (bins,), ``colors`` (bins, 3) (colour of each
        bin's centre), ``below``, ``above`` (counts outside), ``total`` finite values.
    """
    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    if levels and tolerance is None:
        # whole bins per step: a bin across a step's edge would count values of two colours
        # under the colour of its centre
        bins = levels * max(1, int(round(bins / levels)))
    edges = np.linspace(vmin, vmax, int(bins) + 1)
    counts, _ = np.histogram(v[(v >= vmin) & (v <= vmax)], bins=edges)
    mid = 0.5 * (edges[:-1] + edges[1:])
    if tolerance is not None:
        colors = tolerance_colors(mid, tolerance[0], tolerance[1], warning=warning)
    else:
        colors = map_colors(mid, vmin, vmax, scheme_name, levels=levels)
    return {"edges": edges, "counts": counts, "colors": colors,
            "below": int(np.count_nonzero(v < vmin)), "above": int(np.count_nonzero(v > vmax)),
            "total": int(v.size)}


def format_value(value, unit="mm"):
    """Text of a value (mm) in the display unit: ``'+0.0450 mm'``, ``'-12.3 µm'``, ``'0.0 µm'``
    (``unit`` ``'um'`` is written ``µm``)."""
    if unit not in UNITS:
        raise ValueError("unknown display unit %r (expected one of %s)" % (unit, ", ".join(UNITS)))
    factor, fmt = UNITS[unit]
    text = fmt % (value * factor)
    if float(text) == 0.0:
        text = (fmt % 0.0).lstrip("+")
    return text + " " + UNIT_TEXT[unit]


def legend(vmin, vmax, scheme_name=DEFAULT_SCHEME, unit="mm", levels=10, tolerance=None,
           stepped=False, warning=None):
    """What a colour bar shows, from bottom (low values) to top.

    Parameters
    ----------
    vmin, vmax : float
        Colour range (mm).
    scheme_name : str
    unit : {'mm', 'um'}
    levels : int
        Number of intervals of the bar (``levels + 1`` labels).
    tolerance : (float, float), optional
        Tolerance band ``(lower, upper)`` (mm): the bar then has three blocks (below,
        inside, above) labelled at the band limits and the range ends.
    stepped : bool
        One flat colour per interval (as :func:`map_colors` with ``levels``).
    warning : float, optional
        Warning band of the tolerance mode (:func:`warning_limits`): two more blocks.

    Returns
    -------
    dict
        ``stops``: list of ``(fraction, rgb)`` with fraction in [0, 1] along the bar
        (consecutive equal fractions make sharp edges); ``labels``: list of
        ``(fraction, text)``; ``blocks``: ``(name, f0, f1)`` of the tolerance mode's blocks.
    """
    if not vmax > vmin:
        raise ValueError("colour range needs vmin < vmax, got %r .. %r" % (vmin, vmax))

    def frac(x):
        return float(np.clip((x - vmin) / (vmax - vmin), 0.0, 1.0))

    if tolerance is not None:
        lo, hi = tolerance
        cols = dict(TOLERANCE_COLORS, warning=WARNING_COLOR)
        bounds = [("below", 0.0, frac(lo))]
        if warning is not None:
            w_lo, w_hi = warning_limits(lo, hi, warning)
            bounds += [("warning", frac(lo), frac(w_lo)), ("inside", frac(w_lo), frac(w_hi)),
                       ("warning", frac(w_hi), frac(hi))]
        else:
            bounds.append(("inside", frac(lo), frac(hi)))
        bounds.append(("above", frac(hi), 1.0))
        stops = []
        for name, f0, f1 in bounds:
            stops += [(f0, cols[name]), (f1, cols[name])]
        labels = [(0.0, format_value(vmin, unit)), (frac(lo), format_value(lo, unit)),
                  (frac(hi), format_value(hi, unit)), (1.0, format_value(vmax, unit))]
        return {"stops": [(f, tuple(map(float, c))) for f, c in stops], "labels": labels,
                "blocks": bounds}
    fr = np.linspace(0.0, 1.0, levels + 1)
    values = vmin + fr * (vmax - vmin)
    labels = [(float(f), format_value(v, unit)) for f, v in zip(fr, values)]
    if stepped:
        cols = map_colors(vmin + 0.5 * (fr[:-1] + fr[1:]) * (vmax - vmin), vmin, vmax,
                          scheme_name)
        stops = []
        for f0, f1, c in zip(fr[:-1], fr[1:], cols):
            stops += [(float(f0), tuple(map(float, c))), (float(f1), tuple(map(float, c)))]
        return {"stops": stops, "labels": labels, "blocks": []}
    # fine colour stops so the bar shows the scheme's interpolation exactly
    ctrl_fr = np.linspace(0.0, 1.0, len(scheme(scheme_name)))
    stop_fr = np.union1d(fr, ctrl_fr)
    cols = map_colors(vmin + stop_fr * (vmax - vmin), vmin, vmax, scheme_name)
    return {"stops": [(float(f), tuple(map(float, c))) for f, c in zip(stop_fr, cols)],
            "labels": labels, "blocks": []}


def extremes(values):
    """Indices of the largest positive and the largest negative finite value.

    Returns
    -------
    (int or None, int or None)
        ``None`` where there is no positive (resp. negative) value.
    """
    v = np.asarray(values, dtype=float).ravel()
    fin = np.isfinite(v)
    i_max = i_min = None
    if np.any(fin & (v > 0)):
        i_max = int(np.nanargmax(np.where(fin, v, -np.inf)))
    if np.any(fin & (v < 0)):
        i_min = int(np.nanargmin(np.where(fin, v, np.inf)))
    return i_max, i_min


def mesh_resolution(grid_shape=None, low=80, high=240):
    """Samples per parameter direction of the map mesh: twice the measurement grid
    (so the field's shape between nodes shows), at least ``low``, at most ``high``."""
    if grid_shape is None:
        return low, low
    return tuple(int(np.clip(2 * int(k), low, high)) for k in grid_shape)


def uv_grid_mesh(surface, samples=(80, 80)):
    """Triangle mesh of a face on a regular grid of its (u, v) parameter range.

    Parameters
    ----------
    surface : surfcomp.core.surface.bspline.Surface
        The face's surface; its ``u_range``/``v_range`` are the face's bounds (the
        mesh ignores trimming curves inside them).
    samples : (int, int)
        Grid points along u and v (each >= 2).

    Returns
    -------
    points : ndarray, shape (Mu * Mv, 3)
        Mesh vertices (mm), row-major over (u, v).
    triangles : ndarray of int32, shape (2 (Mu - 1)(Mv - 1), 3)
        Vertex indices, counter-clockwise seen from the Su x Sv side.
    u, v : ndarray, shape (Mu * Mv,)
        Face parameters of the vertices.
    """
    mu, mv = int(samples[0]), int(samples[1])
    if mu < 2 or mv < 2:
        raise ValueError("a mesh needs at least 2 x 2 samples, got %r" % (samples,))
    us = np.linspace(surface.u_range[0], surface.u_range[1], mu)
    vs = np.linspace(surface.v_range[0], surface.v_range[1], mv)
    pts = evaluate_grid(surface, us, vs).reshape(-1, 3)
    idx = np.arange(mu * mv, dtype=np.int32).reshape(mu, mv)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    tri = np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])
    U, V = np.meshgrid(us, vs, indexing="ij")
    return pts, tri, U.ravel(), V.ravel()
