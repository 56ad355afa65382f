"""Queries on a computed compensation object: its node values and C1 fields per quantity
(the one source of the GUI's colour maps and the reports), the corrected surface, and the
JSON/HTML reports as the command line writes them.
"""

import numpy as np

from ..core.field import GridField
from ..core.scattered import ScatteredField
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
    unmeasured nodes. ``residual`` is ``deviation - increment`` (what this round leaves)."""
    if quantity == "residual":
        return _grid(obj, "Deviation") - _grid(obj, "Increment")
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
    surfcomp.core.field.GridField
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


def report_of(obj):
    """The JSON report (schema ``surfcomp-report/1``, as the CLI writes it) of a
    compensation object, recomputed from its properties and links."""
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
    return report_io.build_report("compensate", inputs, comp, comp.prepared.warnings)


def write_html_report(obj, path):
    """Write the self-contained HTML report of a compensation object (atomically)."""
    from ..io.html_report import write_html_report as write

    return write(path, report_of(obj))


def corrected_surface(obj):
    """The corrected surface of a computed compensation object as a core
    :class:`~surfcomp.core.bspline.Surface` (from its Shape, in document coordinates:
    the feature's Placement applied)."""
    from .convert import surface_from_part

    shape = obj.Shape
    if obj.Output == "solid":
        face = shape.Faces[int(obj.FaceName[4:]) - 1]
    else:
        face = shape.Faces[0]
    u0, u1, v0, v1 = face.ParameterRange
    return surface_from_part(face.Surface, (u0, u1), (v0, v1))
