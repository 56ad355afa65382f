# SPDX-License-Identifier: LGPL-2.1-or-later
"""Reach of planned points against the whole part, with OpenCASCADE (app layer, headless).

The core (:mod:`surfcomp.core.measurement.planning_reach`) checks the probe's paths against the
planned face itself; when the nominal face is a face of a solid (or of a shell with other faces),
the stylus ball must also keep off every other face: clear of it on the feed moves along the
normal (retract point to touch), and at least the clearance away from it on the rapid descent
from the safe height to the retract point (and the rapid climb back on the same line). Each
path is a segment; a face whose bounding box, widened by the distance kept, misses the
segment's is skipped, the others are measured with ``distToShape`` (exact, OCCT's
BRepExtrema).
"""

import numpy as np

from ..core.measurement.planning_reach import CLEAR_TOL
from ..errors import note

#: the reasons added to :data:`surfcomp.core.measurement.planning.REASONS`
REASONS = {
    "part-approach": "the stylus meets another face of the part on the approach along the "
                     "normal",
    "part-descent": note("the rapid descent from the safe height comes closer than ",
                         ("clearance",), " to another face of the part"),
}


def other_faces(shape, face_name):
    """The faces of ``shape`` other than its ``face_name`` (``FaceN``)."""
    if shape is None:
        return []
    k = int(face_name[4:]) - 1
    return [f for i, f in enumerate(shape.Faces) if i != k]


def exact_box(shape):
    """OCCT's optimal bounding box of ``shape``'s geometry (``BoundBox`` where this FreeCAD
    has no optimal box). Measured on a copy without the shape's mesh: once the GUI has
    drawn a shape, its display triangulation widened the optimal box of the shape itself
    (the example face's top 9.99 mm instead of 9.03), so a plan made in the GUI had a
    higher safe Z than ``plan`` on the same face."""
    if not hasattr(shape, "optimalBoundingBox"):
        return shape.BoundBox
    return shape.copy().optimalBoundingBox()


def part_top(shape, face):
    """The part's top (mm): the highest Z of the shape (or the face when there is none),
    from :func:`exact_box`."""
    return float(exact_box(shape if shape is not None else face).ZMax)


def _boxes(faces):
    out = np.empty((len(faces), 6))
    for k, f in enumerate(faces):
        b = exact_box(f)
        out[k] = (b.XMin, b.YMin, b.ZMin, b.XMax, b.YMax, b.ZMax)
    return out


def _path_shape(a, b):
    import FreeCAD
    import Part

    va, vb = FreeCAD.Vector(*a), FreeCAD.Vector(*b)
    if (vb - va).Length <= 1e-9:
        return Part.Vertex(va)
    return Part.LineSegment(va, vb).toShape()


def blocked_by_faces(a, b, faces, boxes, radius, tol=CLEAR_TOL):
    """Which segments ``a``-``b`` (N, 3) pass closer than ``radius - tol`` to one of
    ``faces``: bool (N,)."""
    out = np.zeros(len(a), dtype=bool)
    if not faces:
        return out
    lo = np.minimum(a, b) - radius
    hi = np.maximum(a, b) + radius
    for i in range(len(a)):
        hit = np.flatnonzero(np.all(boxes[:, :3] <= hi[i], axis=1)
                             & np.all(boxes[:, 3:] >= lo[i], axis=1))
        if not hit.size:
            continue
        path = _path_shape(a[i], b[i])
        for k in hit:
            if path.distToShape(faces[k])[0] < radius - tol:
                out[i] = True
                break
    return out


def part_check(shape, face_name, tip_radius, clearance):
    """The ``extra_check`` of :func:`surfcomp.core.measurement.planning.plan_points` for the face
    ``face_name`` (``FaceN``) of ``shape`` (None when the shape has no other face: a lone
    face): the ball (radius ``tip_radius``) clear of the other faces along the normal, and
    ``clearance`` away from them on the rapid descent."""
    faces = other_faces(shape, face_name)
    if not faces:
        return None
    boxes = _boxes(faces)

    def check(points, normals, touch, standoff, top):
        approach = blocked_by_faces(standoff, touch, faces, boxes, tip_radius)
        descent = blocked_by_faces(top, standoff, faces, boxes, tip_radius + clearance)
        descent &= ~approach
        return [("part-approach", approach), ("part-descent", descent)]

    return check


def plan_face(nominal, layout, count, settings, order="auto", progress=None):
    """``(plan, checked_part)``: plan on a :class:`surfcomp.app.nominal.Nominal` face with
    its trim boundary, the part's top and, when the shape has other faces, the paths checked
    against them (``checked_part`` True then)."""
    from ..core.measurement.planning import plan_points
    from ..core.measurement.planning_face import FaceDomain
    from .nominal import boundary_polylines

    domain = FaceDomain(nominal.surface, nominal.outward,
                        boundary_polylines(nominal.bspline_face))
    check = part_check(nominal.shape, nominal.face_name, settings.tip_radius,
                       settings.clearance)
    plan = plan_points(domain, layout, count, settings,
                       top_z=part_top(nominal.shape, nominal.face), order=order,
                       extra_check=check, progress=progress)
    return plan, check is not None
