# SPDX-License-Identifier: LGPL-2.1-or-later
"""Document objects of the compensation: a measurement object and the compensation feature.

Both are thin proxies (see docs/architecture.md, "Document objects"): every input and
result lives in properties, ``execute`` turns properties into arrays, calls the core
pipeline (:func:`surfcomp.core.compensation.pipeline.prepare` /
:func:`~surfcomp.core.compensation.pipeline.compensate`) and writes the results back. No
FreeCADGui, no PySide: everything recomputes in ``freecadcmd``.

``SurfComp_Measurement`` (``App::FeaturePython``)
    The parsed measurement set kept inside the document (float/int list properties, mm),
    with the source file's name, SHA-256, units and grid shape: the document still opens and
    recomputes when the CSV file has moved or is gone.

``SurfComp_Compensation`` (``Part::FeaturePython``)
    Links the nominal (object + face name) and a measurement object; its ``Shape`` is the
    corrected face, or the nominal's solid with that face replaced (``Output = solid``:
    same number and order of faces, so ``FaceN`` links keep pointing at the right face).

Iterations (Werner 2022: "deviations are always determined in relation to the initial,
nominal model"): a compensation whose ``Base`` is the previous compensation takes a new
measurement of the part machined from the previous corrected face. Its deviations are
computed against the nominal, its own correction (``Increment``) is computed from them
with the chosen method, and the corrections accumulate:
``Correction = Base.Correction (at the new nodes) + Increment``. The corrected surface is
``S(u, v) - Correction(u, v) n(u, v)`` of the nominal ``S``.

The proxy module path ``surfcomp.app.features`` is permanent once documents exist.

Import this module where FreeCAD is importable: inside FreeCAD, or from a plain ``python3``
after :func:`surfcomp.app.fcenv.import_freecad`.
"""

import contextlib
import json
import os
from dataclasses import replace as _dc_replace

import FreeCAD
import numpy as np

from ..core.compensation.deviations import statistics
from ..core.compensation.filters import EDGE_MODES, WERNER_MASK_SIZE
from ..core.compensation.methods import METHODS
from ..core.compensation.pipeline import (
    build_surface,
    compensate,
    parameter_scale,
    prepare,
)
from ..core.options import OPTIONS
from ..core.progress import sub
from ..errors import GeometryError, InputError
from ..io.measurements import MeasurementSet
from ..io.readers import FORMATS, read_any
from . import align_doc, result_cache
from . import preview as preview_cache
from .nominal import face_warnings
from .progress import freecad_progress
from .properties import (
    COMPENSATION_PROPERTIES,
    COMPENSATION_TYPE,
    MEASUREMENT_PROPERTIES,
    MEASUREMENT_TYPE,
    OUTPUTS,
    RENAMED,
    VERSION,
    options_of,
    property_text,
)
from .proxies import Proxy
from .proxies import migrate as _migrate
from .reports import deviation_field
from .shapes import corrected_shape


class _Proxy(Proxy):
    """The features' proxy base (see :class:`surfcomp.app.proxies.Proxy`)."""

    Type = None
    VERSION = VERSION

    def onDocumentRestored(self, obj):
        super().onDocumentRestored(obj)
        _restored(obj)


def migrate(obj, table):
    """Bring an object restored from an older document to the current property set.

    Returns the names of the properties that were added.
    """
    return _migrate(obj, table, VERSION)


# -- measurement object --------------------------------------------------------------------
class MeasurementFeature(_Proxy):
    """Proxy of ``SurfComp_Measurement``: a measurement set stored in the document."""

    Type = MEASUREMENT_TYPE
    PROPERTIES = MEASUREMENT_PROPERTIES

    def execute(self, obj):
        measurement_set(obj)  # checks that the stored lists fit together


def _xyz(obj, names):
    cols = [getattr(obj, n) for n in names]
    if not any(len(c) for c in cols):
        return None
    return np.stack([np.asarray(c, dtype=float) for c in cols], axis=1)


def set_measurement_data(obj, ms):
    """Store a :class:`~surfcomp.io.measurements.MeasurementSet` in a measurement object.

    Every array goes into a list property in mm (the file's units are recorded in
    ``Units``); absent columns leave their lists empty.
    """
    n = next(len(a) for a in (ms.nominal, ms.measured, ms.normal, ms.deviation)
             if a is not None)

    def put(names, arr):
        for k, name in enumerate(names):
            setattr(obj, name, [] if arr is None else np.asarray(arr, float)[:, k].tolist())

    put(("NominalX", "NominalY", "NominalZ"), ms.nominal)
    put(("MeasuredX", "MeasuredY", "MeasuredZ"), ms.measured)
    put(("NormalI", "NormalJ", "NormalK"), ms.normal)
    obj.Deviation = [] if ms.deviation is None else np.asarray(ms.deviation, float).tolist()
    obj.Row = [] if ms.row is None else [int(x) for x in ms.row]
    obj.Col = [] if ms.col is None else [int(x) for x in ms.col]
    obj.GridShape = ([] if ms.row is None or ms.col is None or n == 0 else
                     [int(np.max(ms.row)) + 1, int(np.max(ms.col)) + 1])
    obj.Lines = [int(x) for x in ms.lines]
    obj.Ids = [] if ms.ids is None else [str(x) for x in ms.ids]
    obj.PointFaces = [] if ms.faces is None else [str(x) for x in ms.faces]
    obj.SourceName = os.path.basename(str(ms.source))
    obj.SourceSha256 = ms.sha256 or ""
    obj.Units = ms.units or "mm"
    try:
        obj.Kind = ms.kind()
    except InputError:
        obj.Kind = ""
    obj.Columns = json.dumps(dict(ms.columns or {}), sort_keys=True)
    obj.ReadWarnings = [property_text(w) for w in (ms.warnings or [])]
    obj.PointCount = n


def measurement_set(obj):
    """Rebuild the :class:`~surfcomp.io.measurements.MeasurementSet` from the properties.

    No file access: this is what the compensation uses, so a document keeps working when
    the source file has moved or is gone.

    Raises
    ------
    InputError
        The stored lists do not fit together (a damaged or hand-edited document).
    """
    nominal = _xyz(obj, ("NominalX", "NominalY", "NominalZ"))
    measured = _xyz(obj, ("MeasuredX", "MeasuredY", "MeasuredZ"))
    normal = _xyz(obj, ("NormalI", "NormalJ", "NormalK"))
    dev = np.asarray(obj.Deviation, dtype=float) if len(obj.Deviation) else None
    lists = {"NominalX/Y/Z": nominal, "MeasuredX/Y/Z": measured, "NormalI/J/K": normal,
             "Deviation": dev}
    lengths = {k: len(a) for k, a in lists.items() if a is not None}
    for name in ("Row", "Col", "Lines", "Ids", "PointFaces"):
        if len(getattr(obj, name)):
            lengths[name] = len(getattr(obj, name))
    if not lengths:
        raise InputError("%s holds no measured points" % obj.Label)
    if len(set(lengths.values())) != 1 or obj.PointCount not in lengths.values():
        raise InputError("%s: the stored measurement lists have different lengths (%s; "
                         "PointCount %d): the document is damaged"
                         % (obj.Label, ", ".join("%s %d" % kv for kv in sorted(lengths.items())),
                            obj.PointCount))
    ids = list(obj.Ids) if len(obj.Ids) else None
    lines = np.asarray(obj.Lines, dtype=np.int64) if len(obj.Lines) else None
    row = np.asarray(obj.Row, dtype=np.int64) if len(obj.Row) else None
    col = np.asarray(obj.Col, dtype=np.int64) if len(obj.Col) else None
    return MeasurementSet(nominal=nominal, measured=measured, normal=normal, deviation=dev,
                          row=row, col=col, ids=ids, lines=lines,
                          source=obj.SourceName or obj.Label, sha256=obj.SourceSha256,
                          units=obj.Units, columns=json.loads(obj.Columns or "{}"),
                          warnings=list(obj.ReadWarnings),
                          faces=list(obj.PointFaces) if len(obj.PointFaces) else None)


def make_measurement(doc, path, units="mm", name="Measurement", fmt=None, sample=None,
                     deviation_units=None):
    """Read a measurement file into a new ``SurfComp_Measurement`` object of ``doc``.

    Parameters
    ----------
    doc : FreeCAD document
    path : str
        Any format :func:`surfcomp.io.readers.read_any` reads.
    units : {'mm', 'um', 'in'}
        Units of columns without a unit suffix.
    deviation_units : {'mm', 'um', 'in'}, optional
        Unit of a deviation column without a suffix when it differs from ``units``.
    fmt : str, optional
        One of :data:`surfcomp.io.readers.FORMATS` (default: detected).
    sample : int or str, optional
        Which result of a QIF file holding several.

    Returns
    -------
    The new ``App::FeaturePython`` object (its data is in the document from now on).
    """
    fmt = fmt or "auto"
    if fmt not in FORMATS:
        raise InputError("unknown format %r (expected one of %s)" % (fmt, ", ".join(FORMATS)))
    ms = read_any(os.fspath(path), units=units, fmt=fmt, sample=sample,
                  deviation_units=deviation_units)
    return make_measurement_from_set(doc, ms, name)


def make_measurement_from_set(doc, ms, name="Measurement"):
    """A ``SurfComp_Measurement`` object holding an in-memory measurement set."""
    obj = doc.addObject("App::FeaturePython", name)
    MeasurementFeature(obj)
    set_measurement_data(obj, ms)
    return _created(obj)


#: callables ``hook(obj)`` run on every new surfcomp object: the GUI registers one that
#: gives the object its view provider (app code never imports the GUI), so objects made
#: from the Python console or a macro get their colour map too
NEW_OBJECT_HOOKS = []


def _created(obj):
    for hook in NEW_OBJECT_HOOKS:
        hook(obj)
    return obj


#: callables ``hook(obj)`` run on every surfcomp object restored from a file, while the
#: document is still being opened: the GUI registers one that gives objects of documents
#: made headless their view provider then, so opening such a document does not mark it
#: modified (FreeCAD clears the flag once the restore ends; later changes would set it)
RESTORED_HOOKS = []


def _restored(obj):
    for hook in RESTORED_HOOKS:
        hook(obj)


# -- compensation feature -----------------------------------------------------------------
def is_type(obj, typ):
    """True when ``obj`` is a surfcomp feature of ``typ`` (``MEASUREMENT_TYPE`` ...)."""
    return getattr(getattr(obj, "Proxy", None), "Type", None) == typ


def is_compensation(obj):
    return is_type(obj, COMPENSATION_TYPE)


def is_measurement(obj):
    return is_type(obj, MEASUREMENT_TYPE)


class CompensationFeature(_Proxy):
    """Proxy of ``SurfComp_Compensation`` (see the module docstring)."""

    Type = COMPENSATION_TYPE
    PROPERTIES = COMPENSATION_PROPERTIES
    RENAMED = RENAMED

    def onDocumentRestored(self, obj):
        added = _migrate(obj, self.PROPERTIES, self.VERSION, self.RENAMED)
        if "Lean" in added:     # made before the lean face: recompute to the saved face
            obj.Lean = False
        _restored(obj)

    def execute(self, obj):
        result = _compute(obj)
        _write_results(obj, result)
        align_doc.store(obj, result.alignment)
        if result.shape is None:  # preview: the components changed, the face did not
            return
        # during a recompute Part::Feature gives the Shape the Placement property's value:
        # the feature sits where its nominal sits
        obj.Placement = result.shape.Placement
        obj.Shape = result.shape


#: compensation property -> core option of the filter (the task panel's fields)
FILTER_OPTIONS = {OPTIONS[n].prop: n for n in ("mask_size", "weights", "mask_kind", "edge")}


def check_filter(obj, **values):
    """Check filter values (``MaskSize=``, ``Weights=``, ``MaskKind=``, ``Edge=``) with the
    core's option domains before they are set, so a panel can show the message instead
    of a failed recompute. Returns the mask's size (custom weights set it).

    Raises
    ------
    InputError
        The message of :meth:`surfcomp.core.compensation.pipeline.Options.validate`.
    """
    kw = {}
    for name, value in values.items():
        if name == "Weights":
            value = value.strip() or None
        kw[FILTER_OPTIONS[name]] = value
    options = _dc_replace(options_of(obj), **kw)
    options.validate()
    return int(options.mask().shape[0])


def chain(obj):
    """The compensation and its ``Base`` chain, newest first.

    Raises
    ------
    InputError
        A ``Base`` that is not a compensation, of another nominal face, or a cycle.
    """
    out = [obj]
    seen = {obj.Name}
    base = obj.Base
    while base is not None:
        if not is_compensation(base):
            raise InputError("%s: Base %s is not a surfcomp compensation" % (obj.Label, base.Label))
        if base.Name in seen:
            raise InputError("%s: the Base chain has a cycle at %s" % (obj.Label, base.Label))
        if base.Nominal != obj.Nominal or base.FaceName != obj.FaceName:
            raise InputError("%s: Base %s compensates %s.%s, not %s.%s (iterations must "
                             "compensate the same nominal face)"
                             % (obj.Label, base.Label,
                                getattr(base.Nominal, "Label", None), base.FaceName,
                                getattr(obj.Nominal, "Label", None), obj.FaceName))
        seen.add(base.Name)
        out.append(base)
        base = base.Base
    return out


class _Result:
    """What ``_compute`` returns: the core compensation plus the app-side products
    (``output``: a :class:`surfcomp.app.shapes.Output`, None for a preview)."""

    def __init__(self, comp, nominal, increment, output, round_, alignment=None):
        self.alignment = alignment
        self.comp = comp
        self.nominal = nominal
        self.increment = increment
        self.output = output
        self.shape = None if output is None else output.shape
        self.round = round_


def nominal_of(obj):
    """The :class:`~surfcomp.app.nominal.Nominal` of a compensation object, in the
    nominal object's own coordinates (its Shape without its Placement), and that Placement."""
    if obj.Nominal is None:
        raise InputError("%s has no Nominal (link the object holding the nominal face)"
                         % obj.Label)
    return nominal_in(obj.Nominal, obj.FaceName or None, obj.Label)


def nominal_in(nom_obj, face_name=None, label=None):
    """The :class:`~surfcomp.app.nominal.Nominal` of face ``face_name`` (None: the only
    B-spline face) of a document object, in its own coordinates, and its Placement;
    ``label`` names the asking object in messages."""
    from .face_data import pick_face
    from .nominal import nominal_from_face

    shape = getattr(nom_obj, "Shape", None)
    if shape is None or shape.isNull() or not shape.Faces:
        raise GeometryError("%s: the nominal %s has no faces" % (label or nom_obj.Label,
                                                                nom_obj.Label))
    local = shape.copy()
    placement = local.Placement
    local.Placement = FreeCAD.Placement()
    face, name = pick_face(local, face_name, source=nom_obj.Label)
    nominal = nominal_from_face(face, source=nom_obj.Label, face_name=name,
                                object_name=nom_obj.Name, shape=local)
    return nominal, placement


def local_measurements(ms, placement):
    """The measurement set in the nominal object's own coordinates."""
    if placement.isIdentity():
        return ms
    m = np.array(placement.inverse().toMatrix().A, dtype=float).reshape(4, 4)
    R, t = m[:3, :3], m[:3, 3]
    kw = {}
    for name in ("nominal", "measured"):
        a = getattr(ms, name)
        kw[name] = None if a is None else a @ R.T + t
    kw["normal"] = None if ms.normal is None else ms.normal @ R.T
    return _dc_replace(ms, **kw)


def _compute(obj):
    """Run the pipeline for a compensation object; return a :class:`_Result`."""
    links = chain(obj)
    if obj.Measurement is None or not is_measurement(obj.Measurement):
        raise InputError("%s: Measurement must link a SurfComp_Measurement object" % obj.Label)
    if obj.Output not in OUTPUTS:
        raise InputError("%s: unknown Output %r (expected face or solid)" % (obj.Label, obj.Output))
    nominal, placement = nominal_of(obj)
    ms = local_measurements(measurement_set(obj.Measurement), placement)
    options = options_of(obj)
    ms, alignment = align_doc.aligned(obj.Measurement, nominal, ms, options.tip_radius)
    preview = bool(getattr(obj, "Preview", False))
    if preview:
        return _computed(obj, nominal, placement, ms, options, preview, len(links), alignment)
    # the same inputs give the same result: kept from the last recompute
    return result_cache.result(obj, result_cache.key(obj, nominal, placement, ms, options),
                               lambda: _computed(obj, nominal, placement, ms, options, preview,
                                                 len(links), alignment))


def _computed(obj, nominal, placement, ms, options, preview, rounds, alignment):
    """The :class:`_Result` of :func:`_compute`, computed."""
    base = obj.Base
    # a preview (the filter panel's live maps, a fraction of a second) runs without the
    # progress indicator: it would grab the keyboard and swallow the keys typed meanwhile
    with (contextlib.nullcontext() if preview else
          freecad_progress("%s: compensating" % obj.Label)) as progress:
        prepared, scale = _prepared(obj, nominal, placement, ms, options, preview,
                                    sub(progress, 0.0, 0.3))
        comp = compensate(nominal.surface, nominal.outward, prepared, options,
                          build=base is None and not preview, progress=sub(progress, 0.3, 1.0),
                          scale=scale)
        increment = comp.correction.delta
        if base is not None:
            U, V = prepared.grid.take(prepared.u), prepared.grid.take(prepared.v)
            total = increment + deviation_field(base, "correction")(U, V)
            comp = _build(nominal, prepared, comp, total, build=not preview,
                          progress=sub(progress, 0.3, 1.0))
    if alignment is not None:
        comp.prepared.warnings.extend(alignment.warnings)
    if preview:
        return _Result(comp, nominal, increment, None, rounds, alignment)
    output = corrected_shape(nominal, comp.corrected, obj.Output, obj.Label)
    output.shape.Placement = placement
    comp.prepared.warnings.extend(output.warnings(obj.Label))
    return _Result(comp, nominal, increment, output, rounds, alignment)


def _prepared(obj, nominal, placement, ms, options, preview, progress):
    """``(prepared, parameter scale)``: the points located on the face and arranged on
    their grid, with the trim warning. A preview reuses the ones kept from the previous
    recompute when nothing they depend on changed (:mod:`surfcomp.app.preview`)."""
    def make():
        prep = prepare(nominal.surface, nominal.outward, ms, options, progress=progress)
        return prep, face_warnings(nominal, prep), parameter_scale(nominal.surface, prep)

    if preview:
        key = preview_cache.fingerprint(nominal, placement, ms, options)
        prep, warnings, scale = preview_cache.prepared(obj, key, make)
    else:
        prep, warnings, scale = make()
    prep.warnings.extend(w for w in warnings if w not in prep.warnings)
    return prep, scale


def _build(nominal, prepared, comp, total, build=True, progress=None):
    """Build the corrected surface for an accumulated correction ``total`` (n, m) the
    way :func:`surfcomp.core.compensation.pipeline.compensate` builds it for its own correction."""
    corr = _dc_replace(comp.correction, delta=total)
    comp = _dc_replace(comp, correction=corr)
    comp.statistics = dict(comp.statistics)
    comp.statistics["increment"] = comp.statistics["correction"]
    comp.statistics["correction"] = statistics(total)
    if not build:
        return comp
    return build_surface(comp, nominal.surface, nominal.outward, total, progress=progress)


def _flat(a):
    return np.asarray(a, dtype=float).ravel().tolist()


def _put(obj, name, value):
    """Set a property unless it already holds ``value``: every write notifies the views
    (the property editor, the map), and a preview changes only the filtered components.
    (NaN marks unmeasured nodes: lists equal but for their NaN count as the same.)"""
    old = getattr(obj, name)
    if old == value:
        return
    if isinstance(value, list) and value and isinstance(value[0], float) and \
            len(old) == len(value) and any(x != x for x in value):
        if np.array_equal(np.asarray(old, dtype=float), np.asarray(value), equal_nan=True):
            return
    setattr(obj, name, value)


def _write_results(obj, r):
    comp = r.comp
    p = comp.prepared
    g = p.grid
    n, m = (g.shape[0], 1) if p.scattered else g.shape
    c = comp.correction
    values = {"GridRows": n, "GridCols": m, "Scattered": bool(p.scattered),
              "FieldScale": list(comp.scale) if p.scattered else [],
              "U": _flat(g.take(p.u)), "V": _flat(g.take(p.v)),
              "Nodes": _flat(g.take(p.nominal)), "Normals": _flat(g.take(p.normal)),
              "Deviation": _flat(c.deviation), "Determined": _flat(c.determined),
              "Random": _flat(c.random), "Increment": _flat(r.increment),
              "Correction": _flat(c.delta),
              "Statistics": json.dumps({k: s.as_dict() for k, s in comp.statistics.items()},
                                       sort_keys=True)}
    if comp.checks is not None or not obj.Preview:  # a preview keeps the face's checks
        values["Checks"] = json.dumps(comp.checks.as_dict() if comp.checks else {},
                                      sort_keys=True)
    values["Warnings"] = [property_text(w) for w in p.warnings]
    values["Round"] = r.round
    if r.output is not None:                  # a preview keeps the shape's figures
        values["EdgeTol"] = float(r.output.edge_tolerance)
        values["VolChange"] = float(r.output.volume_change or 0.0)
        values["CorrVol"] = float(r.output.correction_volume)
    for name, value in values.items():
        _put(obj, name, value)


def make_compensation(doc, nominal, face, measurement, method="filtered",
                      mask_size=WERNER_MASK_SIZE, weights="", edge="renormalize", stock=0.0,
                      base=None, name="Compensation", output="face", accept_stock=False):
    """Create a ``SurfComp_Compensation`` feature (recompute the document to compute it).

    Parameters
    ----------
    doc : FreeCAD document
    nominal : document object with a Shape
    face : str
        ``FaceN`` of ``nominal`` (None: the only B-spline face).
    measurement : ``SurfComp_Measurement`` object
    method, mask_size, weights, edge, stock, accept_stock
        As :class:`surfcomp.core.compensation.pipeline.Options` (``stock`` in mm, mirror method;
        ``accept_stock`` uses a stock inconsistent with the measured mean).
    base : ``SurfComp_Compensation``, optional
        The previous round of an iteration.
    output : {'face', 'solid'}

    Returns
    -------
    The new ``Part::FeaturePython`` object.
    """
    if output not in OUTPUTS:
        raise InputError("unknown output %r (expected face or solid)" % (output,))
    if method not in METHODS:
        raise InputError("unknown method %r (expected one of %s)" % (method, ", ".join(METHODS)))
    if edge not in EDGE_MODES:
        raise InputError("unknown edge handling %r (expected one of %s)"
                         % (edge, ", ".join(EDGE_MODES)))
    if not is_measurement(measurement):
        raise InputError("%s is not a surfcomp measurement object" % measurement.Label)
    if base is not None and not is_compensation(base):
        raise InputError("%s is not a surfcomp compensation (expected the previous round)"
                         % base.Label)
    obj = doc.addObject("Part::FeaturePython", name)
    CompensationFeature(obj)
    obj.Nominal = nominal
    obj.FaceName = face or ""
    obj.Measurement = measurement
    obj.Base = base
    obj.Method = method
    obj.MaskSize = int(mask_size)
    obj.Weights = weights or ""
    obj.Edge = edge
    obj.Stock = float(stock or 0.0)
    obj.StockOk = bool(accept_stock)
    obj.Output = output
    if not obj.FaceName:
        from .face_data import pick_face
        obj.FaceName = pick_face(nominal.Shape, None, source=nominal.Label)[1]
    return _created(obj)


def compensation_result(obj):
    """The core :class:`~surfcomp.core.compensation.pipeline.Compensation` of a compensation object,
    computed from its properties and links (nothing is cached on the proxy; the last
    result is reused while those stay the same, :mod:`surfcomp.app.result_cache`).

    For an iteration, ``correction.delta`` is the accumulated correction and
    ``statistics['increment']`` describes this round's own correction.
    """
    return _compute(obj).comp


__all__ = ["VERSION", "MEASUREMENT_TYPE", "COMPENSATION_TYPE", "MeasurementFeature",
           "CompensationFeature", "make_measurement", "make_measurement_from_set",
           "set_measurement_data", "measurement_set", "make_compensation",
           "compensation_result", "options_of", "chain", "migrate", "is_compensation",
           "is_measurement", "nominal_of"]
