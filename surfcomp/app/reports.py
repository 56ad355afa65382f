# SPDX-License-Identifier: LGPL-2.1-or-later
"""Queries on a computed compensation object: its node values and C1 fields per quantity
(the one source of the GUI's colour maps and the reports), the corrected surface, and the
JSON/HTML reports as the command line writes them.
"""

import hashlib

import numpy as np

from ..core.compensation.field import GridField
from ..core.compensation.methods import predicted_residual
from ..core.compensation.scattered import ScatteredField
from ..errors import InputError

#: quantities of :func:`quantity_values` and :func:`deviation_field`
QUANTITIES = ("deviation", "determined", "random", "correction", "increment", "residual")
#: quantity -> result property
_PROPERTY = {"deviation": "Deviation", "determined": "Determined", "random": "Random",
             "correction": "Correction", "increment": "Increment"}


def _grid(obj, name):
    a = np.asarray(getattr(obj, name), dtype=float)
    n, m = obj.GridRows, obj.GridCols
    if n * m == 0 or a.size != n * m:
        raise InputError("%s has no computed %s (recompute it first)" % (obj.Label, name))
    return a.reshape(n, m)


def _fill_gaps(values):
    """Unmeasured nodes (NaN) take the value of the nearest measured node."""
    bad = ~np.isfinite(values)
    if not bad.any():
        return values
    if bad.all():
        raise InputError("no measured node to build a field from")
    from scipy import ndimage

    idx = ndimage.distance_transform_edt(bad, return_distances=False, return_indices=True)
    return values[tuple(idx)]


def quantity_values(obj, quantity):
    """Node values (mm) of ``quantity`` on the measurement grid, shape (rows, cols); NaN at
    unmeasured nodes.

    ``residual`` is the predicted residual of this round's correction
    (:func:`surfcomp.core.compensation.methods.predicted_residual`).
    """
    if quantity == "residual":
        return predicted_residual(_grid(obj, "Determined"), _grid(obj, "Increment"),
                                  obj.Method, float(obj.Stock.Value))
    if quantity not in _PROPERTY:
        raise InputError("unknown quantity %r (expected one of %s)"
                         % (quantity, ", ".join(QUANTITIES)))
    return _grid(obj, _PROPERTY[quantity])


def deviation_field(obj, quantity):
    """A C1 field ``f(u, v)`` of a compensation's node values over the face's parameters.

    Parameters
    ----------
    obj : ``SurfComp_Compensation`` (computed)
    quantity : str
        ``deviation``, ``determined``, ``random``, ``correction`` (total, accumulated),
        ``increment`` (this round's correction) or ``residual``
        (``deviation - increment``: what this round leaves uncorrected).

    Returns
    -------
    surfcomp.core.compensation.field.GridField
        Callable on arrays of u, v (face parameters); values in mm. Unmeasured nodes
        take the value of their nearest measured node.
    """
    values = quantity_values(obj, quantity)
    if obj.Scattered:
        from .features import nominal_of

        surf = nominal_of(obj)[0].surface
        return ScatteredField(_grid(obj, "U").ravel(), _grid(obj, "V").ravel(), values.ravel(),
                              scale=tuple(obj.FieldScale), box=(surf.u_range, surf.v_range))
    return GridField(_grid(obj, "U"), _grid(obj, "V"), _fill_gaps(values))


def field_values(obj, quantity, u, v, located=None):
    """``deviation_field(obj, quantity)(u, v)``, reusing where the points lie on the grid.

    ``located`` is a dict the caller keeps with its points ``(u, v)`` (a map's mesh): the
    points' index coordinates on the measurement grid depend only on the nodes' (u, v),
    so they are found once per grid and a refiltered result (the filter panel's preview)
    only evaluates the new values there. Without it this is the field's plain call.
    """
    if obj.Scattered or located is None:
        return deviation_field(obj, quantity)(u, v)
    U, V = _grid(obj, "U"), _grid(obj, "V")
    field = GridField(U, V, _fill_gaps(quantity_values(obj, quantity)))
    key = (np.shape(u), hashlib.sha1(U.tobytes() + V.tobytes()).hexdigest())
    if located.get("key") != key:
        located.clear()
        located["st"] = field.locate(u, v)
        located["key"] = key
    return field.at_index(*located["st"]).reshape(np.shape(u))


def report_of(obj):
    """The JSON report (schema ``surfcomp-report/1``, as the CLI writes it) of a
    compensation object, recomputed from its properties and links; an iteration's points
    also carry this round's own correction (``increment``, mm)."""
    from ..io import report as report_io
    from .features import compensation_result, nominal_of

    comp = compensation_result(obj)
    nominal = nominal_of(obj)[0]
    m = obj.Measurement
    inputs = {
        "nominal": {"path": obj.Document.FileName or obj.Document.Name,
                    "object": obj.Nominal.Label, "face": obj.FaceName,
                    "poles": list(nominal.surface.shape),
                    "degree": [nominal.surface.degree_u, nominal.surface.degree_v],
                    "rational": nominal.surface.weights is not None},
        "measurements": {"path": m.SourceName, "sha256": m.SourceSha256, "units": m.Units,
                         "points": int(m.PointCount), "object": m.Label},
    }
    rep = report_io.build_report("compensate", inputs, comp, comp.prepared.warnings)
    if obj.Base is not None:
        # an iteration: the report's correction is the accumulated one; the predicted
        # residual is what this round's own correction leaves (quantity_values)
        inc = np.empty(comp.prepared.u.size)
        inc[comp.prepared.grid.index.ravel()] = _grid(obj, "Increment").ravel()
        rep["points"]["increment"] = inc
    return rep


def write_html_report(obj, path, style=None):
    """Write the self-contained HTML report of a compensation object (atomically);
    ``style`` (``scheme``, ``range``) as :func:`surfcomp.io.html_report.render_html`."""
    from ..io.html_report import write_html_report as write

    return write(path, report_of(obj), style=style)


def corrected_surface(obj):
    """The corrected surface of a computed compensation object as a core
    :class:`~surfcomp.core.surface.bspline.Surface` (from its Shape, in document coordinates:
    the feature's Placement applied)."""
    from .convert import surface_from_part

    shape = obj.Shape
    if obj.Output == "solid":
        face = shape.Faces[int(obj.FaceName[4:]) - 1]
    else:
        face = shape.Faces[0]
    u0, u1, v0, v1 = face.ParameterRange
    return surface_from_part(face.Surface, (u0, u1), (v0, v1))


def rms(values):
    """Root mean square of the finite values (mm), NaN when there is none."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v ** 2))) if v.size else float("nan")


def filter_summary(obj):
    """What the filter panel shows of a computed compensation (mm): RMS of the
    determined and random components, of the predicted residual (see
    :func:`quantity_values`), and the expected RMS of the next part, the residual plus a
    new random scatter like this one: ``sqrt(rms(residual)^2 + rms(random)^2)``."""
    out = {q: rms(quantity_values(obj, q)) for q in ("deviation", "determined", "random",
                                                      "residual")}
    out["next_part"] = float(np.hypot(out["residual"], out["random"]))
    return out


def common_range(objs, quantities=("deviation", "determined", "random", "correction")):
    """One symmetric colour range (mm) over the node values of ``quantities`` of the
    computed compensations ``objs`` (the maps of one measurement side by side)."""
    from ..core.colormap import symmetric_range

    values = []
    for obj in objs:
        for q in quantities:
            try:
                values.append(quantity_values(obj, q).ravel())
            except InputError:
                continue            # not computed: no values to share
    return symmetric_range(np.concatenate(values) if values else [])


class PointLocator:
    """The measured node nearest to a point on the map, with its values.

    Built once per computed compensation (a KD-tree over the nodes, in the nominal
    object's own coordinates, as the map is drawn); :meth:`at` answers the readout.
    """

    def __init__(self, obj):
        from scipy.spatial import cKDTree

        from .features import measurement_set

        self.obj = obj
        nodes = np.asarray(obj.Nodes, dtype=float).reshape(-1, 3)
        dev = np.asarray(obj.Deviation, dtype=float)
        self.keep = np.flatnonzero(np.isfinite(dev))
        self.nodes = nodes
        self.tree = cKDTree(nodes[self.keep])
        # every quantity a map shows: a flag on the increment or residual map gives its own
        # value, not the deviation
        self.values = {q: quantity_values(obj, q).ravel() for q in QUANTITIES}
        self.ids = self._ids(measurement_set(obj.Measurement), cKDTree)

    def _ids(self, ms, tree_type):
        """Name (or file line) of the measured point at every node."""
        base = ms.nominal if ms.nominal is not None else ms.measured
        if base is None or not len(base):
            return None
        pl = self.obj.Nominal.Placement if self.obj.Nominal is not None else None
        if pl is not None and not pl.isIdentity():
            m = np.array(pl.inverse().toMatrix().A, dtype=float).reshape(4, 4)
            base = base @ m[:3, :3].T + m[:3, 3]
        k = tree_type(base).query(self.nodes)[1]
        if ms.ids:
            return [ms.ids[i] for i in k]
        lines = ms.lines if ms.lines is not None else np.arange(len(base)) + 1
        return ["line %d" % lines[i] for i in k]

    def at(self, local_point):
        """``dict`` of the nearest measured node to ``local_point`` (nominal object's
        coordinates, mm): ``node``, ``id``, ``xyz`` (document coordinates), ``distance``
        and the node's value of every quantity of :data:`QUANTITIES` (mm)."""
        dist, k = self.tree.query(np.asarray(local_point, dtype=float))
        node = int(self.keep[k])
        return self.node(node, float(dist))

    def node(self, node, distance=0.0):
        xyz = self.nodes[node]
        pl = self.obj.Placement
        import FreeCAD

        world = pl.multVec(FreeCAD.Vector(*map(float, xyz)))
        out = {"node": node, "id": self.ids[node] if self.ids else str(node),
               "xyz": (world.x, world.y, world.z), "local": tuple(map(float, xyz)),
               "distance": distance}
        for q, vals in self.values.items():
            out[q] = float(vals[node])
        return out
