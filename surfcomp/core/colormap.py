"""Colour mapping of deviation values for the GUI's maps (numpy only, no FreeCAD, no Qt).

The GUI draws a value field (mm) on a face; everything numeric about that drawing
lives here: value -> RGB with a colour scheme, the tolerance-band colouring used by
inspection software, the symmetric default range, the legend's levels and labels,
the positions of the extreme values and the (u, v) grid tessellation of a face.

Colours are floats in [0, 1], arrays of shape (N, 3).
"""

import numpy as np

from .bspline import evaluate_grid

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

#: colour of values that are not a number (unmeasured nodes)
NAN_COLOR = (0.5, 0.5, 0.5)

#: display units of the legend and labels: name -> factor from mm, number format
UNITS = {"mm": (1.0, "%+.4f"), "um": (1000.0, "%+.1f")}

#: the smallest half range of an automatic range (mm), for an all-zero field
MIN_HALF_RANGE = 1e-6


def scheme(name):
    """Control colours (K, 3) of the scheme ``name`` (one of :data:`SCHEMES`)."""
    try:
        return SCHEMES[name]
    except KeyError:
        raise ValueError("unknown colour scheme %r (expected one of %s)"
                         % (name, ", ".join(SCHEMES))) from None


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


def map_colors(values, vmin, vmax, scheme_name=DEFAULT_SCHEME):
    """RGB colours of ``values`` on the scheme spread linearly over ``[vmin, vmax]``.

    Parameters
    ----------
    values : array_like, shape (N,)
        Values (mm); NaN gives :data:`NAN_COLOR`; values outside the range take the end
        colours.
    vmin, vmax : float
        Range (mm), ``vmin < vmax``.
    scheme_name : str

    Returns
    -------
    ndarray, shape (N, 3), floats in [0, 1]
    """
    if not vmax > vmin:
        raise ValueError("colour range needs vmin < vmax, got %r .. %r" % (vmin, vmax))
    ctrl = scheme(scheme_name)
    v = np.asarray(values, dtype=float).ravel()
    f = np.clip((v - vmin) / (vmax - vmin), 0.0, 1.0)
    pos = np.linspace(0.0, 1.0, len(ctrl))
    fin = np.isfinite(f)
    out = np.empty((v.size, 3))
    for c in range(3):
        out[:, c] = np.interp(np.where(fin, f, 0.0), pos, ctrl[:, c])
    out[~fin] = NAN_COLOR
    return out


def tolerance_colors(values, lower, upper, colors=None):
    """Tolerance-band colouring: ``lower <= v <= upper`` inside, else below/above.

    Parameters
    ----------
    values : array_like, shape (N,)
        Values (mm); NaN gives :data:`NAN_COLOR`.
    lower, upper : float
        Band limits (mm), ``lower <= upper`` (e.g. -0.01, +0.01).
    colors : dict, optional
        ``below``/``inside``/``above`` -> RGB (default :data:`TOLERANCE_COLORS`).

    Returns
    -------
    ndarray, shape (N, 3)
    """
    if lower > upper:
        raise ValueError("tolerance band needs lower <= upper, got %r .. %r" % (lower, upper))
    cols = dict(TOLERANCE_COLORS, **(colors or {}))
    v = np.asarray(values, dtype=float).ravel()
    out = np.empty((v.size, 3))
    out[:] = cols["inside"]
    out[v < lower] = cols["below"]
    out[v > upper] = cols["above"]
    out[~np.isfinite(v)] = NAN_COLOR
    return out


def format_value(value, unit="mm"):
    """Text of a value (mm) in the display unit: ``'+0.0450 mm'``, ``'-12.3 um'``, ``'0.0 um'``."""
    if unit not in UNITS:
        raise ValueError("unknown display unit %r (expected one of %s)" % (unit, ", ".join(UNITS)))
    factor, fmt = UNITS[unit]
    text = fmt % (value * factor)
    if float(text) == 0.0:
        text = (fmt % 0.0).lstrip("+")
    return text + " " + unit


def legend(vmin, vmax, scheme_name=DEFAULT_SCHEME, unit="mm", levels=10, tolerance=None):
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

    Returns
    -------
    dict
        ``stops``: list of ``(fraction, rgb)`` with fraction in [0, 1] along the bar
        (consecutive equal fractions make sharp edges); ``labels``: list of
        ``(fraction, text)``.
    """
    if not vmax > vmin:
        raise ValueError("colour range needs vmin < vmax, got %r .. %r" % (vmin, vmax))
    if tolerance is not None:
        lo, hi = tolerance
        cols = TOLERANCE_COLORS
        f_lo = float(np.clip((lo - vmin) / (vmax - vmin), 0.0, 1.0))
        f_hi = float(np.clip((hi - vmin) / (vmax - vmin), 0.0, 1.0))
        stops = [(0.0, cols["below"]), (f_lo, cols["below"]), (f_lo, cols["inside"]),
                 (f_hi, cols["inside"]), (f_hi, cols["above"]), (1.0, cols["above"])]
        labels = [(0.0, format_value(vmin, unit)), (f_lo, format_value(lo, unit)),
                  (f_hi, format_value(hi, unit)), (1.0, format_value(vmax, unit))]
        return {"stops": [(f, tuple(map(float, c))) for f, c in stops], "labels": labels}
    fr = np.linspace(0.0, 1.0, levels + 1)
    values = vmin + fr * (vmax - vmin)
    # fine colour stops so the bar shows the scheme's interpolation exactly
    ctrl_fr = np.linspace(0.0, 1.0, len(scheme(scheme_name)))
    stop_fr = np.union1d(fr, ctrl_fr)
    cols = map_colors(vmin + stop_fr * (vmax - vmin), vmin, vmax, scheme_name)
    return {"stops": [(float(f), tuple(map(float, c))) for f, c in zip(stop_fr, cols)],
            "labels": [(float(f), format_value(v, unit)) for f, v in zip(fr, values)]}


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
    surface : surfcomp.core.bspline.Surface
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
