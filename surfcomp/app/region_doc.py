# SPDX-License-Identifier: LGPL-2.1-or-later
"""The region compensation as a document object (issue 30): ``SurfComp_RegionCompensation``.

A ``Part::FeaturePython`` that links the nominal object (``Nominal``), the region's faces
(``Faces``: ``Face1,Face2`` or ``auto``) and a measurement object (``Measurement``, a
``SurfComp_Measurement``: the points are kept in the document). Its ``execute`` runs
:func:`surfcomp.app.region_route.compute_region` on the nominal's shape and the stored
points; its ``Shape`` is the nominal's solid with the region's faces corrected (same faces,
same order, so ``FaceN`` links of Path operations stay valid). The figures of the run (points
per face, the continuity along every shared edge, the volume check) are written to
read-only properties and the whole report to ``Report`` (JSON).

It carries what :func:`surfcomp.app.replace.replace` needs of a compensation (``Output`` is
always ``solid``, ``ReplacedLinks``), so the nominal's users (Path Job models, operations)
can be moved to it and back.

Iterations: a region object whose ``Base`` is an earlier region object of the same nominal
and faces takes a measurement of the part machined from the earlier result. Its deviations
are against the nominal, its own field (the increment) comes from them, and the faces are
rebuilt from the sum of the fields of every round
(:mod:`surfcomp.core.compensation.region_rounds`). Each round keeps its own field in hidden
properties (``Field*``), so the next round does not recompute the earlier ones.

Alignment: the measurement object's Align* properties (as for one face,
:mod:`surfcomp.app.align_doc`) align the points to the region's faces, or to datum faces
(``AlignFaces``), before the deviations (:mod:`surfcomp.app.region_align`); the result goes
to ``AlignMatrix`` and ``Alignment``.

The proxy module path ``surfcomp.app.region_doc`` is permanent once documents exist.
"""

import json
from dataclasses import dataclass

from ..core.choices import MASK_KINDS
from ..core.command_options import COMPENSATE
from ..core.compensation.filters import WERNER_MASK_SIZE
from ..errors import InputError
from . import features
from .properties import QT_TRANSLATE_NOOP, option_row
from .proxies import Proxy

REGION_TYPE = "SurfComp_RegionCompensation"
VERSION = 2

_IN = "Region"
_OUT = "Region result"
_RO, _HIDDEN = 1, 2
_T = "App::Property"

REGION_PROPERTIES = (
    ("App::PropertyLink", "Nominal", _IN,
     QT_TRANSLATE_NOOP(_T, "The object whose faces are compensated"), None, 0),
    option_row("App::PropertyString", "faces", _IN, COMPENSATE),
    ("App::PropertyLink", "Measurement", _IN,
     QT_TRANSLATE_NOOP(_T, "The measurement object (points stored in the document)"), None, 0),
    ("App::PropertyEnumeration", "Method", _IN,
     QT_TRANSLATE_NOOP(_T, "filtered: Werner's mask filter over the region; raw: the "
                           "deviations as measured"), ["filtered", "raw"], 0),
    ("App::PropertyInteger", "MaskSize", _IN,
     QT_TRANSLATE_NOOP(_T, "Side of the filter mask in point spacings"), WERNER_MASK_SIZE, 0),
    ("App::PropertyEnumeration", "MaskKind", _IN,
     QT_TRANSLATE_NOOP(_T, "Weights of the filter mask"), list(MASK_KINDS), 0),
    ("App::PropertyFloat", "Sigma", _IN,
     QT_TRANSLATE_NOOP(_T, "Gaussian mask's sigma in point spacings (0: the default)"), 0.0, 0),
    ("App::PropertyLength", "MaxOffset", _IN,
     QT_TRANSLATE_NOOP(_T, "Largest distance of a point from its face, and largest step "
                           "between the readings of two faces across an edge"), 1.0, 0),
    option_row("App::PropertyFloat", "min_coverage", _IN, COMPENSATE),
    ("App::PropertyLength", "Smoothing", _IN,
     QT_TRANSLATE_NOOP(_T, "Radius of the correction field (0: 5 % of the shape's diagonal, "
                           "at least 4 point spacings)"), 0.0, 0),
    ("App::PropertyString", "Output", _IN,
     QT_TRANSLATE_NOOP(_T, "Always solid: the nominal's shape with the region corrected"),
     "solid", _RO | _HIDDEN),
    ("App::PropertyLink", "Base", _IN,
     QT_TRANSLATE_NOOP(_T, "The previous round (iterations): this measurement is of the part "
                           "machined from Base's result"), None, 0),
    ("App::PropertyString", "ReplacedLinks", _IN,
     QT_TRANSLATE_NOOP(_T, "Links moved from the nominal to this object by Replace (JSON)"),
     "", _RO | _HIDDEN),
    ("App::PropertyStringList", "RegionFaces", _OUT,
     QT_TRANSLATE_NOOP(_T, "The faces corrected"), None, _RO),
    ("App::PropertyStringList", "PointsPerFace", _OUT,
     QT_TRANSLATE_NOOP(_T, "Measured points given to every face (each to its nearest)"),
     None, _RO),
    ("App::PropertyInteger", "PointsOnNoFace", _OUT,
     QT_TRANSLATE_NOOP(_T, "Points farther than MaxOffset from every face of the region"),
     0, _RO),
    ("App::PropertyStringList", "Continuity", _OUT,
     QT_TRANSLATE_NOOP(_T, "Per face and per shared edge: points, poles, largest gap and "
                           "normal angle"), None, _RO),
    ("App::PropertyFloat", "MaxGap", _OUT,
     QT_TRANSLATE_NOOP(_T, "Largest gap along the region's shared edges (um)"), 0.0, _RO),
    ("App::PropertyFloat", "MaxAngleChange", _OUT,
     QT_TRANSLATE_NOOP(_T, "Largest change of the normal angle along the shared edges (deg)"),
     0.0, _RO),
    ("App::PropertyFloat", "VolChange", _OUT,
     QT_TRANSLATE_NOOP(_T, "Volume of the result minus the nominal's (mm^3)"), 0.0, _RO),
    ("App::PropertyFloat", "CorrIntegral", _OUT,
     QT_TRANSLATE_NOOP(_T, "-integral of the correction over the region (mm^3): the expected "
                           "volume change"), 0.0, _RO),
    ("App::PropertyInteger", "Round", _OUT,
     QT_TRANSLATE_NOOP(_T, "Iteration round (1 without a Base)"), 1, _RO),
    ("App::PropertyFloatList", "AlignMatrix", _OUT,
     QT_TRANSLATE_NOOP(_T, "Alignment applied to the measured points (4x4 row-major, "
                           "measured -> nominal; empty: none)"), None, _RO | _HIDDEN),
    ("App::PropertyStringList", "Alignment", _OUT,
     QT_TRANSLATE_NOOP(_T, "What the alignment did: method, transform, RMS per face"), None,
     _RO),
    ("App::PropertyFloatList", "FieldCentres", _OUT,
     QT_TRANSLATE_NOOP(_T, "This round's correction field: kernel centres (x, y, z, mm)"),
     None, _RO | _HIDDEN),
    ("App::PropertyFloatList", "FieldValues", _OUT,
     QT_TRANSLATE_NOOP(_T, "This round's correction field: values at the centres (mm)"),
     None, _RO | _HIDDEN),
    ("App::PropertyFloatList", "FieldWeights", _OUT,
     QT_TRANSLATE_NOOP(_T, "This round's correction field: weights of the centres"),
     None, _RO | _HIDDEN),
    ("App::PropertyFloat", "FieldMean", _OUT,
     QT_TRANSLATE_NOOP(_T, "This round's correction field: mean value (mm)"), 0.0,
     _RO | _HIDDEN),
    ("App::PropertyFloat", "FieldRadius", _OUT,
     QT_TRANSLATE_NOOP(_T, "This round's correction field: kernel radius (mm)"), 0.0,
     _RO | _HIDDEN),
    ("App::PropertyString", "Report", _OUT,
     QT_TRANSLATE_NOOP(_T, "The run's report (JSON)"), "", _RO | _HIDDEN),
    ("App::PropertyInteger", "Version", _OUT,
     QT_TRANSLATE_NOOP(_T, "Version of the property set"), VERSION, _RO | _HIDDEN),
)


def is_region(obj):
    return features.is_type(obj, REGION_TYPE)


class RegionCompensationFeature(Proxy):
    """Proxy of ``SurfComp_RegionCompensation`` (see the module docstring)."""

    Type = REGION_TYPE
    PROPERTIES = REGION_PROPERTIES
    VERSION = VERSION

    def onDocumentRestored(self, obj):
        super().onDocumentRestored(obj)
        obj.setEditorMode("Base", 0)     # hidden and read-only in version 1 (no iterations)
        features._restored(obj)

    def execute(self, obj):
        run = compute(obj)
        write_results(obj, run)
        # the result is in the document's coordinates (the nominal's shape is placed)
        obj.Placement = run.shape.Placement
        obj.Shape = run.shape


@dataclass
class RegionRun:
    """What :func:`compute` gives: the shape, the report, this round's own field and the
    alignment (None without one)."""

    shape: object
    report: dict
    field: object
    alignment: object = None


def chain(obj):
    """The region object and its ``Base`` chain, newest first.

    Raises
    ------
    InputError
        A ``Base`` that is not a region object, of another nominal, or a cycle.
    """
    out, seen, base = [obj], {obj.Name}, obj.Base
    while base is not None:
        if not is_region(base):
            raise InputError("%s: Base %s is not a surfcomp region compensation (iterations "
                             "stack region objects)" % (obj.Label, base.Label))
        if base.Name in seen:
            raise InputError("%s: the Base chain has a cycle at %s" % (obj.Label, base.Label))
        if base.Nominal != obj.Nominal:
            raise InputError("%s: Base %s compensates %s, not %s (iterations must compensate "
                             "the same nominal)" % (obj.Label, base.Label,
                                                    getattr(base.Nominal, "Label", None),
                                                    getattr(obj.Nominal, "Label", None)))
        seen.add(base.Name)
        out.append(base)
        base = base.Base
    return out


def base_field(base):
    """The field of an earlier round, from its ``Field*`` properties."""
    from ..core.compensation.region_rounds import field_from_arrays

    return field_from_arrays(base.FieldCentres, base.FieldValues, base.FieldWeights,
                             base.FieldMean, base.FieldRadius, source=base.Label)


def compute(obj, log=None):
    """The :class:`RegionRun` of a region object from its properties."""
    from ..core.compensation.region_rounds import StackedField
    from .region_align import aligned
    from .region_route import check_method, compute_region

    nominal, meas = obj.Nominal, obj.Measurement
    if nominal is None or not hasattr(nominal, "Shape") or nominal.Shape.isNull():
        raise InputError("%s: Nominal is not set or has no shape" % obj.Label)
    if meas is None or not features.is_measurement(meas):
        raise InputError("%s: Measurement is not a surfcomp measurement object" % obj.Label)
    check_method(obj.Method)
    earlier = chain(obj)[1:]
    if earlier and obj.Faces.strip().lower() != "auto":
        from .region import parse_faces

        _same_faces(obj, earlier[0], ["Face%d" % (k + 1)
                                      for k in parse_faces(obj.Faces, nominal.Shape)])
    fields = [base_field(b) for b in earlier]
    ms = features.measurement_set(meas)
    ms, alignment = aligned(meas, nominal.Shape, obj.Faces, ms)
    own = []

    def stack(field):
        own.append(field)
        return StackedField(fields, field) if fields else field

    lines = []
    shape, rep = compute_region(
        nominal.Shape, ms, obj.Faces, (nominal.Label, ms.source), method=obj.Method,
        mask_size=int(obj.MaskSize), mask_kind=obj.MaskKind, sigma=float(obj.Sigma) or None,
        max_offset=float(obj.MaxOffset.Value), min_coverage=float(obj.MinCoverage),
        smoothing=float(obj.Smoothing.Value) or None, log=log or lines.append, stack=stack)
    if rep["output"]["kind"] != "solid":
        raise InputError("%s: %s is not one closed solid; a region in a document needs a "
                         "solid (compensate the faces to a file instead)"
                         % (obj.Label, nominal.Label))
    if earlier:
        _same_faces(obj, earlier[0], [f["face"] for f in rep["faces"]])
    rep["inputs"]["measurement_object"] = meas.Name
    rep["round"] = len(earlier) + 1
    rep["base"] = [b.Name for b in earlier]
    rep["alignment"] = None if alignment is None else alignment.as_dict()
    return RegionRun(shape, rep, own[0], alignment)


def _same_faces(obj, base, names):
    """Refuse a round whose faces are not its Base's."""
    if sorted(names) != sorted(base.RegionFaces):
        raise InputError("%s: the region is %s, but Base %s corrected %s (a next round "
                         "corrects what the earlier ones corrected: set faces to %s)"
                         % (obj.Label, ",".join(names), base.Label, ",".join(base.RegionFaces),
                            ",".join(base.RegionFaces)), options=("faces",))


def write_results(obj, run):
    from ..core.compensation.region_rounds import field_arrays
    from .align_doc import store
    from .region_route import output_line, summary

    rep = run.report
    obj.RegionFaces = [f["face"] for f in rep["faces"]]
    obj.PointsPerFace = ["%s %d" % (f["face"], f["points"]) for f in rep["faces"]]
    obj.PointsOnNoFace = int(rep["points_on_no_face"])
    obj.Continuity = summary(rep) + [output_line(rep["output"])]
    obj.MaxGap = max((e["max_gap_um"] for e in rep["edges"]), default=0.0)
    obj.MaxAngleChange = max((e["max_angle_change_deg"] for e in rep["edges"]), default=0.0)
    obj.VolChange = float(rep["output"]["change_mm3"])
    obj.CorrIntegral = float(rep["output"]["integral_mm3"])
    obj.Round = int(rep["round"])
    store(obj, run.alignment)
    arrays = field_arrays(run.field)
    obj.FieldCentres = arrays["centres"].ravel().tolist()
    obj.FieldValues = arrays["values"].tolist()
    obj.FieldWeights = arrays["weights"].tolist()
    obj.FieldMean = arrays["mean"]
    obj.FieldRadius = arrays["radius"]
    obj.Report = json.dumps(rep, sort_keys=True)


def make_region(doc, nominal, faces, measurement, name="RegionCompensation", base=None,
                **options):
    """Add a region compensation of ``nominal``'s ``faces`` (``'Face1,Face2'``, a list of
    names, or ``'auto'``) with the measurement object ``measurement``; ``base``: the
    previous round (a region object of the same nominal); ``options``: property values
    (``Method``, ``MaskSize``, ``MaxOffset``, ``MinCoverage`` ...)."""
    rounds = 1
    if base is not None:
        if not is_region(base):
            raise InputError("%s is not a surfcomp region compensation (expected the previous "
                             "round)" % base.Label)
        if base.Nominal != nominal:
            raise InputError("%s compensates %s, not %s (iterations must compensate the same "
                             "nominal)" % (base.Label, getattr(base.Nominal, "Label", None),
                                           nominal.Label))
        rounds = len(chain(base)) + 1
    obj = doc.addObject("Part::FeaturePython", name)
    RegionCompensationFeature(obj)
    obj.Nominal = nominal
    obj.Base = base
    obj.Measurement = measurement
    obj.Faces = faces if isinstance(faces, str) else ",".join(faces)
    for key, value in options.items():
        if value is not None:
            setattr(obj, key, value)
    obj.Label = "%s_region" % nominal.Label + ("" if rounds == 1 else " round %d" % rounds)
    return features._created(obj)


def options_record(obj):
    """The object's inputs as a dict (what the summary and the tests show)."""
    return {"Faces": obj.Faces, "Method": obj.Method, "MaskSize": int(obj.MaskSize),
            "MaskKind": obj.MaskKind, "Sigma": float(obj.Sigma),
            "MaxOffset": float(obj.MaxOffset.Value), "MinCoverage": float(obj.MinCoverage),
            "Smoothing": float(obj.Smoothing.Value)}


__all__ = ["RegionCompensationFeature", "make_region", "is_region", "REGION_TYPE"]
__all__ += ["compute", "write_results", "options_record", "chain", "RegionRun"]
