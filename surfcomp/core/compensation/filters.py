# SPDX-License-Identifier: LGPL-2.1-or-later
"""Image-style mask filters on the n x m deviation grid (Werner 2022, eq. 3-5).

The filtered value at node (i, j) is the weighted sum of the deviations in the
mask window (eq. 4), divided by the sum of the weights (eq. 5). Werner divides by
the sum of *all* weights; at the grid border and at gaps (unmeasured nodes, NaN)
part of the window falls on no measured point, so we divide by the sum of the
weights that fall on measured points ("normalised convolution"). Inside the grid
this is exactly eq. 5; at the border it is eq. 5 applied to the part of the mask
that lies on the grid. A constant field therefore passes unchanged everywhere.

Mask orientation: ``mask[a, b]`` weights the node ``(i + a - r, j + b - r)``
(correlation, as eq. 4 is written), the first grid index being the row.
"""

import re

import numpy as np

from ...errors import InputError
from ..choices import EDGE_MODES, MASK_KINDS
from ..limits import MAX_MASK_SIZE
from ..options import OPTIONS

#: Werner 2022's mask: 5 x 5 box (the default everywhere, from the option registry)
WERNER_MASK_SIZE = OPTIONS["mask_size"].default


def box_mask(size):
    """The ``size`` x ``size`` box mask with all weights 1 (Werner's 5x5 choice)."""
    _check_size(size)
    return np.ones((size, size))


def gaussian_mask(size, sigma=None):
    """A ``size`` x ``size`` Gaussian mask, ``sigma`` in grid steps (default ``size / 4``)."""
    _check_size(size)
    sigma = float(size) / 4.0 if sigma is None else float(sigma)
    if not 0 < sigma <= MAX_MASK_SIZE:
        raise InputError("Gaussian sigma must be > 0 and at most %d grid steps, got %g"
                         % (MAX_MASK_SIZE, sigma))
    r = size // 2
    x = np.arange(-r, r + 1, dtype=float)
    g = np.exp(-0.5 * (x / sigma) ** 2)
    return np.outer(g, g)


def parse_weights(text):
    """Parse a custom mask from text: rows separated by ``;`` or newlines.

    ``"1 2 1; 2 4 2; 1 2 1"`` -> a 3x3 array. Numbers may be separated by spaces
    or commas. The mask must be square with an odd size and a non-zero sum.
    """
    rows = [r for r in re.split(r"[;\n]", str(text).strip()) if r.strip()]
    if not rows:
        raise InputError("empty mask weights %r (expected rows like '1 2 1; 2 4 2; 1 2 1')" % text)
    values = []
    for k, row in enumerate(rows, 1):
        try:
            values.append([float(x) for x in re.split(r"[\s,]+", row.strip())])
        except ValueError:
            raise InputError("mask weights row %d %r is not a list of numbers "
                             "(expected rows like '1 2 1; 2 4 2; 1 2 1')"
                             % (k, row.strip())) from None
    n = len(values)
    if any(len(r) != n for r in values):
        raise InputError("mask weights %r are not square: %d rows of lengths %s (expected "
                         "n rows of n numbers, n odd)" % (text, n, [len(r) for r in values]))
    mask = np.array(values)
    check_mask(mask)
    return mask


def _whole(x):
    return isinstance(x, (int, np.integer)) or (isinstance(x, float) and x.is_integer())


def _check_size(size):
    if not _whole(size) or not 1 <= size <= MAX_MASK_SIZE or size % 2 == 0:
        raise InputError("mask_size %r: expected an odd whole number from 1 to %d (3, 5, 7, "
                         "...)" % (size, MAX_MASK_SIZE), options=("mask_size",))


def check_mask(mask):
    """Refuse masks that eq. 5 cannot use: even-sized, non-square, non-finite or zero-sum."""
    mask = np.asarray(mask, dtype=float)
    if mask.ndim != 2 or mask.shape[0] != mask.shape[1]:
        raise InputError("mask must be square, got shape %r" % (mask.shape,))
    _check_size(mask.shape[0])
    if not np.all(np.isfinite(mask)):
        raise InputError("mask weights must be finite numbers")
    if abs(mask.sum()) <= 1e-12 * max(1.0, np.abs(mask).sum()):
        raise InputError("mask weights sum to zero: eq. 5 of Werner 2022 divides by this sum "
                         "(expected a mask with a non-zero sum)")
    return mask


def make_mask(size=WERNER_MASK_SIZE, weights=None, kind="box", sigma=None):
    """Build the filter mask from user options (box by default, 5x5 as in Werner 2022).

    Parameters
    ----------
    size : int
        Odd mask size; ignored when ``weights`` are given.
    weights : str or array_like, optional
        Custom weights (text as for :func:`parse_weights`, or an array).
    kind : {'box', 'gaussian'}
    sigma : float, optional
        Gaussian sigma in grid steps.
    """
    if weights is not None:
        return parse_weights(weights) if isinstance(weights, str) else check_mask(weights)
    if kind == "box":
        return box_mask(size)
    if kind == "gaussian":
        return gaussian_mask(size, sigma)
    raise InputError("unknown mask kind %r (expected %s)" % (kind, " or ".join(MASK_KINDS)))


def mask_filter(d, mask, edge="renormalize"):
    """Determined (filtered) component of a deviation grid (Werner 2022, eq. 4-5).

    Parameters
    ----------
    d : array_like, shape (n, m)
        Deviations on the measurement grid in mm; NaN marks unmeasured nodes.
    mask : array_like, shape (k, k)
        Odd-sized weights with a non-zero sum.
    edge : {'renormalize', 'reflect', 'nearest'}
        How the window is completed beyond the grid border (see module docstring).
        Gaps (NaN) are always handled by renormalisation.

    Returns
    -------
    ndarray, shape (n, m)
        ``d_f``; NaN where ``d`` is NaN. The random component is ``d - d_f``
        (Werner Fig. 10b).

    Raises
    ------
    InputError
        When at some node the weights falling on measured points sum to zero
        (possible only with negative weights), naming the node.
    """
    mask = check_mask(mask)
    d = np.asarray(d, dtype=float)
    if edge not in EDGE_MODES:
        raise InputError("unknown edge handling %r (expected one of %s)"
                         % (edge, ", ".join(EDGE_MODES)))
    valid = np.isfinite(d)
    values = np.where(valid, d, 0.0)
    num = correlate(values, mask, edge)
    den = correlate(valid.astype(float), mask, edge)
    tiny = 1e-9 * np.abs(mask).sum()
    bad = valid & (np.abs(den) <= tiny)
    if np.any(bad):
        i, j = np.argwhere(bad)[0]
        raise InputError("the mask weights falling on measured points sum to zero at grid node "
                         "(row %d, col %d): eq. 5 cannot normalise there (expected weights "
                         "whose partial sums are non-zero, e.g. all weights >= 0)" % (i, j))
    out = np.full(d.shape, np.nan)
    out[valid] = num[valid] / den[valid]
    return out


#: masks up to this size are applied by :func:`correlate`'s shifted sums; larger ones by
#: ``scipy.ndimage.correlate`` (imported only then: its import would cost every start,
#: docs/benchmarks.md, "Costs behind choices in the code")
SHIFTED_MAX = 11
#: numpy.pad's name of each edge mode
_PAD = {"renormalize": "constant", "reflect": "reflect", "nearest": "edge"}


def correlate(values, mask, edge):
    """``scipy.ndimage.correlate(values, mask)`` with the window completed beyond the grid
    as ``edge`` says (``renormalize``: zeros, ``reflect``: mirrored without repeating the
    border node, ``nearest``: the border node). Masks up to :data:`SHIFTED_MAX` are summed
    shift by shift in ndimage's order (the same numbers to the last bit:
    tests/pure/test_filter_shifts.py)."""
    k = mask.shape[0]
    if k > SHIFTED_MAX:
        from scipy import ndimage

        # ndimage's names: its 'reflect' repeats the border node, its 'mirror' is our
        # 'reflect'
        mode = {"renormalize": "constant", "reflect": "mirror", "nearest": "nearest"}[edge]
        return ndimage.correlate(values, mask, mode=mode, cval=0.0)
    r = k // 2
    padded = np.pad(values, r, mode=_PAD[edge])
    n, m = values.shape
    out = np.zeros(values.shape)
    for a in range(k):
        for b in range(k):
            out += mask[a, b] * padded[a:a + n, b:b + m]
    return out
