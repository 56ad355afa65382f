# SPDX-License-Identifier: LGPL-2.1-or-later
"""The machining-process model of virtual machining: where a pass leaves the surface (no FreeCAD).

Two passes, one CAM surface
---------------------------
Every simulated part is cut in two passes from the surface ``S_g`` given to CAM (the
nominal, or a corrected face), as in the mirror paper (2019, Sec. 2.6: roughing leaves
0.4 mm, semi-finishing 0.2 mm, finishing 0) and in Werner 2022 (Sec. 3: 0.3 mm left for
the finishing cutter):

1. semi-finishing, programmed at ``S_g + s n_g`` (``s`` the stock), removes the depth
   ``a_1 = a_semi`` (the roughing allowance minus the stock; roughing is taken as exact)
   and leaves the stock plus its own error ``e_1``;
2. finishing, programmed at ``S_g``, removes what the first pass left at that point,
   ``a_2 = s + e_1`` (the nominal stock plus the previous pass's error), and leaves
   ``e_2``.

Pass ``k`` places the point of parameters (u, v) at

    M_k(u, v) = S_g(u, v) + (o_k + e_k(u, v)) n_g(u, v),      o_1 = s, o_2 = 0,

``n_g`` the outward unit normal of ``S_g``; ``e > 0`` leaves material (undercut, the
deviation sign of :mod:`surfcomp.core.compensation.deviations`). The error is the sum of four parts:

    e_k = e_geo + e_defl(a_k) + e_wav + e_rand,k

geometric (the machine and set-up; the same in every pass)
    ``e_geo = offset + slope_gain * s_f + abs_slope_gain * |s_f| + tilt_f * xi + tilt_c * eta
    + bow_f * xi^2 + bow_c * eta^2 + E_axis(M0) . n_g``
deflection (the cutting force grows with the material removed)
    ``e_defl = a_k * (k_0 + k_s * s_f + k_a * |s_f|) = a_k * g``
waviness
    ``e_wav = waviness * sin(2 pi p_f / wavelength)``
random scatter
    ``e_rand``: standard deviation ``sigma``, a new realisation in every pass

with the feed direction ``f`` (projected perpendicular to the tool axis ``a``), the
cross-feed direction ``c = a x f``, the point's coordinates ``p_f``, ``p_c`` (mm) along
``f`` and ``c`` from the centre of the nominal work area, ``xi = p_f / h_f``,
``eta = p_c / h_c`` (``h_f``, ``h_c`` the work area's half extents, so the tilt and bow
coefficients are the errors in mm at the border), the slope along the feed
``s_f = -(n . f) / (n . a)`` (``dz/dx`` for a face ``z = h(x, y)`` cut along x, clipped
to +-``MAX_SLOPE``) and ``E_axis`` the tool-position error of the machine's axes
(:class:`surfcomp.core.axis.axis_errors.AxisErrorModel`, Dobariya 2015 eq. 14; only its
component along the normal moves the surface). ``g = k_0 + k_s s_f + k_a |s_f|`` is the
deflection per mm of engagement (dimensionless): a ball-end cutter deflects more with
more material to remove, and differently uphill, downhill and on the flat, where it
cuts near its tip.

The random part with ``correlation_length L = 0`` is independent from point to point;
with ``L > 0`` it is a Gaussian random field over the plane perpendicular to the tool
axis with correlation ``exp(-(r / L)^2)``: white noise on a lattice of spacing <= L/3,
Gaussian-filtered (kernel sigma L/2, ``scipy.ndimage``), scaled to unit variance
exactly, and interpolated by cubic splines (``scipy.ndimage.map_coordinates``).
Measurements add independent probe noise ``probe_sigma``.

What follows (write ``G = e_geo + e_wav`` and take ``a_semi = s``, no random part)
    a part machined from the nominal: ``e_1 = G + g s`` and ``e_2 = G + g (s + e_1) =
    (1 + g) e_1``: the finishing error follows the cut. Mirror (the semi-finished part
    measured, ``delta = e_1``) leaves ``g e_1``; raw (a finished part measured, the next
    part corrected) leaves nothing systematic: ``g (e_1' - e_1)`` and the passes'
    scatter are random; offset leaves ``e_2 - mean(e_2)``. With ``k = 0`` the two passes
    have the same error, so mirror and raw see the same thing. The noise floor (every
    systematic part removed exactly) is ``sqrt(sigma^2 (1 + g^2) + probe_sigma^2)``: the
    last pass's scatter, its echo through the engagement and the probe.

Left out: the correction's own change of the engagement (a finishing pass programmed
``delta`` deeper removes ``delta`` more, so it would deflect ``g delta`` more and realise
only ``(1 - g)`` of every correction); roughing errors; tool wear, heat and
part-to-part set-up changes (all parts are machined alike); the scallops between tool
paths and the ball's contact geometry (errors are along the normal at the point).
"""

from dataclasses import asdict, dataclass, replace

import numpy as np
from scipy import ndimage

from ...errors import InputError
from ..command_options import SIMULATE
from ..option_tables import MODEL
from ..surface import bspline

#: slope along the feed beyond which the model clips (nearly vertical walls)
MAX_SLOPE = 10.0
#: random-field lattice nodes per direction at most
MAX_LATTICE = 1024
#: default stock (mm) the semi-finishing pass leaves (Werner 2022: 0.3 mm; ``simulate
#: --stock``, :data:`surfcomp.core.command_options.SIMULATE`)
DEFAULT_STOCK = SIMULATE["stock"].default
#: what the model contains and what it leaves out, in words (reports; docs/method.md)
SUMMARY = {
    "contains": "Every part is cut in two passes from the surface given to CAM: "
                "semi-finishing, programmed the stock outside it, then finishing. Each pass "
                "leaves an error along the normal that is the sum of the machine's geometric "
                "error (constant, slope, tilt and bow terms, axis errors), a tool deflection "
                "proportional to the depth the pass removes and growing with the slope along "
                "the feed, a waviness along the feed and random scatter; the finishing pass "
                "removes the stock plus the semi-finishing error, so its error follows the "
                "cut. The probe adds noise to every measured point.",
    "leaves_out": "The correction's own change of the depth of cut (a path programmed deeper "
                  "would deflect more and realise only part of the correction), roughing "
                  "errors, tool wear, heat and part-to-part set-up changes (every part is "
                  "machined alike), scallops between tool paths and the ball's contact "
                  "geometry (errors act along the normal at the point).",
}

_SCALARS = ("offset", "slope_gain", "abs_slope_gain", "waviness", "wavelength", "sigma",
            "correlation_length", "probe_sigma", "stock")
_NON_NEGATIVE = ("sigma", "correlation_length", "probe_sigma", "stock")
#: largest error (mm) of a pass and of each error term: the largest deviation a
#: compensation accepts (``--max-offset`` at most 100 mm); more is a unit mistake
MAX_ERROR = 100.0
#: the terms bounded by MAX_ERROR in magnitude (the deflection's gains by MAX_GAIN)
_ERRORS = ("offset", "slope_gain", "abs_slope_gain", "waviness", "sigma", "probe_sigma", "stock",
           "tilt", "bow")
MAX_GAIN = 10.0


@dataclass
class MachiningModel:
    """Parameters of the machining-process model (module docstring); lengths in mm.

    Defaults describe a Werner-like case without deflection: on the bundled example
    face (45 x 45 mm, slopes up to about +-0.35) the systematic part spans about
    -0.030 .. +0.043 mm (mean 4.8 um, std 16.4 um; Werner 2022 Tab. 1: -0.030 ..
    +0.045, std 17.3 um), with a 1.5 um random part and 0.5 um probe noise.
    ``deflection`` is ``(k_0, k_s, k_a)`` (mm of error per mm of engagement);
    ``stock`` the allowance the semi-finishing pass leaves; ``semi_engagement`` the
    depth the semi-finishing pass removes (None: equal to ``stock``).
    """

    offset: float = MODEL["offset"].default
    slope_gain: float = MODEL["slope_gain"].default
    abs_slope_gain: float = MODEL["abs_slope_gain"].default
    tilt: tuple = MODEL["tilt"].default
    bow: tuple = MODEL["bow"].default
    waviness: float = MODEL["waviness"].default
    wavelength: float = MODEL["wavelength"].default
    feed: tuple = MODEL["feed"].default
    tool_axis: tuple = MODEL["tool_axis"].default
    sigma: float = MODEL["sigma"].default
    correlation_length: float = MODEL["correlation_length"].default
    probe_sigma: float = MODEL["probe_sigma"].default
    axis_errors: object = None
    deflection: tuple = MODEL["deflection"].default
    stock: float = DEFAULT_STOCK
    semi_engagement: float = MODEL["semi_engagement"].default

    def __post_init__(self):
        for name in _SCALARS:
            if not np.isfinite(float(getattr(self, name))):
                raise InputError("machining model %s must be a finite number, got %r"
                                 % (name, getattr(self, name)))
        for name in _NON_NEGATIVE:
            if getattr(self, name) < 0:
                raise InputError("machining model %s must be >= 0 mm, got %g"
                                 % (name, getattr(self, name)))
        if self.semi_engagement is not None:
            self.semi_engagement = float(self.semi_engagement)
            if not (np.isfinite(self.semi_engagement) and self.semi_engagement >= 0):
                raise InputError("machining model semi_engagement must be a finite depth "
                                 ">= 0 mm, got %r" % (self.semi_engagement,))
        if self.waviness and not self.wavelength > 0:
            raise InputError("the waviness wavelength must be > 0 mm, got %g" % self.wavelength)
        self.tilt = _finite_tuple(self.tilt, 2, "tilt")
        self.bow = _finite_tuple(self.bow, 2, "bow")
        self.deflection = _finite_tuple(self.deflection, 3, "deflection")
        self._check_magnitudes()
        a = _scaled(_finite_tuple(self.tool_axis, 3, "tool_axis"))
        f = _scaled(_finite_tuple(self.feed, 3, "feed"))
        if not np.linalg.norm(a) > 0:
            raise InputError("feed and tool axis must be 3-vectors, the tool axis non-zero")
        a = a / np.linalg.norm(a)
        f = f - np.dot(f, a) * a
        if not np.linalg.norm(f) > 1e-9:
            raise InputError("the feed direction must be non-zero and not parallel to the tool "
                             "axis, got feed %s, tool axis %s" % (self.feed, self.tool_axis))
        self.tool_axis = tuple(a.tolist())
        self.feed = tuple((f / np.linalg.norm(f)).tolist())

    def _check_magnitudes(self):
        """Error terms of at most MAX_ERROR mm, deflection gains of at most MAX_GAIN: larger
        ones are no machining error (and overflow the simulation)."""
        limits = [(name, MAX_ERROR, "mm") for name in _ERRORS] + [("deflection", MAX_GAIN,
                                                                   "mm per mm of engagement")]
        if self.semi_engagement is not None:
            limits.append(("semi_engagement", MAX_ERROR, "mm"))
        for name, limit, unit in limits:
            value = getattr(self, name)
            if np.max(np.abs(value)) > limit:
                raise InputError("machining model %s must be at most %g %s in magnitude (a "
                                 "larger one is no machining error: a unit mistake?), got %s"
                                 % (name, limit, unit, value))

    @property
    def deflects(self):
        """True when the deflection term is not zero (the engagement matters)."""
        return any(k != 0.0 for k in self.deflection)

    @property
    def semi_depth(self):
        """Depth ``a_1`` (mm) the semi-finishing pass removes."""
        return self.stock if self.semi_engagement is None else self.semi_engagement

    def as_dict(self):
        """JSON-able parameters (axis errors as :meth:`AxisErrorModel.to_dict`)."""
        d = asdict(replace(self, axis_errors=None))
        for key in ("tilt", "bow", "feed", "tool_axis", "deflection"):
            d[key] = list(getattr(self, key))
        d["axis_errors"] = (None if self.axis_errors is None else
                            (self.axis_errors.to_dict() if hasattr(self.axis_errors, "to_dict")
                             else repr(self.axis_errors)))
        d["units"] = ("mm (gains: mm per unit slope; tilt/bow: mm at the work-area border; "
                      "deflection k_0, k_s, k_a: mm per mm of engagement)")
        return d

    # ------------------------------------------------------------------ evaluation
    def frame(self, surface, samples=41):
        """The work-area frame of ``surface``: centre and half extents along feed/cross-feed.

        Returns
        -------
        Frame
        """
        (u0, u1), (v0, v1) = surface.u_range, surface.v_range
        P = bspline.evaluate_grid(surface, np.linspace(u0, u1, samples),
                                  np.linspace(v0, v1, samples)).reshape(-1, 3)
        a = np.asarray(self.tool_axis)
        f = np.asarray(self.feed)
        c = np.cross(a, f)
        pf, pc = P @ f, P @ c
        center = (0.5 * (pf.max() + pf.min())) * f + (0.5 * (pc.max() + pc.min())) * c
        center = center + (P @ a).mean() * a
        half = (max(0.5 * np.ptp(pf), 1e-9), max(0.5 * np.ptp(pc), 1e-9))
        return Frame(center=center, feed=f, cross=c, axis=a, half=half)

    def slope(self, normal):
        """Slope along the feed ``s = -(n . f) / (n . a)``, clipped to +-MAX_SLOPE; shape (N,)."""
        n = np.asarray(normal, dtype=float)
        na = n @ np.asarray(self.tool_axis)
        nf = n @ np.asarray(self.feed)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = -nf / na
        s = np.where(np.abs(na) < 1e-12, -np.sign(nf) * np.sign(na + 1e-300) * MAX_SLOPE, s)
        return np.clip(s, -MAX_SLOPE, MAX_SLOPE)

    def systematic(self, frame, points, normal):
        """Engagement-independent systematic error ``e_geo + e_wav`` (mm) at points.

        Parameters
        ----------
        frame : Frame
        points, normal : array_like, shape (N, 3)
            Points (mm) and outward unit normals.

        Returns
        -------
        ndarray, shape (N,)
        """
        P = np.asarray(points, dtype=float).reshape(-1, 3)
        n = np.asarray(normal, dtype=float).reshape(-1, 3)
        pf, pc = frame.coords(P)
        xi, eta = pf / frame.half[0], pc / frame.half[1]
        s = self.slope(n)
        e = (self.offset + self.slope_gain * s + self.abs_slope_gain * np.abs(s)
             + self.tilt[0] * xi + self.tilt[1] * eta
             + self.bow[0] * xi ** 2 + self.bow[1] * eta ** 2)
        if self.waviness:
            e = e + self.waviness * np.sin(2.0 * np.pi * pf / self.wavelength)
        if self.axis_errors is not None:
            e = e + np.einsum("ij,ij->i", np.asarray(self.axis_errors.error(P)).reshape(-1, 3), n)
        return e

    def compliance(self, normal):
        """Deflection per mm of engagement ``g = k_0 + k_s s + k_a |s|`` (dimensionless), (N,)."""
        s = self.slope(np.asarray(normal, dtype=float).reshape(-1, 3))
        k0, ks, ka = self.deflection
        return k0 + ks * s + ka * np.abs(s)

    def deflection_error(self, normal, engagement):
        """Deflection term ``e_defl = a g`` (mm) for the engagement ``a`` (mm; scalar or (N,))."""
        return np.asarray(engagement, dtype=float).reshape(-1) * self.compliance(normal)

    def random(self, frame, points, rng):
        """One realisation of the random part at the points (mm), shape (N,)."""
        P = np.asarray(points, dtype=float).reshape(-1, 3)
        if self.sigma == 0:
            return np.zeros(P.shape[0])
        if self.correlation_length == 0:
            return rng.normal(0.0, self.sigma, P.shape[0])
        return self.sigma * correlated_field(frame.coords(P), frame.half,
                                             self.correlation_length, rng)

    def noise_floor(self, normal):
        """Standard deviation (mm) left when every systematic error is removed exactly.

        ``sqrt(sigma^2 (1 + mean(g^2)) + probe_sigma^2)`` over the given outward unit
        normals (N, 3): the finishing pass's scatter, the semi-finishing pass's scatter
        passed on through the engagement, and the probe noise of the final measurement.
        """
        g2 = float(np.mean(self.compliance(normal) ** 2))
        return float(np.sqrt(self.sigma ** 2 * (1.0 + g2) + self.probe_sigma ** 2))


def _scaled(vector):
    """A direction divided by its largest component (so its norm neither overflows nor
    underflows: 1e308 and 1e-320 components keep their direction)."""
    v = np.asarray(vector, dtype=float)
    big = np.max(np.abs(v)) if v.size else 0.0
    return v / big if 0 < big < np.inf else v


def _finite_tuple(values, count, name):
    try:
        out = tuple(float(x) for x in values)
    except (TypeError, ValueError):
        out = ()
    if len(out) != count or not all(np.isfinite(out)):
        raise InputError("machining model %s takes %d finite values, got %r"
                         % (name, count, values))
    return out


@dataclass
class Frame:
    """Work-area frame: ``center`` (3,), unit ``feed``, ``cross``, ``axis`` (3,), ``half``
    (2,) mm."""

    center: np.ndarray
    feed: np.ndarray
    cross: np.ndarray
    axis: np.ndarray
    half: tuple

    def coords(self, points):
        """Coordinates ``(p_f, p_c)`` (mm) along feed and cross-feed from the centre."""
        d = np.asarray(points, dtype=float).reshape(-1, 3) - self.center
        return d @ self.feed, d @ self.cross


def correlated_field(coords, half, length, rng, pad=2.0):
    """A unit-variance Gaussian random field with correlation ``exp(-(r/L)^2)`` at points.

    Parameters
    ----------
    coords : tuple of ndarray (N,)
        Plane coordinates (mm) of the points, inside ``[-half[k], half[k]]`` (points a
        little outside are clamped to the lattice's padded border).
    half : tuple of float
        Half extents (mm) of the area.
    length : float
        Correlation length ``L`` (mm), > 0.
    rng : numpy.random.Generator

    Returns
    -------
    ndarray, shape (N,)
        White noise on a lattice (spacing ``h <= L/3``; at most ``MAX_LATTICE`` nodes
        per direction), filtered with a Gaussian of standard deviation ``L/2`` (the
        covariance of filtered white noise is the kernel's autocorrelation, a Gaussian
        of standard deviation ``L / sqrt(2)``), divided by the filtered impulse's norm
        (unit variance), interpolated with cubic splines.
    """
    x, y = (np.asarray(c, dtype=float) for c in coords)
    ext = [2.0 * (h + pad * length) for h in half]
    h = max(length / 3.0, max(ext) / (MAX_LATTICE - 1))
    shape = tuple(int(np.ceil(e / h)) + 1 for e in ext)
    ks = 0.5 * length / h
    white = rng.standard_normal(shape)
    field_ = ndimage.gaussian_filter(white, ks, mode="wrap")
    r = int(np.ceil(4 * ks))
    imp = np.zeros((2 * r + 1, 2 * r + 1))
    imp[r, r] = 1.0
    norm = np.sqrt(np.sum(ndimage.gaussian_filter(imp, ks, mode="constant") ** 2))
    field_ /= norm
    i = (x + ext[0] / 2.0) / h
    j = (y + ext[1] / 2.0) / h
    return ndimage.map_coordinates(field_, [i, j], order=3, mode="nearest")


def cam_grid(surface, outward, us, vs):
    """Points (Ne, Me, 3) and outward unit normals (Ne, Me, 3) of ``surface`` on us x vs."""
    S, Su, Sv = bspline.evaluate_grid(surface, us, vs, order=1)
    n = np.cross(Su, Sv)
    n *= outward / np.linalg.norm(n, axis=-1, keepdims=True)
    return S, n


def machine_pass(model, frame, S, n, rng, offset=0.0, engagement=None):
    """One pass over CAM points ``S`` with normals ``n`` (both (..., 3), from :func:`cam_grid`).

    Returns
    -------
    (ndarray (..., 3), ndarray (...))
        The machined points ``S + (o + e) n`` and the pass's error ``e`` (mm); see
        :func:`machine`.
    """
    G = (S + offset * n).reshape(-1, 3)
    nn = n.reshape(-1, 3)
    e = model.systematic(frame, G, nn)
    if model.deflects:
        a = model.stock if engagement is None else engagement
        e = e + model.deflection_error(nn, np.broadcast_to(a, S.shape[:-1]))
    e = e + model.random(frame, G, rng)
    worst = np.max(np.where(np.isfinite(e), np.abs(e), np.inf)) if e.size else 0.0
    if not worst <= MAX_ERROR:
        raise InputError("the machining model gives a pass an error of %.6g mm (expected at "
                         "most %g mm, the largest deviation a compensation accepts): check the "
                         "model's terms (offset, gains, tilt, bow, waviness, deflection, axis "
                         "errors)" % (worst, MAX_ERROR))
    return (G + e[:, None] * nn).reshape(S.shape), e.reshape(S.shape[:-1])


def machine(model, frame, surface, outward, us, vs, rng, offset=0.0, engagement=None,
            with_error=False):
    """One pass: machine ``surface`` (given to CAM) and return the points on the grid us x vs.

    Parameters
    ----------
    model : MachiningModel
    frame : Frame
        From the nominal (:meth:`MachiningModel.frame`).
    surface : bspline.Surface
        The surface given to CAM (nominal or corrected).
    outward : {1, -1}
        Sign turning ``Su x Sv`` into the outward normal.
    us, vs : array_like (Ne,), (Me,)
    rng : numpy.random.Generator
    offset : float
        Distance ``o`` (mm) the programmed surface lies outside ``surface`` along its
        normal (the semi-finishing pass: the stock).
    engagement : float or array_like (Ne, Me), optional
        Depth ``a`` (mm) the pass removes at every point (default: the model's stock).
    with_error : bool
        Also return the pass's error ``e``.

    Returns
    -------
    ndarray, shape (Ne, Me, 3)
        ``S_g + (o + e) n`` (mm), ``e = e_geo + e_wav + a g + e_rand``; with
        ``with_error`` the tuple (points, ``e`` (Ne, Me)).
    """
    S, n = cam_grid(surface, outward, us, vs)
    M, e = machine_pass(model, frame, S, n, rng, offset, engagement)
    return (M, e) if with_error else M
