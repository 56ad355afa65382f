# SPDX-License-Identifier: LGPL-2.1-or-later
"""Path dressup "Surface correction": the finishing operation moved by a compensation.

Beside the axis-error dressup (:mod:`surfcomp.app.dressup_axis`), in the same thin manner:
the proxy reads the base operation's commands, the compensation object's nominal and
corrected faces, and calls :func:`surfcomp.io.gcode.offset_stream.offset_commands` (the
direct program compensation of :mod:`surfcomp.core.compensation.program_offset`); the Job then posts
the moved program without re-running the 3D Surface operation. It is parametric: a new
measurement, another method or a next iteration round (a compensation whose ``Base`` is the
previous round: its corrected face carries every round's correction) recomputes it, and
pointing ``Compensation`` at the next round is how iterations stack.

Ball-end cutters only; ``BallRadius`` is taken from the tool controller's diameter when the
dressup is created. No FreeCADGui, no PySide: it recomputes in ``freecadcmd``.
"""

import FreeCAD
import Path

from ..core.command_options import PROGRAM_MOVE
from ..errors import InputError
from ..io.gcode.offset_stream import offset_commands
from . import cam
from .dressups import DressupProxy, check_base, place
from .program_geometry import offset_of

QT_TRANSLATE_NOOP = FreeCAD.Qt.QT_TRANSLATE_NOOP

#: version of the document object's property set
VERSION = 1
#: the proxy's Type (:func:`surfcomp.app.features.is_type`)
SURFACE_DRESSUP_TYPE = "SurfComp_DressupSurfaceCorrection"

_GROUP = "SurfaceCorrection"
_GROUP_RESULT = "Result"

#: (type, name, group, tooltip, default, editor mode) of every property
PROPERTIES = (
    ("App::PropertyLink", "Base", "Base",
     QT_TRANSLATE_NOOP("App::Property", "The finishing operation (ball end mill) to move"),
     None, 0),
    ("App::PropertyLink", "Compensation", _GROUP,
     QT_TRANSLATE_NOOP("App::Property", "The compensation whose corrected face the path is "
                                        "moved onto (the last round of an iteration)"),
     None, 0),
    ("App::PropertyLength", "BallRadius", _GROUP,
     QT_TRANSLATE_NOOP("App::Property", "Radius of the ball end mill the base path was made "
                                        "with"),
     0.0, 0),
    ("App::PropertyLength", "Tolerance", _GROUP,
     QT_TRANSLATE_NOOP("App::Property", "Largest distance of the moved path from the exactly "
                                        "moved one (long moves are split)"),
     PROGRAM_MOVE["tolerance"].default, 0),
    ("App::PropertyLength", "Blend", _GROUP,
     QT_TRANSLATE_NOOP("App::Property", "Beyond the face the correction fades out over this "
                                        "clearance"),
     PROGRAM_MOVE["blend"].default, 0),
    ("App::PropertyLength", "SegmentLength", _GROUP,
     QT_TRANSLATE_NOOP("App::Property", "Long moves are first sampled at this spacing"),
     PROGRAM_MOVE["segment_length"].default, 0),
    ("App::PropertyInteger", "MovedMoves", _GROUP_RESULT,
     QT_TRANSLATE_NOOP("App::Property", "Moves the correction moved"),
     0, 1),
    ("App::PropertyLength", "MaxMove", _GROUP_RESULT,
     QT_TRANSLATE_NOOP("App::Property", "Largest move of a point"),
     0.0, 1),
    ("App::PropertyInteger", "ContactPoints", _GROUP_RESULT,
     QT_TRANSLATE_NOOP("App::Property", "Cutter-location points found touching the face"),
     0, 1),
    ("App::PropertyInteger", "Version", "Base",
     QT_TRANSLATE_NOOP("App::Property", "Property set version of this object"),
     VERSION, 2),
)


def ball_offset(obj):
    """The :class:`~surfcomp.core.compensation.program_offset.BallOffset` of the dressup's
    compensation (nominal and corrected face in document coordinates)."""
    from .features import nominal_of
    from .reports import corrected_surface

    comp = obj.Compensation
    if comp is None:
        raise InputError("%s has no Compensation (link the compensation to follow)"
                         % obj.Label)
    nominal, placement = nominal_of(comp)
    if not placement.isIdentity():
        raise InputError("%s: the nominal %s has a Placement; the surface correction "
                         "dressup needs it at the document origin (as the Job's model)"
                         % (obj.Label, comp.Nominal.Label))
    corrected = corrected_surface(comp)
    radius = float(obj.BallRadius.Value)
    if not radius > 0:
        raise InputError("%s: BallRadius must be positive (the ball end mill's radius)"
                         % obj.Label)

    return offset_of(nominal, corrected, radius, float(obj.Blend.Value))


def check_ball_end(obj, base):
    """Refuse a base whose tool is known not to be a ball end mill: the dressup moves the
    ball's centre along the face normal at its contact, which is not where a flat or
    bull-nose cutter touches (``compensate --program`` refuses ``flat:`` and ``bull:``
    alike). A tool that names no shape is taken as the ball ``BallRadius`` gives."""
    from .cam_job import tool_controller_of

    tc = tool_controller_of(base)
    shape = cam.tool_shape(getattr(tc, "Tool", None))
    if shape is not None and shape not in cam.BALL_END_SHAPES:
        raise InputError("%s: the tool of %s (%s, tool controller %s) has the shape %r, not "
                         "a ball end mill's: the surface correction moves ball-end programs "
                         "only (a flat or bull-nose cutter touches the face elsewhere); "
                         "expected a ball end mill's finishing operation"
                         % (obj.Label, cam.base_operation(base).Label, tc.Tool.Label,
                            tc.Label, shape))


def move_path(obj):
    """The dressup's Path from its base (what ``execute`` does) and the result, or an empty
    Path and None without a base."""
    base = obj.Base
    if base is None or not base.isDerivedFrom("Path::Feature"):
        return Path.Path(), None
    check_ball_end(obj, base)
    cmds = cam.placed_commands(base)
    source = "%s (on %s)" % (obj.Label, cam.base_operation(base).Label)
    res, fit, op = offset_commands([(c.Name, c.Parameters) for c in cmds], ball_offset(obj),
                                   tolerance=float(obj.Tolerance.Value),
                                   segment_length=float(obj.SegmentLength.Value),
                                   source=source)
    out = [cmds[item] if isinstance(item, int) else Path.Command(item[0], item[1])
           for item in res.output]
    return Path.Path(out), (res, fit, op)


class DressupSurfaceCorrection(DressupProxy):
    """Proxy of the surface correction dressup (state lives in properties)."""

    Type = SURFACE_DRESSUP_TYPE
    PROPERTIES = PROPERTIES
    VERSION = VERSION

    def execute(self, obj):
        path, result = move_path(obj)
        obj.Path = path
        if result is None:      # no base: nothing moved, no figures of an earlier run kept
            obj.MovedMoves, obj.MaxMove, obj.ContactPoints = 0, 0.0, 0
            return
        res, fit, op = result
        obj.MovedMoves = int(op.moved.sum())
        obj.MaxMove = res.max_correction()
        obj.ContactPoints = fit.points


def Create(base, compensation, name="DressupSurfaceCorrection"):
    """Create the surface correction dressup on ``base``, following ``compensation``.

    ``BallRadius`` is half the diameter of the base's tool controller's tool. The new
    ``Path::FeaturePython`` takes the base's place in its Job; recompute the document to
    compute its Path. Keep ``Dressup`` in ``name`` (Path finds the tool controller of
    dressups by that part of the name)."""
    check_base(base)
    from .cam_job import tool_controller_of

    doc = base.Document
    obj = doc.addObject("Path::FeaturePython", name)
    DressupSurfaceCorrection(obj, base)
    obj.Compensation = compensation
    tc = tool_controller_of(base)
    tool = getattr(tc, "Tool", None)
    diameter = getattr(tool, "Diameter", None)
    if diameter is not None:
        obj.BallRadius = float(getattr(diameter, "Value", diameter)) / 2.0
    place(obj, base)
    return obj
