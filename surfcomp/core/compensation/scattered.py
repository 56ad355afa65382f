# SPDX-License-Identifier: LGPL-2.1-or-later
"""Deviation fields from scattered (non-grid) points over the face's (u, v) (no FreeCAD).

The scattered counterparts of the grid path's mask filter and correction field, in two
modules by job and re-exported here:

:mod:`surfcomp.core.compensation.scattered_fit`
    :func:`smooth` (:class:`SmoothFit`): the smoothing fit that splits deviations into a
    determined and a random component (thin-plate smoothing spline, P-spline
    (:mod:`surfcomp.core.compensation.pspline`), GCV, leave-one-out residuals).
:mod:`surfcomp.core.compensation.scattered_field`
    :class:`ScatteredField`: the Clough-Tocher C1 field through the corrections.
"""

from .pspline import LOO_SAMPLE, PSPLINE_MAX_COEFFS
from .scattered_field import FRAME_MARGIN, GHOST_NEIGHBOURS, GRADIENT_RTOL, ScatteredField
from .scattered_fit import (
    EXACT_MAX,
    LOG_ELL_RANGE,
    SmoothFit,
    loo_residuals,
    smooth,
    tps_smoothing_parameter,
)

__all__ = ["smooth", "SmoothFit", "loo_residuals", "tps_smoothing_parameter", "ScatteredField",
           "EXACT_MAX", "PSPLINE_MAX_COEFFS", "LOO_SAMPLE", "LOG_ELL_RANGE", "FRAME_MARGIN",
           "GHOST_NEIGHBOURS", "GRADIENT_RTOL"]
