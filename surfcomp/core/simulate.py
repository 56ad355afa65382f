"""Virtual machining: see what a compensation does before cutting metal (no FreeCAD).

The loop of the papers (Werner 2022 Tab. 1-5; mirror paper Tab. 2-4, 4 replicas), for
every compensation method and replica:

1. machine the nominal (mirror: the nominal offset outward by the stock, the
   semi-finishing pass) with the machining-error model below;
2. measure it on the n x m grid (probe noise added);
3. compensate with :func:`surfcomp.core.pipeline.compensate` (a
   :class:`~surfcomp.io.measurements.MeasurementSet` built in memory);
4. machine the corrected surface with the same model (a new random realisation);
5. measure it against the nominal, at the grid nodes and between them (a grid
   ``between`` times denser over the same area), as signed distances along the
   nominal's outward normal (projection engine, :mod:`surfcomp.core.projection`).

Machining-error model
---------------------
"Machining" a surface ``S_g`` given to CAM places the point of parameters (u, v) at

    M(u, v) = S_g(u, v) + e(u, v) n_g(u, v),        e = e_sys + e_rand,

``n_g`` the outward unit normal of ``S_g``; ``e > 0`` leaves material (undercut, as
the deviation sign of :mod:`surfcomp.core.deviations`). The systematic part is

    e_sys = offset + slope_gain * s + abs_slope_gain * |s|
            + tilt_f * xi + tilt_c * eta + bow_f * xi^2 + bow_c * eta^2
            + waviness * sin(2 pi p_f / wavelength) + E_axis(M0) . n_g

with the feed direction ``f`` (projected perpendicular to the tool axis ``a``),
the cross-feed direction ``c = a x f``, the point's coordinates ``p_f``, ``p_c``
(mm) along ``f`` and ``c`` from the centre of the nominal work area, ``xi = p_f /
h_f``, ``eta = p_c / h_c`` (``h_f``, ``h_c`` the work area's half extents, so the
tilt and bow coefficients are the errors in mm at the border), the slope along the
feed ``s = -(n . f) / (n . a)`` (``dz/dx`` for a face ``z = h(x, y)`` cut along x;
clipped to +-``MAX_SLOPE``: tool deflection grows with the slope, uphill and
downhill differently), and ``E_axis`` the tool-position error of the machine's axes
(:class:`surfcomp.core.axis_errors.AxisErrorModel`, Dobariya 2015 eq. 14; only its
component along the normal moves the surface).

The random part has standard deviation ``sigma`` (mm). With ``correlation_length
L = 0`` it is independent from point to point; with ``L > 0`` it is a Gaussian
random field over the plane perpendicular to the tool axis with correlation
``exp(-(r / L)^2)``: white noise on a lattice of spacing <= L/3, Gaussian-filtered
(kernel sigma L/2, ``scipy.ndimage``), scaled to unit variance exactly, and
interpolated by cubic splines (``scipy.ndimage.map_coordinates``). Every machining
pass draws a new realisation; measurements add independent probe noise
``probe_sigma``. Random streams are seeded per (seed, replica, pass) so a method's
result does not depend on which other methods run.
"""

import zlib
from dataclasses import asdict, dataclass, field, replace

import numpy as np
from scipy import ndimage

from ..errors import InputError
from . import bspline
from .deviations import Statistics, statistics
from .methods import METHODS
from .pipeline import Options, compensate, prepare
from .progress import report, sub
from .projection import Projector

#: slope along the feed beyond which the model clips (nearly vertical walls)
MAX_SLOPE = 10.0
#: random-field lattice nodes per direction at most
MAX_LATTICE = 1024
#: method names of the simulation (``none`` = no compensation)
SIM_METHODS = ("none",) + METHODS
#: schema name of :meth:`SimulationResult.as_dict`
SCHEMA = "surfcomp-simulation/1"
#: statistics shown in the papers' table form (key, label)
TABLE_ROWS = (("max_negative", "Max. negative"), ("max_positive", "Max. positive"),
              ("mean", "Average value"), ("std", "Standard deviation (ddof=1)"),
              ("profile", "Profile error ISO 1101 (2 max|d|)"))
STAT_KEYS = ("count", "max_negative", "max_positive", "mean", "std", "rms", "profile")


@dataclass
class MachiningModel:
    """Parameters of the machining-error model (module docstring); lengths in mm.

    Defaults describe a Werner-like case: on the bundled example face (45 x 45 mm,
    slopes up to about +-0.35) the systematic part spans about -0.030 .. +0.043 mm
    (mean 4.8 um, std 16.4 um; Werner 2022 Tab. 1: -0.030 .. +0.045, std 17.3 um),
    with a 1.5 um random part and 0.5 um probe noise.
    """

    offset: float = 0.0
    slope_gain: float = 0.06
    abs_slope_gain: float = 0.03
    tilt: tuple = (0.0, 0.02)
    bow: tuple = (-0.02, 0.02)
    waviness: float = 0.0
    wavelength: float = 10.0
    feed: tuple = (1.0, 0.0, 0.0)
    tool_axis: tuple = (0.0, 0.0, 1.0)
    sigma: float = 0.0015
    correlation_length: float = 0.0
    probe_sigma: float = 0.0005
    axis_errors: object = None

    def __post_init__(self):
        for name in ("offset", "slope_gain", "abs_slope_gain", "waviness", "wavelength", "sigma",
                     "correlation_length", "probe_sigma"):
            if not np.isfinite(float(getattr(self, name))):
                raise InputError("machining model %s must be a finite number, got %r"
                                 % (name, getattr(self, name)))
        for name in ("sigma", "correlation_length", "probe_sigma"):
            if getattr(self, name) < 0:
                raise InputError("machining model %s must be >= 0 mm, got %g"
                                 % (name, getattr(self, name)))
        if self.waviness and not self.wavelength > 0:
            raise InputError("the waviness wavelength must be > 0 mm, got %g" % self.wavelength)
        self.tilt = tuple(float(x) for x in self.tilt)
        self.bow = tuple(float(x) for x in self.bow)
        if len(self.tilt) != 2 or len(self.bow) != 2:
            raise InputError("tilt and bow take two values (along the feed, across it)")
        a = np.asarray(self.tool_axis, dtype=float)
        f = np.asarray(self.feed, dtype=float)
        if a.shape != (3,) or f.shape != (3,) or not np.linalg.norm(a) > 0:
            raise InputError("feed and tool axis must be 3-vectors, the tool axis non-zero")
        a = a / np.linalg.norm(a)
        f = f - np.dot(f, a) * a
        if not np.linalg.norm(f) > 1e-9:
            raise InputError("the feed direction must not be parallel to the tool axis")
        self.tool_axis = tuple(a.tolist())
        self.feed = tuple((f / np.linalg.norm(f)).tolist())

    def as_dict(self):
        """JSON-able parameters (axis errors as :meth:`AxisErrorModel.to_dict`)."""
        d = asdict(replace(self, axis_errors=None))
        d["tilt"], d["bow"] = list(self.tilt), list(self.bow)
        d["feed"], d["tool_axis"] = list(self.feed), list(self.tool_axis)
        d["axis_errors"] = (None if self.axis_errors is None else
                            (self.axis_errors.to_dict() if hasattr(self.axis_errors, "to_dict")
                             else repr(self.axis_errors)))
        d["units"] = "mm (gains: mm per unit slope; tilt/bow: mm at the work-area border)"
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
        """Systematic error ``e_sys`` (mm) at points with outward unit normals.

        Parameters
        ----------
        frame : Frame
        points, normal : array_like, shape (N, 3)

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

    def random(self, frame, points, rng):
        """One realisation of the random part at the points (mm), shape (N,)."""
        P = np.asarray(points, dtype=float).reshape(-1, 3)
        if self.sigma == 0:
            return np.zeros(P.shape[0])
        if self.correlation_length == 0:
            return rng.normal(0.0, self.sigma, P.shape[0])
        return self.sigma * correlated_field(frame.coords(P), frame.half,
                                             self.correlation_length, rng)


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


# ---------------------------------------------------------------------- methods
@dataclass
class MethodSpec:
    """One compensation to simulate: a ``label`` (column header) and pipeline ``options``
    (``method == 'none'``: the nominal is machined again, no compensation)."""

    label: str
    method: str
    options: Options = None

    def as_dict(self):
        o = self.options
        d = {"label": self.label, "method": self.method}
        if o is not None:
            d.update(mask_size=int(o.mask().shape[0]), mask_kind=o.mask_kind, edge=o.edge,
                     stock_mm=o.stock, refine=o.refine)
        return d


def method_specs(methods=("none", "offset", "raw", "filtered", "mirror"), masks=(5,), stock=0.3,
                 mask_kind="box", edge="renormalize", refine=None):
    """The list of :class:`MethodSpec` for method names; ``filtered`` once per mask size.

    Parameters
    ----------
    methods : iterable of str
        Names from ``SIM_METHODS``.
    masks : iterable of int
        Odd mask sizes of the ``filtered`` method (Werner 2022: 5).
    stock : float
        Semi-finishing allowance (mm) of the ``mirror`` method.
    """
    specs = []
    masks = list(masks)
    if not masks:
        raise InputError("give at least one mask size for the filtered method")
    for m in methods:
        m = m.strip()
        if m not in SIM_METHODS:
            raise InputError("unknown method %r (expected some of %s)"
                             % (m, ", ".join(SIM_METHODS)))
        kw = {} if refine is None else {"refine": int(refine)}
        if m == "none":
            specs.append(MethodSpec("none", "none"))
        elif m == "filtered":
            for k in masks:
                opt = Options(method="filtered", mask_size=int(k), mask_kind=mask_kind, edge=edge,
                              **kw)
                opt.mask()  # validates the size
                specs.append(MethodSpec("filtered %dx%d" % (k, k) if len(masks) > 1 or k != 5
                                        else "filtered", "filtered", opt))
        elif m == "mirror":
            if stock is None or not np.isfinite(stock) or stock < 0:
                raise InputError("the mirror method needs a stock >= 0 mm, got %r" % (stock,))
            specs.append(MethodSpec("mirror", "mirror",
                                    Options(method="mirror", stock=float(stock),
                                            mask_kind=mask_kind, edge=edge, **kw)))
        else:
            specs.append(MethodSpec(m, m, Options(method=m, mask_kind=mask_kind, edge=edge, **kw)))
    labels = [s.label for s in specs]
    if len(set(labels)) != len(labels):
        raise InputError("a method is listed twice: %s" % ", ".join(labels))
    return specs


# ---------------------------------------------------------------------- the loop
@dataclass
class GridMeasurements:
    """A measurement set built in memory, with the attributes of
    :class:`surfcomp.io.measurements.MeasurementSet` that :func:`pipeline.prepare` reads
    (core does not import io): nominal points and outward normals (N, 3), deviations
    (N,), grid indices ``row``/``col`` (N,)."""

    nominal: np.ndarray
    normal: np.ndarray
    deviation: np.ndarray
    row: np.ndarray
    col: np.ndarray
    measured: np.ndarray = None
    source: str = "<simulated measurement>"
    warnings: list = field(default_factory=list)
    lines: np.ndarray = None

    def __post_init__(self):
        if self.lines is None:
            self.lines = np.arange(1, len(self.nominal) + 1, dtype=np.int64)

    def __len__(self):
        return len(self.lines)


@dataclass
class Layout:
    """Measurement grid (n, m) and the denser evaluation grid over the same area.

    ``us``/``vs`` are the evaluation parameters; grid nodes are every ``between``-th.
    """

    grid: tuple
    between: int
    us: np.ndarray
    vs: np.ndarray

    @property
    def eval_shape(self):
        return (self.us.size, self.vs.size)

    def node_mask(self):
        """Bool (Ne, Me): evaluation points that are measurement-grid nodes."""
        mask = np.zeros(self.eval_shape, dtype=bool)
        mask[::self.between, ::self.between] = True
        return mask


def make_layout(surface, grid=(45, 45), margin=0.02, between=2):
    """Parameter grid of the measurement (``margin`` of the range left at each border)."""
    n, m = (int(g) for g in grid)
    if n < 3 or m < 3:
        raise InputError("the simulated grid needs at least 3 x 3 points, got %d x %d" % (n, m))
    if int(between) != between or between < 1:
        raise InputError("between must be a whole number >= 1, got %r" % (between,))
    if not 0 <= margin < 0.5:
        raise InputError("margin must be in [0, 0.5), got %r" % (margin,))
    (u0, u1), (v0, v1) = surface.u_range, surface.v_range
    us = u0 + (u1 - u0) * np.linspace(margin, 1 - margin, between * (n - 1) + 1)
    vs = v0 + (v1 - v0) * np.linspace(margin, 1 - margin, between * (m - 1) + 1)
    return Layout(grid=(n, m), between=int(between), us=us, vs=vs)


def machine(model, frame, surface, outward, us, vs, rng, offset=0.0):
    """Machine ``surface`` (given to CAM) and return the machined points on the grid us x vs.

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
        Distance (mm) the CAM surface lies outside ``surface`` along its normal (the
        mirror method's semi-finishing stock).

    Returns
    -------
    ndarray, shape (Ne, Me, 3)
        ``S_g + offset n + (e_sys + e_rand) n`` (mm).
    """
    S, Su, Sv = bspline.evaluate_grid(surface, us, vs, order=1)
    n = np.cross(Su, Sv)
    n *= outward / np.linalg.norm(n, axis=-1, keepdims=True)
    G = (S + offset * n).reshape(-1, 3)
    nn = n.reshape(-1, 3)
    e = model.systematic(frame, G, nn) + model.random(frame, G, rng)
    return (G + e[:, None] * nn).reshape(S.shape)


def measure(projector, outward, points, rng, probe_sigma=0.0):
    """Signed distances (mm) of points from the nominal along its outward normal, plus probe noise.

    Parameters
    ----------
    projector : surfcomp.core.projection.Projector
        Of the nominal.
    points : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (...)
    """
    P = np.asarray(points, dtype=float)
    proj = projector.project(P.reshape(-1, 3))
    d = proj.distance * outward
    if probe_sigma:
        d = d + rng.normal(0.0, probe_sigma, d.shape)
    return d.reshape(P.shape[:-1])


def _stats3(d, nodes):
    return {"all": statistics(d), "grid": statistics(d[nodes]), "between": statistics(d[~nodes])
            if np.any(~nodes) else statistics(d[nodes])}


def _rng(seed, replica, stream):
    key = stream if isinstance(stream, int) else zlib.crc32(stream.encode("utf-8"))
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(replica), key]))


def simulate(surface, outward, model=None, grid=(45, 45), specs=None, replicas=4, seed=0,
             margin=0.02, between=2, keep=False, progress=None):
    """Run the virtual machining loop (module docstring) for every method and replica.

    Parameters
    ----------
    surface : bspline.Surface
        Nominal face (work area ``u_range`` x ``v_range``).
    outward : {1, -1}
    model : MachiningModel
    grid : (int, int)
        Measurement grid n x m (uniform in the face parameters, ``margin`` from the border).
    specs : list of MethodSpec
        Default :func:`method_specs` () (none, offset, raw, filtered 5x5, mirror 0.3 mm).
    replicas : int
        Parts machined per method (the mirror paper: 4).
    seed : int
    between : int
        The evaluation grid is ``between`` times denser than the measurement grid.
    keep : bool
        Keep the first replica's maps (``SimulationResult.maps[label]``: ``'measured'``
        (n, m) deviations the compensation used, ``'correction'`` (n, m), ``'after'``
        (Ne, Me) the corrected part's deviations; ``maps['before']['after']`` the first
        machining) and :class:`~surfcomp.core.pipeline.Compensation` objects
        (``SimulationResult.compensations[label]``) for reports.

    Returns
    -------
    SimulationResult
    """
    model = model or MachiningModel()
    specs = method_specs() if specs is None else list(specs)
    if int(replicas) != replicas or replicas < 1:
        raise InputError("replicas must be a whole number >= 1, got %r" % (replicas,))
    layout = make_layout(surface, grid, margin, between)
    frame = model.frame(surface)
    projector = Projector(surface)
    nodes = layout.node_mask()
    b = layout.between
    n, m = layout.grid
    # the measurement set's nominal points and normals on the grid (fixed for all parts)
    S, Su, Sv = bspline.evaluate_grid(surface, layout.us[::b], layout.vs[::b], order=1)
    nrm = np.cross(Su, Sv)
    nrm *= outward / np.linalg.norm(nrm, axis=-1, keepdims=True)
    rows, cols = np.indices((n, m))
    ms = GridMeasurements(nominal=S.reshape(-1, 3), normal=nrm.reshape(-1, 3),
                          deviation=np.zeros(n * m), row=rows.ravel(), col=cols.ravel())
    prepared = prepare(surface, outward, ms, Options(max_offset=100.0))
    result = SimulationResult(model=model, specs=specs, grid=(n, m), eval_shape=layout.eval_shape,
                              between=b, margin=margin, replicas=int(replicas), seed=int(seed))
    steps = replicas * (1 + len(specs))
    k = 0
    for r in range(replicas):
        report(progress, k / steps, "replica %d: machining the nominal" % (r + 1))
        rng = _rng(seed, r, 0)
        first = measure(projector, outward,
                        machine(model, frame, surface, outward, layout.us, layout.vs, rng),
                        rng, model.probe_sigma)
        result.before.append(_stats3(first, nodes))
        k += 1
        for spec in specs:
            report(progress, k / steps, "replica %d: %s" % (r + 1, spec.label))
            rng = _rng(seed, r, spec.label)
            if spec.method == "none":
                given = surface
                d_grid = first[::b, ::b]
                delta = np.zeros((n, m))
            else:
                if spec.method == "mirror":
                    semi = measure(projector, outward,
                                   machine(model, frame, surface, outward, layout.us[::b],
                                           layout.vs[::b], rng, offset=spec.options.stock),
                                   rng, model.probe_sigma)
                    result.semi_finish.setdefault(spec.label, []).append(statistics(semi))
                    d_grid = semi
                else:
                    d_grid = first[::b, ::b]
                prep = replace(prepared, deviation=_file_order(prepared, d_grid))
                comp = compensate(surface, outward, prep, spec.options,
                                  progress=sub(progress, k / steps, (k + 0.9) / steps))
                given = comp.corrected
                delta = comp.correction.delta
                result.checks.setdefault(spec.label, []).append(comp.checks.max_error_at_points)
            after = measure(projector, outward,
                            machine(model, frame, given, outward, layout.us, layout.vs, rng),
                            rng, model.probe_sigma)
            result.after.setdefault(spec.label, []).append(_stats3(after, nodes))
            if keep and r == 0:
                result.maps[spec.label] = {"measured": d_grid, "correction": delta, "after": after}
                if spec.method != "none":
                    result.compensations[spec.label] = comp
            k += 1
        if keep and r == 0:
            result.maps["before"] = {"after": first}
    report(progress, 1.0, "done")
    return result


def _file_order(prepared, grid_values):
    """Grid (n, m) values back in the measurement set's point order (N,)."""
    out = np.empty(prepared.u.size)
    out[prepared.grid.index.ravel()] = np.asarray(grid_values, dtype=float).ravel()
    return out


# ---------------------------------------------------------------------- results
def spread(stats_list):
    """Spread over replicas of each statistic: ``{key: {mean, min, max, range, std}}`` (mm).

    ``std`` over replicas uses ddof=1 (0 for one replica).
    """
    out = {}
    for key in STAT_KEYS:
        a = np.array([getattr(s, key) for s in stats_list], dtype=float)
        out[key] = {"mean": float(a.mean()), "min": float(a.min()), "max": float(a.max()),
                    "range": float(np.ptp(a)), "std": float(a.std(ddof=1)) if a.size > 1 else 0.0}
    return out


@dataclass
class SimulationResult:
    """Statistics of every replica: ``before`` (the nominal machined, list over replicas)
    and ``after[label]`` (the corrected face machined), each a dict ``{'all', 'grid',
    'between'}`` of :class:`~surfcomp.core.deviations.Statistics` over all evaluation
    points, the grid nodes only, and the points between them. ``semi_finish[label]``:
    the mirror method's semi-finished part (includes the stock); ``checks[label]``: the
    corrected faces' max |realised - intended| at the grid nodes (mm)."""

    model: MachiningModel
    specs: list
    grid: tuple
    eval_shape: tuple
    between: int
    margin: float
    replicas: int
    seed: int
    before: list = field(default_factory=list)
    after: dict = field(default_factory=dict)
    semi_finish: dict = field(default_factory=dict)
    checks: dict = field(default_factory=dict)
    maps: dict = field(default_factory=dict)
    compensations: dict = field(default_factory=dict)

    @property
    def labels(self):
        return [s.label for s in self.specs]

    def values(self, label, key, where="all"):
        """One statistic of every replica, ndarray (replicas,) in mm; ``label`` may be 'before'."""
        lst = self.before if label == "before" else self.after[label]
        return np.array([getattr(x[where], key) for x in lst])

    def as_dict(self):
        """JSON-able dict (schema ``surfcomp-simulation/1``, mm)."""
        def block(lst):
            return {"replicas": [{w: s.as_dict() for w, s in x.items()} for x in lst],
                    "spread": {w: spread([x[w] for x in lst]) for w in ("all", "grid", "between")}}

        methods = []
        for spec in self.specs:
            d = spec.as_dict()
            d.update(block(self.after[spec.label]))
            if spec.label in self.semi_finish:
                d["semi_finish"] = {"replicas": [s.as_dict() for s in self.semi_finish[spec.label]],
                                    "note": "measured before the mirror correction; includes "
                                            "the stock"}
            if spec.label in self.checks:
                d["max_error_at_points_mm"] = [float(x) for x in self.checks[spec.label]]
            methods.append(d)
        return {"schema": SCHEMA, "units": "mm", "statistics_ddof": 1,
                "model": self.model.as_dict(),
                "grid": list(self.grid), "evaluation_grid": list(self.eval_shape),
                "between": self.between, "margin": self.margin,
                "replicas": self.replicas, "seed": self.seed,
                "where": "all = grid nodes and points between them; grid = nodes only; "
                         "between = the points between nodes",
                "before": block(self.before),
                "methods": methods,
                "table": self.table()}

    def table(self, unit="um", where="all"):
        """The papers' table form: per method the replicas' mean and (range) of each statistic."""
        return format_simulation_table(self.as_columns(where), self.replicas, unit)

    def as_columns(self, where="all"):
        """``[(header, [Statistics per replica])]``: 'Before' then every method."""
        cols = [("Before", [x[where] for x in self.before])]
        cols += [(lab, [x[where] for x in self.after[lab]]) for lab in self.labels]
        return cols

    def replica_table(self, key="std", unit="um", where="all"):
        """Every replica's value of one statistic, and the range (mirror paper Tab. 2 form)."""
        f = 1000.0 if unit == "um" else 1.0
        fmt = "%.1f" if unit == "um" else "%.4f"
        lines = ["%s per replica (%s), (range)" % (dict(TABLE_ROWS).get(key, key),
                                                    "µm" if unit == "um" else "mm")]
        for head, lst in self.as_columns(where):
            a = np.array([getattr(s, key) for s in lst]) * f
            lines.append("%-20s %s (%s)" % (head, ", ".join(fmt % x for x in a), fmt % np.ptp(a)))
        return "\n".join(lines)


def format_simulation_table(columns, replicas, unit="um"):
    """Format ``[(header, [Statistics per replica])]`` as rows of ``mean (range)``.

    Returns
    -------
    str
        Rows Max. negative, Max. positive, Average value, Standard deviation, Profile
        error ISO 1101; every cell the mean over replicas and, in parentheses, the range
        (max - min) over them (mirror paper Tab. 2-4 form).
    """
    f = 1000.0 if unit == "um" else 1.0
    fmt = "%.2f (%.2f)" if unit == "um" else "%.4f (%.4f)"
    labels = [lab for _, lab in TABLE_ROWS]
    width = max(len(s) for s in labels) + 2
    cells = [[fmt % (np.mean([getattr(s, key) for s in lst]) * f,
                     np.ptp([getattr(s, key) for s in lst]) * f) for key, _ in TABLE_ROWS]
             for _, lst in columns]
    colw = max(14, max(len(h) for h, _ in columns) + 2,
               max(len(c) for col in cells for c in col) + 2)
    out = ["Simulated machining, %d replica(s): mean (range) over replicas, %s"
           % (replicas, "µm" if unit == "um" else "mm"),
           "Deviations".ljust(width) + "".join(h.rjust(colw) for h, _ in columns)]
    for k, lab in enumerate(labels):
        out.append(lab.ljust(width) + "".join(col[k].rjust(colw) for col in cells))
    return "\n".join(out)


def statistics_from_dict(d):
    """Inverse of ``Statistics.as_dict`` (for readers of the JSON)."""
    return Statistics(**{k: d[k] for k in STAT_KEYS})
