# SPDX-License-Identifier: LGPL-2.1-or-later
"""The property tables of surfcomp's document objects (``surfcomp.app.features``).

One row per property: ``(type, name, group, tooltip, default, editor mode)``. The proxies
add missing rows when an object is created or restored (older documents get the properties
added since), and move the values of renamed ones (``RENAMED``). Tooltips are marked for
translation in FreeCAD's ``App::Property`` context, as FreeCAD's own features do.

Import this module where FreeCAD is importable.
"""

import FreeCAD

from ..core.option_tables import ALIGN, INPUTS
from ..core.options import OPTIONS, tooltip

#: marks property tooltips for translation (FreeCAD translates them in the "App::Property"
#: context when it shows them)
QT_TRANSLATE_NOOP = FreeCAD.Qt.QT_TRANSLATE_NOOP

#: version of the property sets; onDocumentRestored upgrades older objects
#: (properties added since, such as VolChange, come from the property tables;
#: 2: short names that fit the property view, see RENAMED)
VERSION = 2
#: compensation properties renamed in version 2: old name -> new name
RENAMED = {"FlipNormals": "Flip", "EdgeTolerance": "EdgeTol", "NominalPoints": "Nodes"}

MEASUREMENT_TYPE = "SurfComp_Measurement"
COMPENSATION_TYPE = "SurfComp_Compensation"

OUTPUTS = ("face", "solid")

_RO = 1      # editor mode: read-only
_HIDDEN = 2  # editor mode: hidden
#: the property value of an unset option (:mod:`surfcomp.core.options`)
_UNSET = {float: 0.0, str: "", int: 0}


def property_text(message):
    """The text of a warning for a document property: the options a
    :class:`surfcomp.errors.Note` names shown as their document properties (``align_faces``
    -> ``AlignFaces``; :mod:`surfcomp.core.option_tables`); a plain string as it is."""
    from ..core.option_tables import find

    if not hasattr(message, "shown"):
        return str(message)
    return message.shown(lambda name: getattr(find(name), "prop", None) or name)


def option_row(typ, name, group, table=OPTIONS, mode=0):
    """The property row of option ``name`` of the option registry's ``table``
    (:mod:`surfcomp.core.options`, :mod:`surfcomp.core.option_tables`): its property,
    tooltip and default (an enumeration: the choices, the first one set; an unset option:
    its ``stored`` value, else 0 or empty; a list: empty)."""
    o = table[name]
    if o.choices is not None:
        default = list(o.choices)
    elif o.default is not None:
        default = o.default
    elif o.stored is not None:
        default = o.stored
    else:
        default = None if typ.endswith("List") else _UNSET[o.type]
    return (typ, o.prop, group, QT_TRANSLATE_NOOP("App::Property", tooltip(name, table)),
            default, mode)

# (type, name, group, tooltip, default, editor mode)
_MEAS = "Measurement"
MEASUREMENT_PROPERTIES = (
    ("App::PropertyString", "SourceName", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "File the measurements were read from (information only: "
                                        "the data is stored below)"),
     "", _RO),
    ("App::PropertyString", "SourceSha256", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "SHA-256 of the source file's bytes"),
     "", _RO),
    ("App::PropertyString", "Units", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Units of the source file's length columns (the stored "
                                        "values are in mm)"),
     "mm", _RO),
    ("App::PropertyString", "Kind", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Columns the file had: nominal+normal+deviation, "
                                        "nominal+measured, ..."),
     "", _RO),
    ("App::PropertyInteger", "PointCount", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Number of measured points"),
     0, _RO),
    ("App::PropertyIntegerList", "GridShape", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Rows and columns of the grid when the file gives row/col "
                                        "indices (else empty)"),
     None, _RO),
    ("App::PropertyFloatList", "NominalX", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Nominal points, x (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "NominalY", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Nominal points, y (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "NominalZ", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Nominal points, z (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "MeasuredX", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Measured points, x (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "MeasuredY", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Measured points, y (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "MeasuredZ", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Measured points, z (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "NormalI", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Normals, x component"),
     None, _RO),
    ("App::PropertyFloatList", "NormalJ", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Normals, y component"),
     None, _RO),
    ("App::PropertyFloatList", "NormalK", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Normals, z component"),
     None, _RO),
    ("App::PropertyFloatList", "Deviation", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Deviation along the normal (mm, positive = material "
                                        "left)"),
     None, _RO),
    ("App::PropertyIntegerList", "Row", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Grid row of every point (when given)"),
     None, _RO),
    ("App::PropertyIntegerList", "Col", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Grid column of every point (when given)"),
     None, _RO),
    ("App::PropertyIntegerList", "Lines", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Line of every point in the source file"),
     None, _RO),
    ("App::PropertyStringList", "Ids", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Point names (when given)"),
     None, _RO),
    ("App::PropertyStringList", "PointFaces", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Reference face of every point (the file's face "
                                        "column, when given)"),
     None, _RO),
    ("App::PropertyString", "Columns", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Role -> column name as written in the file (JSON)"),
     "{}", _RO),
    ("App::PropertyStringList", "ReadWarnings", _MEAS,
     QT_TRANSLATE_NOOP("App::Property", "Warnings of the file reader"),
     None, _RO),
    # the alignment's settings: the option registry's ALIGN table
    option_row("App::PropertyEnumeration", "align", "Alignment", ALIGN),
    option_row("App::PropertyString", "align_faces", "Alignment", ALIGN),
    option_row("App::PropertyString", "align_dof", "Alignment", ALIGN),
    option_row("App::PropertyString", "rps", "Alignment", ALIGN),
    option_row("App::PropertyFloatList", "transform", "Alignment", ALIGN),
    ("App::PropertyInteger", "Version", "Base",
     QT_TRANSLATE_NOOP("App::Property", "Property set version of this object"),
     VERSION, _HIDDEN),
)

_IN, _RES = "Compensation", "Result"


def options_of(obj):
    """The core :class:`~surfcomp.core.compensation.pipeline.Options` of a compensation object
    (this table module imports no numerics until then)."""
    from ..core.compensation.pipeline import Options

    weights = obj.Weights.strip() or None
    return Options(method=obj.Method, mask_size=int(obj.MaskSize), weights=weights,
                   mask_kind=obj.MaskKind, sigma=(float(obj.Sigma) or None),
                   edge=obj.Edge, stock=float(obj.Stock.Value),
                   accept_stock=bool(getattr(obj, "StockOk", False)),
                   max_offset=float(obj.MaxOffset.Value), flip_normals=bool(obj.Flip),
                   refine=int(obj.Refine), lean=bool(getattr(obj, "Lean", True)),
                   layout=obj.Layout,
                   smoothing=(float(obj.Smoothing.Value) or None),
                   tip_radius=float(obj.TipRadius.Value), context="document")


def store_options(obj, options):
    """Set every option property of compensation ``obj`` from core ``options`` (the inverse
    of :func:`options_of`): an unset option becomes 0 or empty, and
    weights given as rows of numbers the property's text."""
    for name, o in OPTIONS.items():
        value = getattr(options, name)
        if value is None:
            value = _UNSET[o.type]
        elif name == "weights" and not isinstance(value, str):
            value = "; ".join(" ".join("%.17g" % w for w in row) for row in value)
        setattr(obj, o.prop, value)


def _option(typ, name):
    """The row of the compensation option ``name`` of the option registry."""
    return option_row(typ, name, _IN)


#: the results of an alignment on the compensation (its settings are the measurement's)
ALIGNMENT_RESULTS = (
    ("App::PropertyFloatList", "AlignMatrix", _RES,
     QT_TRANSLATE_NOOP("App::Property", "The measured points' alignment: 4x4 matrix row-major, "
                                        "measured -> nominal (empty: none)"),
     None, _RO),
    ("App::PropertyStringList", "Alignment", _RES,
     QT_TRANSLATE_NOOP("App::Property", "The alignment: transform, RMS before and after per "
                                        "face, iterations, what it absorbed"),
     None, _RO),
)
COMPENSATION_PROPERTIES = (
    ("App::PropertyLink", "Nominal", _IN,
     QT_TRANSLATE_NOOP("App::Property", "Object holding the nominal face"),
     None, 0),
    option_row("App::PropertyString", "face", _IN, INPUTS),
    ("App::PropertyLink", "Measurement", _IN,
     QT_TRANSLATE_NOOP("App::Property", "Measurement object (SurfComp_Measurement)"),
     None, 0),
    ("App::PropertyLink", "Base", _IN,
     QT_TRANSLATE_NOOP("App::Property", "Previous compensation (iterations): this measurement is "
                                        "of the part machined from its corrected face; corrections"
                                        " accumulate"),
     None, 0),
    _option("App::PropertyEnumeration", "method"),
    _option("App::PropertyInteger", "mask_size"),
    _option("App::PropertyString", "weights"),
    _option("App::PropertyEnumeration", "mask_kind"),
    _option("App::PropertyFloat", "sigma"),
    _option("App::PropertyEnumeration", "edge"),
    _option("App::PropertyLength", "stock"),
    _option("App::PropertyBool", "accept_stock"),
    _option("App::PropertyLength", "max_offset"),
    _option("App::PropertyBool", "flip_normals"),
    _option("App::PropertyInteger", "refine"),
    _option("App::PropertyBool", "lean"),
    ("App::PropertyEnumeration", "Output", _IN,
     QT_TRANSLATE_NOOP("App::Property", "face: the corrected face; solid: the nominal's shape with"
                                        " the face replaced and its neighbours re-trimmed to meet"
                                        " it"),
     list(OUTPUTS), 0),
    _option("App::PropertyEnumeration", "layout"),
    _option("App::PropertyLength", "smoothing"),
    _option("App::PropertyLength", "tip_radius"),
    ("App::PropertyBool", "Preview", _IN,
     QT_TRANSLATE_NOOP("App::Property", "Filter preview (task panel): compute deviations and "
                                        "components only and keep the last corrected shape; the "
                                        "panel clears it when it closes"),
     False, _HIDDEN),
    ("App::PropertyInteger", "GridRows", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Rows of the measurement grid (scattered layouts: the "
                                        "number of points)"),
     0, _RO),
    ("App::PropertyInteger", "GridCols", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Columns of the measurement grid (scattered layouts: 1)"),
     0, _RO),
    ("App::PropertyBool", "Scattered", _RES,
     QT_TRANSLATE_NOOP("App::Property", "The points are a scattered layout (not a grid): fields "
                                        "are built over the points"),
     False, _RO),
    ("App::PropertyFloatList", "FieldScale", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Scattered layouts: mm per unit parameter along u and v "
                                        "used by the fits"),
     None, _RO),
    ("App::PropertyFloatList", "U", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Face parameter u of every grid node (row-major)"),
     None, _RO),
    ("App::PropertyFloatList", "V", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Face parameter v of every grid node (row-major)"),
     None, _RO),
    ("App::PropertyFloatList", "Nodes", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Nominal point of every node, flat x y z (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "Normals", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Outward normal of every node, flat"),
     None, _RO),
    ("App::PropertyFloatList", "Deviation", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Deviation from the nominal at every node (mm, NaN = not "
                                        "measured)"),
     None, _RO),
    ("App::PropertyFloatList", "Determined", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Filtered (determined) component of the deviation (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "Random", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Random component: deviation - determined (mm)"),
     None, _RO),
    ("App::PropertyFloatList", "Increment", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Correction of this round (mm); equals Correction without "
                                        "a Base"),
     None, _RO),
    ("App::PropertyFloatList", "Correction", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Total correction realised by the corrected face (mm, "
                                        "accumulated over the Base chain)"),
     None, _RO),
    ("App::PropertyString", "Statistics", _RES,
     QT_TRANSLATE_NOOP("App::Property", "name -> statistics (mm) as JSON"),
     "{}", _RO),
    ("App::PropertyString", "Checks", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Check figures of the corrected face (JSON)"),
     "{}", _RO),
    ("App::PropertyStringList", "Warnings", _RES,
     QT_TRANSLATE_NOOP("App::Property", "What the computation warned about"),
     None, _RO),
    ("App::PropertyInteger", "Round", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Iteration round (1 without a Base)"),
     1, _RO),
    ("App::PropertyLength", "EdgeTol", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Largest tolerance of the corrected face's edges and "
                                        "vertices"),
     0.0, _RO),
    ("App::PropertyFloat", "VolChange", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Output solid: its volume minus the nominal's (mm^3; 0 for"
                                        " a face)"),
     0.0, _RO),
    ("App::PropertyFloat", "CorrVol", _RES,
     QT_TRANSLATE_NOOP("App::Property", "Integral of the correction over the face (mm^3, positive"
                                        " = material removed): the volume change should be minus"
                                        " this"),
     0.0, _RO),
    ("App::PropertyString", "ReplacedLinks", "Replace",
     QT_TRANSLATE_NOOP("App::Property", "Links rebound by surfcomp.app.replace.replace (JSON; "
                                        "restore() reverts them)"),
     "", _HIDDEN),
    ("App::PropertyInteger", "Version", "Base",
     QT_TRANSLATE_NOOP("App::Property", "Property set version of this object"),
     VERSION, _HIDDEN),
) + ALIGNMENT_RESULTS
