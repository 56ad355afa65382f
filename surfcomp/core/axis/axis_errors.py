# SPDX-License-Identifier: LGPL-2.1-or-later
"""Geometric error model of a 3-axis machine and its compensation (Dobariya et al. 2015).

The model (Dobariya 2015, eq. 6-16)
-----------------------------------
Each slide ``a`` in ``x, y, z`` moves the tool by its travel ``t_a = X_a - r_a`` from a
reference point ``r`` (default the program zero) and carries three 1-D error functions,
``delta_i(a)`` = the tool-position error along ``i`` caused by slide ``a`` (``i`` in
``x, y, z``): nine functions, each linear or quadratic in ``t_a`` and zero at ``t_a = 0``:

- ``delta_a(a)`` positional error of slide ``a`` (eq. 6: ``delta_x(x) = delta_x1(x) +
  delta_x2(x)``, scale error plus ball-screw positional error; the linear coefficient is
  reported as the scale error, the quadratic one as the non-linear positional error);
- ``delta_i(a) = delta'_i(a) + alpha_ai * t_a`` for ``i != a`` (eq. 7-8): straightness
  ``delta'_y(x), delta'_x(y), delta'_x(z)`` and flatness ``delta'_z(x), delta'_z(y),
  delta'_y(z)`` (the quadratic coefficients; a straightness error's linear part cannot be
  told apart from an angle), and the slope ``alpha_ai`` of the cross-axis error.

The three squareness errors are ``alpha_xy + alpha_yx``, ``alpha_xz + alpha_zx`` and
``alpha_yz + alpha_zy`` (the angle between two slides minus 90 degrees); what is left of
the six slopes is a rigid rotation of the measuring frame. The composition keeps all six
slopes as measured, so a measured frame rotation is compensated too. Together: 3 positional
(scale) + 3 straightness + 3 flatness + 3 squareness = the paper's 12 components.

The tool-position error at a commanded point ``X`` is eq. 14,

    E_i(X) = e0_i + delta_i(x) + delta_i(y) + delta_i(z),    i = x, y, z,

with ``e0`` the error at the reference point (zero when the measurements are zeroed there).

Sign convention: an error is **actual minus commanded** (the tool lands at ``X + E(X)``);
Dobariya's eq. 1 defines ``E_p = P - P_a``, the opposite sign. Compensation (the issue's
refinement of the paper's ``X' = X - E(X)``) solves ``X' + E(X') = X`` for the command
``X'`` so that the tool lands on the programmed ``X``: Newton's method with the model's
analytic Jacobian, vectorised over all points.

Fitting
-------
Per axis, the measured rows (``position``, ``ex, ey, ez`` with the other slides at the
reference) are fitted by least squares as polynomials in ``t`` of degree 1 or 2, one degree
per component. ``model='linear'`` or ``'quadratic'`` fixes it; ``'auto'`` takes the
quadratic only when the partial F-test of the quadratic term is significant at
``alpha = 0.05`` (``F = (RSS_1 - RSS_2) / (RSS_2 / (n - 3))`` against ``F(1, n - 3)``), which
needs ``n >= 4`` positions (with fewer, linear). A component fitted by a straight line
within 1 nm RMS is linear. The value of each axis' fit at the reference is that axis'
estimate of ``e0``; ``e0`` is their mean and the spread between axes is reported.

Everything is in mm (angles and slopes in mm/mm = rad, quadratic terms in 1/mm).
"""

from dataclasses import dataclass

import numpy as np
from scipy import stats

from ...errors import ComputationError, InputError
from ..choices import AXIS_MODELS
from .axes import AXES, as_points, axis_index
from .machine import SimulatedMachine  # noqa: F401 (its home before core/axis/machine.py)

#: fit choices of :func:`fit_axis_errors`
MODEL_CHOICES = AXIS_MODELS
#: significance level of the F-test of ``model='auto'``
F_TEST_ALPHA = 0.05
#: a component whose straight-line fit has an RMS residual below this (mm) stays linear
EXACT_RMS = 1e-9
#: Newton tolerance (mm) of :meth:`AxisErrorModel.compensate`
COMPENSATE_TOL = 1e-10
#: largest position, error or reference coordinate (mm) the fit takes: 1 km, beyond any
#: machine (as G-code positions); the squares of larger values overflow in the fit
MAX_VALUE = 1e6


def _finite_points(values, message, points=None):
    """Raise InputError when a row of ``values`` (n, 3) is not finite; ``message`` gets
    the count and the first such row of ``points`` (default ``values``)."""
    ok = np.isfinite(values).all(axis=1)
    if ok.all():
        return
    bad = np.flatnonzero(~ok)
    at = (values if points is None else points)[bad[0]]
    raise InputError(message % ((bad.size,) + tuple(at)))


@dataclass
class ComponentFit:
    """The least-squares fit of one error function ``delta_i(a)``.

    Attributes
    ----------
    axis, component : str
        Moving slide ``a`` and error direction ``i`` (``'x'``, ``'y'``, ``'z'``).
    degree : int
        1 or 2.
    coefficients : ndarray (3,)
        ``b0, b1, b2`` of ``b0 + b1 t + b2 t**2`` with ``t = position - reference`` (mm,
        mm/mm, 1/mm); ``b2 = 0`` for degree 1. ``b0`` is this axis' estimate of ``e0``.
    positions, values, residuals : ndarray (n,)
        Measured positions (mm), measured errors (mm), measured minus fitted (mm).
    rss, rms, max_abs : float
        Residual sum of squares (mm^2), RMS and largest absolute residual (mm).
    r2_adjusted : float
        Adjusted coefficient of determination; NaN when undefined (n <= degree + 1, or a
        constant measured error).
    rule : str
        How the degree was chosen: ``'given'``, ``'F-test'``, ``'exact line'``, ``'n < 4'``.
    f_statistic, p_value : float
        Partial F-test of the quadratic term (``'auto'`` with n >= 4), else NaN.
    """

    axis: str
    component: str
    degree: int
    coefficients: np.ndarray
    positions: np.ndarray
    values: np.ndarray
    residuals: np.ndarray
    rss: float
    rms: float
    max_abs: float
    r2_adjusted: float
    rule: str
    f_statistic: float = float("nan")
    p_value: float = float("nan")

    @property
    def name(self):
        """Paper notation, e.g. ``delta_y(x)``."""
        return "delta_%s(%s)" % (self.component, self.axis)

    @property
    def n(self):
        return int(self.positions.size)

    def as_dict(self):
        def num(v):
            return None if not np.isfinite(v) else float(v)
        return {"function": self.name, "axis": self.axis, "component": self.component,
                "degree": self.degree, "b0_mm": float(self.coefficients[0]),
                "b1": float(self.coefficients[1]), "b2_per_mm": float(self.coefficients[2]),
                "n": self.n, "rms_residual_mm": float(self.rms),
                "max_residual_mm": float(self.max_abs), "r2_adjusted": num(self.r2_adjusted),
                "rule": self.rule, "f_statistic": num(self.f_statistic),
                "p_value": num(self.p_value),
                "residuals_mm": [float(v) for v in self.residuals]}


class AxisErrorModel:
    """The 12-component error model of a 3-axis machine (Dobariya 2015, eq. 6-16).

    Parameters
    ----------
    slope : array_like (3, 3)
        ``slope[a, i]`` = linear coefficient of ``delta_i(a)`` (mm/mm): scale errors on the
        diagonal, the squareness slopes ``alpha_ai`` off it.
    curvature : array_like (3, 3)
        ``curvature[a, i]`` = quadratic coefficient of ``delta_i(a)`` (1/mm): non-linear
        positional error on the diagonal, straightness/flatness off it.
    reference : array_like (3,)
        Reference point ``r`` (mm) the travels ``t_a = X_a - r_a`` count from.
    offset : array_like (3,)
        ``e0``, the error at the reference point (mm).
    travel : array_like (3, 2), optional
        Measured range of each slide (mm); NaN rows for slides without data.
    fits : list of ComponentFit, optional
        The fits the model came from (for reports).
    """

    def __init__(self, slope=None, curvature=None, reference=(0.0, 0.0, 0.0),
                 offset=(0.0, 0.0, 0.0), travel=None, fits=(), offset_spread=None):
        self.slope = np.zeros((3, 3)) if slope is None else np.array(slope, dtype=float)
        self.curvature = (np.zeros((3, 3)) if curvature is None
                          else np.array(curvature, dtype=float))
        self.reference = np.array(reference, dtype=float).reshape(3)
        self.offset = np.array(offset, dtype=float).reshape(3)
        self.travel = (np.full((3, 2), np.nan) if travel is None
                       else np.array(travel, dtype=float).reshape(3, 2))
        self.fits = list(fits)
        self.offset_spread = (np.zeros(3) if offset_spread is None
                              else np.array(offset_spread, dtype=float).reshape(3))
        if self.slope.shape != (3, 3) or self.curvature.shape != (3, 3):
            raise InputError("slope and curvature must be 3 x 3")
        for name, arr in (("slope", self.slope), ("curvature", self.curvature),
                          ("reference", self.reference), ("offset", self.offset)):
            if not np.all(np.isfinite(arr)):
                raise InputError("%s of the axis error model has non-finite values" % name)

    # ----------------------------------------------------------------- construction
    @classmethod
    def zero(cls, reference=(0.0, 0.0, 0.0)):
        """A model with no error at all (compensation returns its input exactly)."""
        return cls(reference=reference)

    @classmethod
    def from_components(cls, scale=None, positional=None, straightness=None, squareness=None,
                        reference=(0.0, 0.0, 0.0), offset=(0.0, 0.0, 0.0)):
        """Build a model from the paper's named components (Dobariya 2015, eq. 6-8).

        Parameters
        ----------
        scale : dict, optional
            ``{'x': s}``: scale error ``delta_x1(x) = s * t_x`` (mm/mm), eq. 6.
        positional : dict, optional
            ``{'x': (c1, c2)}``: ball-screw positional error ``delta_x2(x) = c1 t + c2 t^2``,
            eq. 6.
        straightness : dict, optional
            ``{'y(x)': (c1, c2)}``: straightness/flatness ``delta'_y(x) = c1 t_x + c2 t_x^2``
            (error along ``y`` of slide ``x``), eq. 7-8. Keys ``'i(a)'`` with ``i != a``.
        squareness : dict, optional
            ``{'xy': alpha}``: ``alpha_xy`` (rad), entering ``delta_y(x)`` as
            ``alpha_xy * t_x`` (eq. 7); key ``'ai'`` = moving slide ``a``, direction ``i``.
        reference, offset : array_like (3,)
            Reference point and error at it (mm).
        """
        slope = np.zeros((3, 3))
        curv = np.zeros((3, 3))
        for ax, s in (scale or {}).items():
            a = axis_index(ax)
            slope[a, a] += float(s)
        for ax, (c1, c2) in (positional or {}).items():
            a = axis_index(ax)
            slope[a, a] += float(c1)
            curv[a, a] += float(c2)
        for key, (c1, c2) in (straightness or {}).items():
            k = key.replace(" ", "").lower()
            if len(k) != 4 or k[1] != "(" or k[3] != ")" or k[0] == k[2]:
                raise InputError("straightness keys are 'i(a)' with i != a, e.g. 'y(x)' "
                                 "(got %r)" % key)
            i, a = axis_index(k[0]), axis_index(k[2])
            slope[a, i] += float(c1)
            curv[a, i] += float(c2)
        for key, alpha in (squareness or {}).items():
            k = key.strip().lower()
            if len(k) != 2 or k[0] == k[1]:
                raise InputError("squareness keys are two different axes, e.g. 'xy' (got %r)"
                                 % key)
            a, i = axis_index(k[0]), axis_index(k[1])
            slope[a, i] += float(alpha)
        return cls(slope, curv, reference=reference, offset=offset)

    def to_dict(self):
        """JSON-able dict; :meth:`from_dict` restores the model (without the fits)."""
        return {"reference_mm": self.reference.tolist(), "offset_mm": self.offset.tolist(),
                "slope": self.slope.tolist(), "curvature_per_mm": self.curvature.tolist(),
                "travel_mm": [[None if not np.isfinite(v) else float(v) for v in row]
                              for row in self.travel],
                "layout": "slope[a][i], curvature[a][i]: slide a = x,y,z moving, "
                          "error along i = x,y,z"}

    @classmethod
    def from_dict(cls, d):
        travel = np.array([[np.nan if v is None else v for v in row]
                           for row in d.get("travel_mm", [[None, None]] * 3)], dtype=float)
        return cls(d["slope"], d["curvature_per_mm"], reference=d["reference_mm"],
                   offset=d["offset_mm"], travel=travel)

    def in_program_coordinates(self, work_offset):
        """The same machine seen from a program whose zero sits at ``work_offset``.

        Parameters
        ----------
        work_offset : array_like (3,)
            Machine coordinates (mm) of the program zero (the G54 offset), when the error
            measurements are in machine coordinates.

        Returns
        -------
        AxisErrorModel
            ``E_prog(P) = E(P + work_offset)``: reference and travel shifted by
            ``-work_offset``.
        """
        o = np.array(work_offset, dtype=float).reshape(3)
        return AxisErrorModel(self.slope, self.curvature, self.reference - o, self.offset,
                              self.travel - o[:, None], self.fits, self.offset_spread)

    # ------------------------------------------------------------------- evaluation
    def is_zero(self):
        return not (self.slope.any() or self.curvature.any() or self.offset.any())

    def delta(self, component, axis, positions):
        """One error function ``delta_i(a)`` (eq. 6-8) at slide positions (mm).

        Parameters
        ----------
        component, axis : str
            Error direction ``i`` and moving slide ``a``.
        positions : array_like (n,)
            Positions of slide ``a`` (mm, absolute, not travel).

        Returns
        -------
        ndarray (n,)
            ``slope[a, i] t + curvature[a, i] t^2`` with ``t = position - r_a`` (mm).
        """
        i, a = axis_index(component), axis_index(axis)
        t = np.asarray(positions, dtype=float) - self.reference[a]
        return self.slope[a, i] * t + self.curvature[a, i] * t * t

    def error(self, points):
        """Tool-position error ``E(X)`` (actual minus commanded), eq. 14.

        Parameters
        ----------
        points : array_like (..., 3)
            Commanded points (mm).

        Returns
        -------
        ndarray (..., 3)
            ``E_i = e0_i + sum_a (slope[a, i] t_a + curvature[a, i] t_a^2)`` (mm).
        """
        p = as_points(points)
        t = p - self.reference
        return self.offset + t @ self.slope + (t * t) @ self.curvature

    def jacobian(self, points):
        """``dE_i/dX_a`` at the points: array (..., 3, 3) indexed ``[..., i, a]``."""
        p = as_points(points)
        t = p - self.reference
        d = self.slope[None, :, :] + 2.0 * t.reshape(-1, 3)[:, :, None] * self.curvature
        return np.swapaxes(d, 1, 2).reshape(p.shape[:-1] + (3, 3))

    def actual(self, points):
        """Where the tool lands for commanded points: ``X + E(X)`` (mm)."""
        p = as_points(points)
        return p + self.error(p)

    def compensate(self, points, tol=COMPENSATE_TOL, max_iter=30):
        """Commands ``X'`` with ``X' + E(X') = X``: the tool lands on the programmed ``X``.

        Newton's method with the analytic Jacobian ``I + dE/dX``, started from the
        paper's first-order ``X - E(X)``; vectorised over all points.

        Parameters
        ----------
        points : array_like (..., 3)
            Programmed points (mm).
        tol : float
            Largest accepted ``|X' + E(X') - X|`` per coordinate (mm).

        Returns
        -------
        ndarray (..., 3)
            Compensated commands (mm). A zero model returns the input values exactly.

        Raises
        ------
        ComputationError
            When Newton's method does not converge (an error model whose slopes reach
            -1, i.e. a slide that does not move).
        InputError
            Non-finite points, or points so far outside the measured travel that the
            model's polynomials overflow there.
        """
        p = as_points(points)
        flat = p.reshape(-1, 3)
        _finite_points(flat, "cannot compensate %d non-finite point(s) (the first: %.6g, "
                             "%.6g, %.6g)")
        if self.is_zero() or flat.shape[0] == 0:
            return p.copy()
        with np.errstate(over="ignore", invalid="ignore"):
            xc = flat - self.error(flat)
        for _ in range(max_iter):
            with np.errstate(over="ignore", invalid="ignore"):
                r = xc + self.error(xc) - flat
            _finite_points(r, "the axis error model has no finite compensation for %d "
                           "point(s) (the first at %.6g, %.6g, %.6g mm): they lie too far "
                           "outside the measured travel for its polynomials", flat)
            bad = np.abs(r).max(axis=1) > tol
            if not bad.any():
                return xc.reshape(p.shape)
            J = self.jacobian(xc[bad]) + np.eye(3)
            try:
                xc[bad] -= np.linalg.solve(J, r[bad][:, :, None])[:, :, 0]
            except np.linalg.LinAlgError as exc:
                raise ComputationError("axis error compensation: singular Jacobian (%s); the "
                                       "error model's slopes make a slide stand still"
                                       % exc) from exc
        raise ComputationError("axis error compensation did not converge in %d Newton steps "
                               "(largest residual %.3g mm)" % (max_iter, np.abs(r).max()))

    # --------------------------------------------------------------------- reports
    def components(self):
        """The 12 components of Dobariya 2015 (plus the six measured slopes).

        Returns
        -------
        dict
            ``scale`` {axis: mm/mm}, ``positional_quadratic`` {axis: 1/mm} (eq. 6),
            ``straightness`` {'y(x)', 'x(y)', 'x(z)': 1/mm}, ``flatness`` {'z(x)', 'z(y)',
            'y(z)': 1/mm} (quadratic coefficients of ``delta'``, eq. 7-8),
            ``squareness`` {'xy', 'xz', 'yz': rad} (``alpha_ab + alpha_ba``),
            ``slopes`` {'xy', ...: rad} (the six ``alpha_ai``), ``offset_mm`` (e0).
        """
        s, c = self.slope, self.curvature
        idx = {a: k for k, a in enumerate(AXES)}
        return {
            "scale": {a: float(s[k, k]) for k, a in enumerate(AXES)},
            "positional_quadratic": {a: float(c[k, k]) for k, a in enumerate(AXES)},
            "straightness": {key: float(c[idx[key[2]], idx[key[0]]])
                             for key in ("y(x)", "x(y)", "x(z)")},
            "flatness": {key: float(c[idx[key[2]], idx[key[0]]])
                         for key in ("z(x)", "z(y)", "y(z)")},
            "squareness": {ab: float(s[idx[ab[0]], idx[ab[1]]] + s[idx[ab[1]], idx[ab[0]]])
                           for ab in ("xy", "xz", "yz")},
            "slopes": {a + i: float(s[idx[a], idx[i]]) for a in AXES for i in AXES if a != i},
            "offset_mm": self.offset.tolist(),
        }

    def summary_lines(self):
        """Human-readable lines: per-function fit and the 12 components."""
        out = []
        if self.fits:
            out.append("Fitted error functions (t = position - reference, mm; "
                       "error = actual - commanded):")
            out.append("  %-11s %3s %6s %12s %13s %13s %10s %10s  %s"
                       % ("function", "n", "degree", "b0 [um]", "b1 [um/m]", "b2 [um/m^2]",
                          "rms [um]", "max [um]", "rule"))
            for f in self.fits:
                out.append("  %-11s %3d %6d %12.3f %13.3f %13.3f %10.3f %10.3f  %s"
                           % (f.name, f.n, f.degree, f.coefficients[0] * 1e3,
                              f.coefficients[1] * 1e6, f.coefficients[2] * 1e9,
                              f.rms * 1e3, f.max_abs * 1e3, f.rule
                              + ("" if not np.isfinite(f.p_value) else " p=%.3g" % f.p_value)))
            missing = [a.upper() for k, a in enumerate(AXES)
                       if not np.isfinite(self.travel[k]).all()]
            if missing:
                out.append("  not measured (no error assumed): %s" % ", ".join(missing))
        comp = self.components()
        out.append("Components (Dobariya 2015, eq. 6-8): scale [um/m] X %.3f Y %.3f Z %.3f"
                   % tuple(comp["scale"][a] * 1e6 for a in AXES))
        out.append("  squareness [urad] XY %.3f XZ %.3f YZ %.3f; straightness [um/m^2] "
                   "y(x) %.3f x(y) %.3f x(z) %.3f; flatness [um/m^2] z(x) %.3f z(y) %.3f "
                   "y(z) %.3f"
                   % (tuple(comp["squareness"][k] * 1e6 for k in ("xy", "xz", "yz"))
                      + tuple(comp["straightness"][k] * 1e9 for k in ("y(x)", "x(y)", "x(z)"))
                      + tuple(comp["flatness"][k] * 1e9 for k in ("z(x)", "z(y)", "y(z)"))))
        out.append("  error at the reference (%.3f, %.3f, %.3f) mm: e0 = (%.3f, %.3f, %.3f) um"
                   % (tuple(self.reference) + tuple(self.offset * 1e3))
                   + ("" if not self.offset_spread.any() else
                      " (spread between axes %.3f %.3f %.3f um)"
                      % tuple(self.offset_spread * 1e3)))
        return out



# ---------------------------------------------------------------------------- fitting
def _polyfit(t, y, degree):
    """Least squares ``y ~ sum b_k t^k``; returns (coefficients (3, m), residuals (n, m))."""
    coef = np.polynomial.polynomial.polyfit(t, y, degree)
    coef = np.atleast_2d(coef.T).T if y.ndim == 1 else coef
    full = np.zeros((3,) + coef.shape[1:])
    full[:degree + 1] = coef
    fitted = np.polynomial.polynomial.polyval(t, coef)
    fitted = fitted.T if y.ndim > 1 else fitted
    return full, y - fitted


def _axis_data(ax, data, source):
    """Positions (n,) and errors (n, 3) of one slide, checked: as many rows as positions,
    finite, within :data:`MAX_VALUE`."""
    pos, err = data
    pos = np.asarray(pos, dtype=float).reshape(-1)
    err = np.asarray(err, dtype=float).reshape(-1, 3)
    if err.shape[0] != pos.size:
        raise InputError("axis %s: %d positions but %d error rows" % (ax, pos.size,
                                                                       err.shape[0]),
                         file=source)
    if not (np.all(np.isfinite(pos)) and not np.isinf(err).any()):
        raise InputError("axis %s: non-finite measured values" % ax.upper(), file=source)
    if not (np.all(np.abs(pos) <= MAX_VALUE) and not (np.abs(err) > MAX_VALUE).any()):
        raise InputError("axis %s: measured positions or errors beyond %g mm (1 km; expected "
                         "a machine's travel and errors in mm)" % (ax.upper(), MAX_VALUE),
                         file=source)
    return pos, err


def _row_sets(err):
    """``[(rows (n,) bool, [component, ...]), ...]``: components measured at the same rows."""
    sets = {}
    for i in range(3):
        sets.setdefault(tuple(~np.isnan(err[:, i])), []).append(i)
    return [(np.array(rows, dtype=bool), comps) for rows, comps in sets.items()]


def fit_axis_errors(data, model="auto", reference=(0.0, 0.0, 0.0), alpha=F_TEST_ALPHA,
                    source=None):
    """Fit the nine 1-D error functions from per-axis measurements (Dobariya 2015, sec. 4).

    Parameters
    ----------
    data : mapping
        ``{'x': (positions (n,), errors (n, 3)), ...}``: for each measured slide, its
        positions (mm, absolute) and the tool-position errors along x, y, z (mm, actual
        minus commanded) with the other slides at the reference; NaN: that component was
        not measured in that row (left out of its fit). Missing slides get no error.
    model : {'linear', 'quadratic', 'auto'}
        Degree of every function, or ``'auto'``: per function, quadratic when the partial
        F-test of the quadratic term is significant at ``alpha`` (needs n >= 4).
    reference : array_like (3,)
        Reference point (mm): where the other slides stood while one was measured.
    source : str, optional
        File name for error messages.

    Returns
    -------
    AxisErrorModel
        With ``fits`` (one :class:`ComponentFit` per measured function) and ``offset`` =
        the mean of the per-axis estimates of the error at the reference.

    Raises
    ------
    InputError
        Unknown ``model``, no data at all, or too few distinct positions for the degree.
    """
    if model not in MODEL_CHOICES:
        raise InputError("unknown axis error model %r (expected one of %s)"
                         % (model, ", ".join(MODEL_CHOICES)), file=source)
    ref = np.array(reference, dtype=float).reshape(3)
    if not np.all(np.abs(ref) <= MAX_VALUE):
        raise InputError("the reference point (%g, %g, %g) mm is not within %g mm (1 km) of the "
                         "origin" % (tuple(ref) + (MAX_VALUE,)), file=source)
    slope = np.zeros((3, 3))
    curv = np.zeros((3, 3))
    travel = np.full((3, 2), np.nan)
    b0 = np.full((3, 3), np.nan)
    fits = []
    keys = {str(k).strip().lower(): v for k, v in dict(data).items()}
    unknown = sorted(set(keys) - set(AXES))
    if unknown:
        raise InputError("unknown axis %r in the axis error data (expected x, y, z)"
                         % unknown[0], file=source)
    if not keys:
        raise InputError("no axis error measurements (expected rows for X, Y and/or Z)",
                         file=source)
    for a, ax in enumerate(AXES):
        if ax not in keys:
            continue
        pos_all, err_all = _axis_data(ax, keys[ax], source)
        travel[a] = pos_all.min(), pos_all.max()
        axis_fits = []
        for rows, comps in _row_sets(err_all):
            pos = pos_all[rows]
            axis_fits += _fit_set(ax, comps, rows.all(), pos, pos - ref[a],
                                  err_all[rows][:, comps], model, alpha, source)
        for f in sorted(axis_fits, key=lambda f: AXES.index(f.component)):
            i = AXES.index(f.component)
            b0[a, i], slope[a, i], curv[a, i] = f.coefficients
            fits.append(f)
    measured = np.isfinite(b0[:, 0])
    offset = b0[measured].mean(axis=0)
    spread = b0[measured].max(axis=0) - b0[measured].min(axis=0)
    return AxisErrorModel(slope, curv, reference=ref, offset=offset, travel=travel, fits=fits,
                          offset_spread=spread)


def _fit_set(ax, comps, every_row, pos, t, err, model, alpha, source):
    """Fits of the components ``comps`` of slide ``ax`` measured at the same rows:
    positions ``pos`` and travels ``t`` (n,), errors ``err`` (n, len(comps));
    ``every_row``: measured at all the slide's rows."""
    n_distinct = np.unique(pos).size
    need = 3 if model == "quadratic" else 2
    if n_distinct < need:
        what = ("%d distinct position(s) measured" if every_row else "error along %s measured "
                "at %%d distinct position(s)" % "/".join(AXES[i].upper() for i in comps))
        raise InputError("axis %s: %s; a %s fit needs at least %d" % (ax.upper(), what % n_distinct,
                         "quadratic" if need == 3 else "linear", need), file=source)
    n = t.size
    c1, r1 = _polyfit(t, err, 1)
    c2, r2 = (_polyfit(t, err, 2) if n_distinct >= 3 else (None, None))
    fits = []
    for j, i in enumerate(comps):
        rss1 = float(np.sum(r1[:, j] ** 2))
        f_stat = p_val = float("nan")
        if model == "linear":
            deg, rule = 1, "given"
        elif model == "quadratic":
            deg, rule = 2, "given"
        elif c2 is None or n < 4:
            deg, rule = 1, "n < 4"
        elif rss1 <= n * EXACT_RMS ** 2:
            deg, rule = 1, "exact line"
        else:
            rss2 = float(np.sum(r2[:, j] ** 2))
            if rss2 <= n * EXACT_RMS ** 2:
                f_stat, p_val = float("inf"), 0.0
            else:
                f_stat = (rss1 - rss2) / (rss2 / (n - 3))
                p_val = float(stats.f.sf(f_stat, 1, n - 3))
            deg, rule = (2 if p_val < alpha else 1), "F-test"
        coef = (c1 if deg == 1 else c2)[:, j].copy()
        res = (r1 if deg == 1 else r2)[:, j].copy()
        rss = float(np.sum(res ** 2))
        tss = float(np.sum((err[:, j] - err[:, j].mean()) ** 2))
        dof = n - deg - 1
        r2a = (1.0 - (rss / dof) / (tss / (n - 1))) if (dof > 0 and tss > 0) else np.nan
        fits.append(ComponentFit(ax, AXES[i], deg, coef, pos.copy(), err[:, j].copy(), res,
                                 rss, float(np.sqrt(rss / n)), float(np.abs(res).max()),
                                 float(r2a), rule, float(f_stat), float(p_val)))
    return fits
