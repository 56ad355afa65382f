"""Path (CAM) helpers: a Job with a 3D Surface finishing operation, post-processing to text.

Works with FreeCAD 0.20 (``PathScripts.*``) and FreeCAD 1.x CAM (``Path.Main.*``,
``Path.Op.*``, ``Path.Tool.*``, ``Path.Post.*``); the modules are looked up once by
:func:`modules`. No FreeCADGui: everything runs in ``freecadcmd`` and in a plain
``python3`` after :func:`surfcomp.app.fcenv.setup_path_workbench`.
"""

import os
from types import SimpleNamespace

from . import fcenv

from ..errors import GCodeError, InputError

_MODULES = None

#: tool bit file of a ball end mill shipped with Path (its Diameter is set on creation)
BALL_END_BIT = "6mm_Ball_End.fctb"


def modules():
    """The Path modules this project uses, for FreeCAD 0.20 or 1.x.

    Returns
    -------
    types.SimpleNamespace
        ``Job``, ``Surface``, ``ToolBit``, ``ToolController``, ``PostProcessor`` (the
        class with ``load(name)``), ``PathUtils``, ``Preferences``, ``version``
        (``'0.20'`` or ``'1.x'``).
    """
    global _MODULES
    if _MODULES is not None:
        return _MODULES
    fcenv.setup_path_workbench()
    try:  # FreeCAD 1.x CAM
        import Path.Main.Job as Job
        import Path.Op.Surface as Surface
        import Path.Tool.Bit as ToolBit
        import Path.Tool.Controller as ToolController
        import Path.Post.Processor as Processor
        import Path.Preferences as Preferences
        import PathScripts.PathUtils as PathUtils
        version = "1.x"
    except ImportError:  # FreeCAD 0.20
        import PathScripts.PathJob as Job
        import PathScripts.PathSurface as Surface
        import PathScripts.PathToolBit as ToolBit
        import PathScripts.PathToolController as ToolController
        import PathScripts.PathPostProcessor as Processor
        import PathScripts.PathPreferences as Preferences
        import PathScripts.PathUtils as PathUtils
        version = "0.20"
    _MODULES = SimpleNamespace(Job=Job, Surface=Surface, ToolBit=ToolBit,
                               ToolController=ToolController,
                               PostProcessor=Processor.PostProcessor, PathUtils=PathUtils,
                               Preferences=Preferences, version=version)
    return _MODULES


def _tool_bit_file(name):
    import FreeCAD

    for sub in ("Mod/Path/Tools/Bit", "Mod/CAM/Tools/Bit"):
        path = os.path.join(FreeCAD.getHomePath(), sub, name)
        if os.path.isfile(path):
            return path
    raise InputError("Path's tool bit %s is not installed (looked under %s)"
                     % (name, FreeCAD.getHomePath()))


def create_job(doc, models, name="Job"):
    """A Path Job on ``models`` (document objects); Path clones them into ``Job.Model``."""
    m = modules()
    import FreeCAD

    if FreeCAD.ActiveDocument is None or FreeCAD.ActiveDocument.Name != doc.Name:
        FreeCAD.setActiveDocument(doc.Name)
    job = m.Job.Create(name, list(models), None)
    doc.recompute()
    return job


def model_clone(job, obj):
    """The clone of ``obj`` in ``job.Model`` (what operations link to), or None."""
    for clone in job.Model.Group:
        if clone is obj or obj in list(getattr(clone, "Objects", []) or []):
            return clone
    return None


def ball_end_tool_controller(job, diameter=6.0, spindle=10000.0, horiz_feed=20.0,
                             vert_feed=5.0):
    """Give ``job`` one tool controller with a ball end mill of ``diameter`` (mm).

    Path's headless operations take the job's only tool controller, so the job's default
    controller (if any) gets the ball end mill and its old bit is removed. Feeds in mm/s.
    """
    m = modules()
    doc = job.Document
    bit = m.ToolBit.Factory.CreateFrom(_tool_bit_file(BALL_END_BIT), "BallEnd")
    bit.Diameter = float(diameter)
    bit.Label = "Ball end %g mm" % diameter
    tcs = list(job.Tools.Group)
    if tcs:
        tc = tcs[0]
        old = tc.Tool
        tc.Tool = bit
        if old is not None and old is not bit and not [o for o in old.InList if o is not tc]:
            doc.removeObject(old.Name)
        for extra in tcs[1:]:
            job.Tools.removeObject(extra)
            doc.removeObject(extra.Name)
    else:
        tc = m.ToolController.Create("TC: Ball end", bit, 1)
        job.Proxy.addToolController(tc)
    tc.Label = "TC: Ball end %g mm" % diameter
    tc.SpindleSpeed = float(spindle)
    tc.HorizFeed = float(horiz_feed)
    tc.VertFeed = float(vert_feed)
    return tc


def surface_operation(job, obj, faces, tool_controller=None, step_over=50.0,
                      sample_interval=1.0, linear_deflection=0.001, name="Surface"):
    """A 3D Surface operation (drop cutter, line pattern) on ``faces`` of ``obj``.

    Parameters
    ----------
    job : the Path Job holding ``obj`` in its model
    obj : the document object (the job's model clone of it is linked)
    faces : list of str
        ``FaceN`` names.
    step_over : float
        Percent of the tool diameter between cut lines.
    sample_interval : float
        Distance of the drop-cutter samples along a line (mm).
    linear_deflection : float
        Mesh deflection of the tessellation OpenCamLib drops the cutter on (mm); it bounds
        the tool path's error against the exact surface.

    Every sampled point is kept (``OptimizeLinearPaths`` off), so the cutter-location
    points of two runs can be compared point by point.
    """
    m = modules()
    clone = model_clone(job, obj)
    if clone is None:
        raise InputError("%s is not in the model of job %s" % (obj.Label, job.Label))
    op = m.Surface.Create(name, parentJob=job)
    op.Base = [(clone, tuple(faces))]
    if tool_controller is not None:
        op.ToolController = tool_controller
    op.ScanType = "Planar"
    op.LayerMode = "Single-pass"
    op.CutPattern = "Line"
    op.BoundBox = "BaseBoundBox"
    op.StepOver = float(step_over)
    op.SampleInterval = float(sample_interval)
    op.LinearDeflection = float(linear_deflection)
    op.OptimizeLinearPaths = False
    op.OptimizeStepOverTransitions = False
    return op


def tool_controller_of(op):
    """The tool controller of an operation or of the operation under a dressup."""
    seen = set()
    while op is not None and op.Name not in seen:
        seen.add(op.Name)
        tc = getattr(op, "ToolController", None)
        if tc is not None:
            return tc
        op = getattr(op, "Base", None)
        if isinstance(op, (list, tuple)):
            return None
    return None


class _Fixture:
    """The work offset block Path's own post command writes before the operations."""

    def __init__(self, name, clearance):
        import Path

        self.Name = self.Label = name
        self.Path = Path.Path([Path.Command(name), Path.Command("G0", {"Z": clearance})])


def post_list(job):
    """Objects to post for ``job`` in Path's order (ordered by fixture, tool changes
    only where the tool controller changes)."""
    clearance = job.Stock.Shape.BoundBox.ZMax + job.SetupSheet.ClearanceHeightOffset.Value
    out = []
    for fixture in job.Fixtures:
        out.append(_Fixture(fixture, clearance))
        current = None
        for op in job.Operations.Group:
            if not getattr(op, "Active", True):
                continue
            tc = tool_controller_of(op)
            if tc is not None and tc is not current:
                out.append(tc)
                current = tc
            out.append(op)
    return out


def post_process(job, post="linuxcnc", args="--no-show-editor"):
    """Post-process ``job`` with Path's post-processor ``post``; return the G-code text.

    Parameters
    ----------
    job : Path Job (recomputed)
    post : str
        Post-processor name without ``_post`` (``linuxcnc``, ``grbl``, ...).
    args : str
        The post-processor's argument string (e.g. ``--no-header`` for output without
        the time stamp).

    Raises
    ------
    GCodeError
        Unknown post-processor, or it produced nothing.
    """
    m = modules()
    if not m.PostProcessor.exists(post):
        raise GCodeError("unknown post-processor %r (available: %s)"
                         % (post, ", ".join(sorted(m.Preferences.allAvailablePostProcessors()))))
    proc = m.PostProcessor.load(post)
    text = proc.export(post_list(job), "-", args)
    if not text:
        raise GCodeError("post-processor %r produced no output (arguments %r)" % (post, args))
    return text


def jobs_of(doc):
    """The Path Jobs of a document."""
    return [o for o in doc.Objects
            if type(getattr(o, "Proxy", None)).__name__ == "ObjectJob"
            or (hasattr(o, "Operations") and hasattr(o, "Model") and hasattr(o, "Tools"))]


def operations_of(job):
    return list(job.Operations.Group)


def cutter_locations(op, feed_only=True):
    """Absolute X Y Z of the moves of an operation's Path, modal axes carried over.

    Parameters
    ----------
    feed_only : bool
        Only feed moves (G1): the cutter-location points of a drop-cutter operation.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
    """
    import numpy as np

    pos = [np.nan, np.nan, np.nan]
    out = []
    names = ("G1", "G01") if feed_only else ("G0", "G00", "G1", "G01")
    for c in op.Path.Commands:
        if c.Name in ("G0", "G00", "G1", "G01", "G2", "G02", "G3", "G03"):
            for a, axis in enumerate("XYZ"):
                if axis in c.Parameters:
                    pos[a] = c.Parameters[axis]
            if c.Name in names:
                out.append(list(pos))
    return np.array(out, dtype=float).reshape(-1, 3)
