# SPDX-License-Identifier: LGPL-2.1-or-later
"""Correction methods: the intended correction at every measured point (no FreeCAD).

The corrected surface is ``S_c(u, v) = S(u, v) - delta(u, v) n(u, v)``: a positive
deviation (material left) moves the surface given to CAM inwards by the same amount.
This module computes ``delta`` at the measured points for each method:

``raw``       Werner 2022 eq. 1-2: ``delta = d``.
``filtered``  Werner 2022 eq. 3-5: ``delta = d_f``, the mask-filtered (determined) component.
``mirror``    Huang et al. (mirror compensation, eq. 1-2): measured after semi-finishing
              with stock ``s``, ``PM = PP + (s/2) VN``, ``DM = (PR - PM).VN = d - s/2``,
              ``PC = PR - 2 DM VN = PP - (d - s) VN``, i.e. ``delta = d - s``.
``offset``    Tool-radius modification (industry baseline in the mirror paper): a uniform
              offset by the mean deviation, ``delta = mean(d)`` everywhere.
"""

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ..choices import METHODS
from .filters import make_mask, mask_filter


@dataclass
class CorrectionResult:
    """Per-node results on the measurement grid (arrays shape (n, m), mm; NaN = not measured).

    ``determined`` is the filtered component ``d_f`` (for every method, so maps and
    reports can show it), ``random`` is ``d - d_f``, ``delta`` the intended correction.
    """

    method: str
    deviation: np.ndarray
    determined: np.ndarray
    random: np.ndarray
    delta: np.ndarray
    mask: np.ndarray
    edge: str
    stock: float = None


def compute_correction(d, method="filtered", mask=None, edge="renormalize", stock=None,
                       determined=None):
    """Intended correction ``delta`` at every grid node for ``method``.

    Parameters
    ----------
    d : array_like, shape (n, m)
        Signed deviations along the outward normal in mm (NaN = not measured).
    method : {'raw', 'filtered', 'mirror', 'offset'}
    mask : array_like, optional
        Filter mask (default: 5x5 box, Werner 2022).
    edge : str
        Edge handling of the filter (see :func:`surfcomp.core.compensation.filters.mask_filter`).
    stock : float, optional
        Semi-finishing allowance in mm; required for ``mirror`` (DH = stock / 2).
    determined : array_like, shape of ``d``, optional
        The determined (systematic) component when it comes from elsewhere (the
        smoothing fit of scattered layouts); then no mask filter is applied and
        ``mask`` is None in the result.

    Returns
    -------
    CorrectionResult
    """
    if method not in METHODS:
        raise InputError("unknown method %r (expected one of %s)" % (method, ", ".join(METHODS)))
    d = np.asarray(d, dtype=float)
    if determined is None:
        mask = make_mask() if mask is None else np.asarray(mask, dtype=float)
        determined = mask_filter(d, mask, edge)
    else:
        determined, mask = np.asarray(determined, dtype=float), None
    if method == "raw":
        delta = d.copy()
    elif method == "filtered":
        delta = determined.copy()
    elif method == "mirror":
        if stock is None:
            raise InputError("the mirror method needs stock, the semi-finishing allowance in mm "
                             "(the mirror surface lies at half of it)", options=("stock",))
        if not np.isfinite(stock) or stock < 0:
            raise InputError("stock must be a finite allowance >= 0 mm, got %r" % (stock,),
                             options=("stock",))
        delta = d - float(stock)
    else:
        delta = np.where(np.isfinite(d), np.nanmean(d), np.nan)
    return CorrectionResult(method=method, deviation=d, determined=determined,
                            random=d - determined, delta=delta, mask=mask, edge=edge,
                            stock=None if stock is None else float(stock))


def predicted_residual(determined, increment, method, stock=None):
    """The predicted residual (mm): what a round's correction leaves of the systematic
    (determined) error when the next part is cut, ``determined - s - increment``, where
    ``s`` is the stock the mirror method's deviations carry (0 for the other methods); the
    next part's own random scatter comes on top.

    Parameters
    ----------
    determined, increment : array_like, same shape
        The determined component ``d_f`` and this round's intended correction (``delta``
        of a single round; the increment of an iteration), mm; NaN where not measured.
    method : str
        One of :data:`~surfcomp.core.choices.METHODS`.
    stock : float, optional
        The mirror method's semi-finishing allowance (mm).

    Returns
    -------
    ndarray
        Zero for ``filtered``, ``-random`` for ``raw`` and ``mirror`` (they copy this
        part's random scatter into the face), ``determined - mean`` for ``offset``.
    """
    s = float(stock or 0.0) if method == "mirror" else 0.0
    return np.asarray(determined, dtype=float) - s - np.asarray(increment, dtype=float)
