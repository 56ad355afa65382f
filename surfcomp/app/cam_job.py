# SPDX-License-Identifier: LGPL-2.1-or-later
"""CAM helpers: a Job with a 3D Surface finishing operation, post-processing to text.

Written once for every FreeCAD version: what differs between 0.20 (``PathScripts.*``)
and 1.x (``Path.*``, 1.1's tool-bit library) is behind :mod:`surfcomp.app.cam`. No
FreeCADGui: everything runs in ``freecadcmd`` and in a plain ``python3``.
"""

from ..errors import GCodeError, InputError
from . import cam

#: a Job on document objects (the adapter's, for callers of this module)
create_job = cam.create_job


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
    doc = job.Document
    bit = cam.create_tool_bit(doc, cam.BALL_END_BIT, "BallEnd")
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
        tc = cam.create_tool_controller("TC: Ball end", bit, 1)
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
    clone = model_clone(job, obj)
    if clone is None:
        raise InputError("%s is not in the model of job %s" % (obj.Label, job.Label))
    op = cam.create_operation("Surface", name, job)
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
    text = cam.load_post(post).export(post_list(job), "-", args)
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
