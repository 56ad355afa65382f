# SPDX-License-Identifier: LGPL-2.1-or-later
"""Virtual machining: see what a compensation does before cutting metal (no FreeCAD).

The loop of the papers (Werner 2022 Tab. 1-5; mirror paper 2019 Tab. 2-4, 4 replicas),
for every compensation method and replica, with the machining-process model of
:mod:`surfcomp.core.simulation.process_model` (a semi-finishing and a finishing pass per part):

1. machine a part from the nominal and measure it on the n x m grid (probe noise
   added); the mirror method instead measures its own part after the semi-finishing
   pass (the nominal offset outward by the stock), as the mirror paper does on the
   machine;
2. compensate with :func:`surfcomp.core.compensation.pipeline.compensate` (a
   :class:`~surfcomp.core.measurement_set.MeasurementSet` built in memory);
3. machine a part from the corrected surface with the same model (new random
   realisations; the mirror method finishes the part it measured, whose semi-finished
   error sets the finishing pass's engagement);
4. measure it against the nominal, at the grid nodes and between them (a grid
   ``between`` times denser over the same area), as signed distances along the
   nominal's outward normal (projection engine, :mod:`surfcomp.core.surface.projection`).

Random streams are seeded per (seed, replica, pass) so a method's result does not
depend on which other methods run. Without a deflection term the semi-finishing pass of
the parts that are measured finished has no effect on them and is not machined.
"""

import zlib
from dataclasses import dataclass, field, replace

import numpy as np

from ...errors import InputError
from .. import limits
from ..compensation.deviations import statistics
from ..compensation.methods import METHODS
from ..compensation.pipeline import Options, compensate, prepare
from ..progress import report, sub
from ..surface import bspline
from ..surface.projection import Projector
from .process_model import (  # noqa: F401 (the simulation's public names)
    DEFAULT_STOCK,
    MAX_LATTICE,
    MAX_SLOPE,
    Frame,
    MachiningModel,
    cam_grid,
    correlated_field,
    machine,
    machine_pass,
)
from .process_model import SUMMARY as MODEL_SUMMARY
from .sim_points import file_order, measurement_set
from .sim_tables import (  # noqa: F401
    STAT_KEYS,
    TABLE_ROWS,
    format_side_by_side,
    format_simulation_table,
    side_by_side,
    side_values,
    spread,
)

#: method names of the simulation (``none`` = no compensation)
SIM_METHODS = ("none",) + METHODS
#: schema name of :meth:`SimulationResult.as_dict`
SCHEMA = "surfcomp-simulation/1"
#: largest measurement grid per direction and most replicas (:mod:`surfcomp.core.limits`)
MAX_GRID = limits.MAX_GRID
MAX_REPLICAS = limits.MAX_REPLICAS
#: largest evaluation grid per direction (the largest grid with the default between = 2)
MAX_EVAL_GRID = 2 * (MAX_GRID - 1) + 1


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


def method_specs(methods=("none", "offset", "raw", "filtered", "mirror"), masks=(5,), stock=None,
                 mask_kind="box", edge="renormalize", refine=None):
    """The list of :class:`MethodSpec` for method names; ``filtered`` once per mask size.

    Parameters
    ----------
    methods : iterable of str
        Names from ``SIM_METHODS``.
    masks : iterable of int
        Odd mask sizes of the ``filtered`` method (Werner 2022: 5).
    stock : float, optional
        Semi-finishing allowance (mm) the ``mirror`` method assumes (DH = stock / 2);
        None: the machining model's stock, filled in by :func:`simulate`.
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
            if stock is not None and not (np.isfinite(stock) and stock >= 0):
                raise InputError("the mirror method needs a stock >= 0 mm, got %r" % (stock,))
            specs.append(MethodSpec("mirror", "mirror",
                                    # the simulated part carries its stock by construction
                                    Options(method="mirror", accept_stock=True,
                                            stock=None if stock is None else float(stock),
                                            mask_kind=mask_kind, edge=edge, **kw)))
        else:
            specs.append(MethodSpec(m, m, Options(method=m, mask_kind=mask_kind, edge=edge, **kw)))
    labels = [s.label for s in specs]
    if len(set(labels)) != len(labels):
        raise InputError("a method is listed twice: %s" % ", ".join(labels))
    return specs


# ---------------------------------------------------------------------- the loop
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
    if n > MAX_GRID or m > MAX_GRID:
        raise InputError("the simulated grid takes at most %d x %d points, got %d x %d"
                         % (MAX_GRID, MAX_GRID, n, m))
    if int(between) != between or between < 1:
        raise InputError("between must be a whole number >= 1, got %r" % (between,))
    size = (between * (n - 1) + 1, between * (m - 1) + 1)
    if max(size) > MAX_EVAL_GRID:
        raise InputError("between %d: the evaluation grid would have %d x %d points (expected "
                         "at most %d per direction)" % ((between,) + size + (MAX_EVAL_GRID,)),
                         options=("between",))
    if not 0 <= margin < 0.5:
        raise InputError("margin must be in [0, 0.5), got %r" % (margin,))
    (u0, u1), (v0, v1) = surface.u_range, surface.v_range
    us = u0 + (u1 - u0) * np.linspace(margin, 1 - margin, between * (n - 1) + 1)
    vs = v0 + (v1 - v0) * np.linspace(margin, 1 - margin, between * (m - 1) + 1)
    return Layout(grid=(n, m), between=int(between), us=us, vs=vs)


def measure(projector, outward, points, rng, probe_sigma=0.0):
    """Signed distances (mm) of points from the nominal along its outward normal, plus probe noise.

    Parameters
    ----------
    projector : surfcomp.core.surface.projection.Projector
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
    """``{'all', 'grid', 'between'}`` statistics; 'between' None where the evaluation grid
    has no points between its nodes (``between = 1``: the nodes' figures are no
    between-nodes figures)."""
    return {"all": statistics(d), "grid": statistics(d[nodes]),
            "between": statistics(d[~nodes]) if np.any(~nodes) else None}


def _rng(seed, replica, stream):
    key = stream if isinstance(stream, int) else zlib.crc32(stream.encode("utf-8"))
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(replica), key]))


@dataclass
class _Shop:
    """The machine, the nominal and the probe of one simulation: machines and measures parts."""

    model: MachiningModel
    frame: Frame
    surface: object
    outward: int
    layout: Layout
    projector: Projector
    _nominal: tuple = None
    #: (u, v) (P,) of measured points off the grid (a plan), machined with the grid
    probe_uv: tuple = None

    def cam(self, given):
        """CAM points and normals of ``given`` on the evaluation grid (the nominal's kept);
        with ``probe_uv``, flat (Ne * Me + P, 3): the grid's, then the probed points'."""
        if given is self.surface and self._nominal is not None:
            return self._nominal
        S, n = cam_grid(given, self.outward, self.layout.us, self.layout.vs)
        if self.probe_uv is not None:
            Sp, Su, Sv = bspline.derivatives(given, *self.probe_uv, 1)
            npr = np.cross(Su, Sv)
            npr *= self.outward / np.linalg.norm(npr, axis=-1, keepdims=True)
            S, n = np.concatenate([S.reshape(-1, 3), Sp]), np.concatenate([n.reshape(-1, 3), npr])
        if given is self.surface:
            self._nominal = (S, n)
        return S, n

    def split(self, d):
        """Values of a machined part ``(on the evaluation grid (Ne, Me), at the measured
        points)``: the grid nodes (n, m), or the probed points (P,)."""
        if self.probe_uv is None:
            return d, d[::self.layout.between, ::self.layout.between]
        k = self.layout.us.size * self.layout.vs.size
        return d[:k].reshape(self.layout.eval_shape), d[k:]

    def stats(self, d, at, nodes):
        """``{'all', 'grid', 'between'}`` statistics; with probed points 'grid' is theirs."""
        out = _stats3(d, nodes)
        if self.probe_uv is not None:
            out["grid"] = statistics(at)
        return out

    def semi_finish(self, given, rng, cam=None):
        """The semi-finishing pass from ``given``: its points and error ``e_1`` (Ne, Me)."""
        S, n = cam or self.cam(given)
        return machine_pass(self.model, self.frame, S, n, rng, offset=self.model.stock,
                            engagement=self.model.semi_depth)

    def finish(self, given, rng, e_semi=None, semi_rng=None):
        """Finish a part from ``given`` and measure it on the evaluation grid (Ne, Me) (mm).

        The finishing pass removes ``stock + e_semi``; without ``e_semi`` the part's
        semi-finishing pass is machined from ``given`` with ``semi_rng`` first (only
        when the model deflects: otherwise the engagement does not matter).
        """
        cam = self.cam(given)
        if e_semi is None and self.model.deflects:
            e_semi = self.semi_finish(given, semi_rng, cam)[1]
        a = None if e_semi is None else self.model.stock + e_semi
        M = machine_pass(self.model, self.frame, cam[0], cam[1], rng, engagement=a)[0]
        return measure(self.projector, self.outward, M, rng, self.model.probe_sigma)

    def measure_nodes(self, points, rng):
        """Measure machined ``points`` at the grid nodes, or at the probed points."""
        if self.probe_uv is None:
            at = points[::self.layout.between, ::self.layout.between]
        else:
            at = points[self.layout.us.size * self.layout.vs.size:]
        return measure(self.projector, self.outward, at, rng, self.model.probe_sigma)


def _with_stock(spec, stock):
    """The mirror method assumes the model's stock unless it was given one."""
    if spec.method == "mirror" and spec.options.stock is None:
        return replace(spec, options=replace(spec.options, stock=float(stock)))
    return spec


def simulate(surface, outward, model=None, grid=(45, 45), specs=None, replicas=4, seed=0,
             margin=0.02, between=2, keep=False, progress=None, points=None, aligner=None):
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
        Default :func:`method_specs` () (none, offset, raw, filtered 5x5, mirror with
        the model's stock).
    replicas : int
        Parts machined per method (the mirror paper: 4).
    seed : int
        >= 0.
    between : int
        The evaluation grid is ``between`` times denser than the measurement grid.
    keep : bool
        Keep the first replica's maps (``SimulationResult.maps[label]``: ``'measured'``
        (n, m) deviations the compensation used, ``'correction'`` (n, m), ``'after'``
        (Ne, Me) the corrected part's deviations; ``maps['before']['after']`` the first
        machining), the evaluation grid's nominal points (``SimulationResult.points``,
        (Ne, Me, 3)) and :class:`~surfcomp.core.compensation.pipeline.Compensation` objects
        (``SimulationResult.compensations[label]``) for reports.
    points : ndarray (P, 3), optional
        Measure at these nominal points (a measurement plan, in its order) instead of the
        grid nodes, compensated as ``compensate --layout auto`` would (a grid when they form
        one, else a scattered layout); ``grid`` then sets the evaluation
        grid only, and the statistics' ``'grid'`` are those at the points. (Not with
        ``keep``.)
    aligner : callable, optional
        ``aligner(label, nominal (P, 3), normals (P, 3), deviations)``: the deviations a
        compensation uses after the measured points were aligned (same shape as given; the
        points are ``nominal + deviation * normal``, :mod:`surfcomp.core.simulation.sim_align`).

    Returns
    -------
    SimulationResult
    """
    model = model or MachiningModel()
    specs = [_with_stock(s, model.stock) for s in (method_specs() if specs is None else specs)]
    if int(replicas) != replicas or not 1 <= replicas <= MAX_REPLICAS:
        raise InputError("replicas must be a whole number from 1 to %d, got %r"
                         % (MAX_REPLICAS, replicas))
    if int(seed) != seed or seed < 0:
        raise InputError("the seed must be a whole number >= 0, got %r" % (seed,))
    if points is not None and keep:
        raise InputError("the maps of a simulation need the grid: measure on the grid, or "
                         "give no report")
    layout = make_layout(surface, grid, margin, between)
    shop = _Shop(model, model.frame(surface), surface, outward, layout, Projector(surface))
    nodes = layout.node_mask()
    b = layout.between
    ms = measurement_set(surface, outward, layout, points)
    # a plan's points take the layout compensate would give them (a grid when they form
    # one whose map covers the face, else the scattered route), as a measured plan's do
    prepared = prepare(surface, outward, ms, Options(max_offset=100.0, layout="auto"))
    nrm = ms.normal
    if points is not None:
        shop.probe_uv = (prepared.u, prepared.v)
    n, m = layout.grid
    result = SimulationResult(model=model, specs=specs, grid=(n, m), eval_shape=layout.eval_shape,
                              between=b, margin=margin, replicas=int(replicas), seed=int(seed),
                              noise_floor=model.noise_floor(nrm.reshape(-1, 3)),
                              probed=None if points is None else len(prepared.u))
    steps = replicas * (1 + len(specs))
    k = 0
    for r in range(replicas):
        report(progress, k / steps, "replica %d: machining the nominal" % (r + 1))
        first, first_at = shop.split(shop.finish(surface, _rng(seed, r, 0),
                                                 semi_rng=_rng(seed, r, "semi")))
        result.before.append(shop.stats(first, first_at, nodes))
        k += 1
        for spec in specs:
            report(progress, k / steps, "replica %d: %s" % (r + 1, spec.label))
            rng = _rng(seed, r, spec.label)
            e_semi, comp = None, None
            if spec.method == "none":
                given, d_grid, delta = surface, first_at, np.zeros(first_at.shape)
            else:
                if spec.method == "mirror":
                    # on the machine: the part's own semi-finished surface, stock included
                    M, e_semi = shop.semi_finish(surface, rng)
                    d_grid = shop.measure_nodes(M, rng)
                    result.add_semi(spec.label, d_grid, model.stock)
                else:
                    d_grid = first_at
                if aligner is not None:
                    d_grid = aligner(spec.label, ms.nominal, ms.normal, d_grid)
                prep = replace(prepared, deviation=d_grid if points is not None
                               else file_order(prepared, d_grid))
                comp = compensate(surface, outward, prep, spec.options,
                                  progress=sub(progress, k / steps, (k + 0.9) / steps))
                given, delta = comp.corrected, comp.correction.delta
                result.checks.setdefault(spec.label, []).append(comp.checks.max_error_at_points)
            after, after_at = shop.split(shop.finish(given, rng, e_semi,
                                                     semi_rng=_rng(seed, r, "semi " + spec.label)))
            result.after.setdefault(spec.label, []).append(shop.stats(after, after_at, nodes))
            if keep and r == 0:
                result.maps[spec.label] = {"measured": d_grid, "correction": delta, "after": after}
                if comp is not None:
                    result.compensations[spec.label] = comp
            k += 1
        if keep and r == 0:
            result.maps["before"] = {"after": first}
            result.points = bspline.evaluate_grid(surface, layout.us, layout.vs)
    report(progress, 1.0, "done")
    return result


# ---------------------------------------------------------------------- results
@dataclass
class SimulationResult:
    """Statistics of every replica: ``before`` (the nominal machined, list over replicas)
    and ``after[label]`` (the corrected face machined), each a dict ``{'all', 'grid',
    'between'}`` of :class:`~surfcomp.core.compensation.deviations.Statistics` over all evaluation
    points, the grid nodes only, and the points between them. ``semi_finish[label]``:
    the mirror method's semi-finished part measured at the grid nodes (includes the
    stock), ``semi_error[label]`` the same minus the stock; ``checks[label]``: the
    corrected faces' max |realised - intended| at the grid nodes (mm); ``noise_floor``
    the std (mm) a perfect compensation would leave
    (:meth:`MachiningModel.noise_floor` at the grid nodes); ``preset`` the
    :class:`surfcomp.core.simulation.presets.Preset` the run imitates, if any."""

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
    noise_floor: float = None
    semi_error: dict = field(default_factory=dict)
    points: object = None
    preset: object = None
    #: the plan's points measured instead of the grid nodes (None: the nodes)
    probed: int = None

    @property
    def labels(self):
        return [s.label for s in self.specs]

    def add_semi(self, label, d_grid, stock):
        """Record a mirror part's semi-finished measurement (n, m) (mm, stock included)."""
        self.semi_finish.setdefault(label, []).append(statistics(d_grid))
        self.semi_error.setdefault(label, []).append(statistics(np.asarray(d_grid) - stock))

    def side_rows(self, where="grid"):
        """``method -> (label, side_values)`` for the side-by-side table (mm).

        The first column of each method (for ``filtered`` the 5x5 mask if it ran, as
        Werner 2022), and ``semi-finished``: the mirror method's semi-finished parts
        minus the stock (always at the grid nodes, where they are measured).
        """
        rows = {}
        for spec in self.specs:
            mine = spec.method == "filtered" and spec.options.mask().shape[0] == 5
            if spec.method not in rows or mine:
                lst = [x[where] for x in self.after[spec.label]]
                rows[spec.method] = (spec.label, side_values(lst))
            if spec.label in self.semi_error and "semi-finished" not in rows:
                rows["semi-finished"] = ("semi-finished (%s)" % spec.label,
                                         side_values(self.semi_error[spec.label]))
        return rows

    def side_by_side(self, paper=None, where="grid"):
        """The paper's table beside the simulated one (:func:`sim_tables.side_by_side`);
        ``paper`` defaults to the preset's."""
        paper = paper if paper is not None else self.preset.paper
        out = side_by_side(self.side_rows(where), paper)
        out["where"] = where
        return out

    def side_table(self, paper=None, where="grid"):
        """:meth:`side_by_side` as text (um)."""
        name = "preset %s (%s)" % (self.preset.name, self.preset.imitates) if self.preset else ""
        # 'grid' statistics are at the measured points: the plan's when it was measured
        count = ("%d x %d" % self.eval_shape if where != "grid" else self.probed
                 if self.probed is not None else self.grid[0] * self.grid[1])
        detail = ("Simulated: %d replica(s) x %s points (%s); mean and std pooled over the "
                  "replicas, max, min and ISO 1101 averaged over them; noise floor %.2f um"
                  % (self.replicas, count, "the measured points" if where == "grid" else where,
                     (self.noise_floor or 0.0) * 1e3))
        return format_side_by_side(self.side_by_side(paper, where),
                                   "Paper vs simulated: %s" % name, detail)

    def values(self, label, key, where="all"):
        """One statistic of every replica, ndarray (replicas,) in mm; ``label`` may be 'before'."""
        lst = self.before if label == "before" else self.after[label]
        return np.array([getattr(x[where], key) for x in lst])

    def as_dict(self):
        """JSON-able dict (schema ``surfcomp-simulation/1``, mm)."""
        def block(lst):
            return {"replicas": [{w: None if s is None else s.as_dict() for w, s in x.items()}
                                 for x in lst],
                    "spread": {w: None if any(x[w] is None for x in lst) else
                               spread([x[w] for x in lst]) for w in ("all", "grid", "between")}}

        methods = []
        for spec in self.specs:
            d = spec.as_dict()
            d.update(block(self.after[spec.label]))
            if spec.label in self.semi_finish:
                d["semi_finish"] = {"replicas": [s.as_dict() for s in self.semi_finish[spec.label]],
                                    "note": "measured before the mirror correction; includes "
                                            "the stock",
                                    "error_replicas": [s.as_dict()
                                                       for s in self.semi_error[spec.label]],
                                    "error_note": "the same minus the model's stock"}
            if spec.label in self.checks:
                d["max_error_at_points_mm"] = [float(x) for x in self.checks[spec.label]]
            methods.append(d)
        out = {"schema": SCHEMA, "units": "mm", "statistics_ddof": 1,
               "model": self.model.as_dict(),
               "grid": list(self.grid), "evaluation_grid": list(self.eval_shape),
               "between": self.between, "margin": self.margin,
               "replicas": self.replicas, "seed": self.seed,
               "where": ("all = grid nodes and points between them; grid = nodes only; "
                         "between = the points between nodes" if self.probed is None else
                         "all = the evaluation grid's points; grid = the %d probed points of "
                         "the plan; between = the evaluation grid's points between its nodes"
                         % self.probed) + ("" if self.between > 1 else " (none: between = 1)"),
               "probed_points": self.probed,
               "before": block(self.before),
               "methods": methods,
               "table": self.table(),
               "noise_floor_mm": self.noise_floor,
               "model_summary": dict(MODEL_SUMMARY)}
        if self.preset is not None:
            out["preset"] = self.preset.as_dict()
            out["paper"] = self.preset.paper.as_dict()
            out["side_by_side"] = dict(self.side_by_side(), table=self.side_table())
        return out

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
