# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measurement plan as a document object (app layer, headless).

``SurfComp_MeasurementPlan`` (``Part::FeaturePython``) links the nominal (object + face
name) and holds the layout and probe settings; ``execute`` plans on the face
(:func:`surfcomp.app.plan_reach.plan_face`, the command line's ``plan``) and writes the
points in visiting order, their outward normals, names and the counts back to properties.
Its ``Shape`` is a compound of the points' vertices, so the plan shows in the 3D view. A
thin proxy (docs/architecture.md): no state on the proxy, no FreeCADGui; the module path is
permanent once documents exist.
"""

import FreeCAD

from ..core.measurement.planning import (
    POINT_LAYOUTS,
    REASONS,
    PlanSettings,
    check_points,
    parse_count,
)
from ..core.option_tables import PLAN
from ..errors import GeometryError
from .features import _created, _Proxy
from .properties import option_row, property_text

PLAN_TYPE = "SurfComp_MeasurementPlan"
PLAN_VERSION = 1
_RO = 1        # editor mode: read-only
#: (type, name, group, tooltip, default, editor mode)
PLAN_PROPERTIES = (
    ("App::PropertyInteger", "Version", "Base", "surfcomp object version", PLAN_VERSION, 1),
    ("App::PropertyLink", "Nominal", "Plan", "object holding the nominal face", None, 0),
    ("App::PropertyString", "Face", "Plan", "the nominal face (FaceN)", "Face1", 0),
    # the plan's settings: the option registry's PLAN table
    option_row("App::PropertyEnumeration", "layout", "Plan", PLAN),
    option_row("App::PropertyString", "count", "Plan", PLAN),
    option_row("App::PropertyInteger", "points", "Plan", PLAN),
    *(option_row("App::PropertyFloat", name, "Probe", PLAN)
      for name in ("tip_radius", "edge_margin", "max_tilt", "stand_off", "clearance")),
    ("App::PropertyVectorList", "PlanPoints", "Result",
     "nominal surface points in visiting order (mm)", None, _RO),
    ("App::PropertyVectorList", "PlanNormals", "Result", "outward unit normals", None, _RO),
    ("App::PropertyStringList", "PointIds", "Result", "point names in visiting order", None,
     _RO),
    ("App::PropertyInteger", "Placed", "Result", "points the layout placed", 0, _RO),
    ("App::PropertyInteger", "Kept", "Result", "points kept", 0, _RO),
    ("App::PropertyStringList", "Dropped", "Result", "dropped points per reason", None, _RO),
    ("App::PropertyFloat", "Travel", "Result",
     "travel between the retract positions in visiting order (mm)", 0.0, _RO),
    ("App::PropertyFloat", "SafeZ", "Result",
     "safe height of the ball centre (mm): part top + tip radius + clearance",
     0.0, _RO),
    ("App::PropertyString", "Order", "Result", "visiting order", "", _RO),
)


class MeasurementPlanFeature(_Proxy):
    """Proxy of ``SurfComp_MeasurementPlan`` (module docstring)."""

    Type = PLAN_TYPE
    PROPERTIES = PLAN_PROPERTIES
    VERSION = PLAN_VERSION

    def execute(self, obj):
        compute_plan(obj)


def trial_plan(obj, **values):
    """The plan of ``obj`` with some properties replaced by ``values`` (``Layout``,
    ``Count``, ``Points``, ``TipRadius``, ...), nothing written: a task panel checks its
    fields with it before they reach the object, so no recompute fails. Raises the
    planner's :class:`~surfcomp.errors.SurfcompError`."""
    from .face_data import pick_face
    from .nominal import nominal_from_face
    from .plan_reach import plan_face

    def val(name):
        return values.get(name, getattr(obj, name))

    if obj.Nominal is None or not hasattr(obj.Nominal, "Shape") or obj.Nominal.Shape.isNull():
        raise GeometryError("the measurement plan needs a nominal object with a shape")
    shape = obj.Nominal.Shape
    face, name = pick_face(shape, val("Face") or None, source=obj.Nominal.Label)
    nominal = nominal_from_face(face, source=obj.Nominal.Label, face_name=name, shape=shape)
    layout = val("Layout")
    count = check_points(val("Points")) if layout in POINT_LAYOUTS else parse_count(val("Count"))
    settings = PlanSettings(tip_radius=val("TipRadius"), edge_margin=val("EdgeMargin"),
                            max_tilt=val("MaxTilt"), stand_off=val("StandOff"),
                            clearance=val("Clearance")).check()
    return plan_face(nominal, layout, count, settings)[0]


def compute_plan(obj):
    """Plan on the linked face and write the results (and the points' Shape) to ``obj``."""
    import Part

    plan = trial_plan(obj)
    V = FreeCAD.Vector
    obj.PlanPoints = [V(*p) for p in plan.points]
    obj.PlanNormals = [V(*n) for n in plan.normals]
    obj.PointIds = list(plan.ids)
    obj.Placed = int(plan.requested)
    obj.Kept = len(plan)
    obj.Dropped = [property_text(text) for text in dropped(plan)]
    obj.Travel = float(plan.travel)
    obj.SafeZ = float(plan.safe_z)
    obj.Order = plan.order
    obj.Shape = Part.makeCompound([Part.Vertex(V(*p)) for p in plan.points])
    return plan


def dropped(plan):
    """The dropped points of ``plan`` per reason (``3 normal leans more than max_tilt from
    +Z``), in the order of the reasons: :class:`~surfcomp.errors.Note` texts naming the
    options as the API does, which the ``Dropped`` property shows as properties and the
    Plan measurement panel as its fields' labels."""
    from .plan_reach import REASONS as PART_REASONS

    return ["%d " % n + (REASONS.get(k) or PART_REASONS.get(k, k))
            for k, n in plan.drop_counts().items()]


def make_measurement_plan(doc, nominal, face="Face1", name="MeasurementPlan", **values):
    """A new ``SurfComp_MeasurementPlan`` object of ``doc`` on ``nominal``'s ``face``;
    ``values``: property values (``Layout``, ``Count``, ``Points``, ``TipRadius``, ...)."""
    obj = doc.addObject("Part::FeaturePython", name)
    MeasurementPlanFeature(obj)
    obj.Nominal = nominal
    obj.Face = face
    for key, val in values.items():
        setattr(obj, key, val)
    return _created(obj)


def plan_file_text(obj, fmt="csv"):
    """The plan file of the object's results (:func:`surfcomp.io.plan_file.plan_text`)."""
    from ..io.plan_file import plan_text

    return plan_text(fmt, list(obj.PointIds), [tuple(p) for p in obj.PlanPoints],
                     [tuple(n) for n in obj.PlanNormals],
                     ["surfcomp measurement plan %s of %s (%s), layout %s"
                      % (obj.Label, obj.Nominal.Label, obj.Face, obj.Layout)])
