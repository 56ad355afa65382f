# SPDX-License-Identifier: LGPL-2.1-or-later
"""The nominal face as plain data, taken from a ``Part.Face`` without numpy (app layer).

A face is chosen in a shape (:func:`pick_face`), given as a B-spline face
(:func:`to_bspline_face`) and cut to its work surface (:func:`work_surface`); what the
compensation needs of it is then plain Python data (:class:`FaceData`: the B-spline
surface's poles, knots and degrees as lists, the face's orientation, the ends of its
straight boundary edges and, on request, its boundary polylines).
:func:`surfcomp.app.nominal.nominal_from_data` makes the :class:`surfcomp.app.nominal.Nominal`
of it.

This module imports neither numpy nor FreeCAD at import time (Part only in its functions):
the reader child of the direct program route (:mod:`surfcomp.app.cadread`) forks before its
parent imports either, imports FreeCAD and Part, reads the STEP file and sends a
:class:`FaceData` back, while the parent imports the numerics beside it; the parent never
imports FreeCAD at all.
"""

from dataclasses import dataclass

from ..core.limits import MAX_DEGREE
from ..core.memory import collector_paused
from ..errors import GeometryError

#: boundary points per edge for integrals over trimmed faces and the inside test
EDGE_POINTS = 400

#: share of the face's UV range the work surface keeps beyond the face's UV bounds (where
#: the underlying surface extends that far): the edges of a neighbour re-trimmed to meet the
#: corrected face can leave the face's UV box by the correction's slope, and their 2D curves
#: must stay on the surface (else a STEP reader that rebuilds them, OCCT 7.7 and later,
#: widens the edge's tolerance to the gap)
WORK_MARGIN = 0.05


@dataclass
class RawSurface:
    """A non-periodic ``Part.BSplineSurface`` as lists: ``poles`` (rows of ``(x, y, z)``),
    ``weights`` (rows, or None when not rational), knots and multiplicities per direction,
    degrees."""

    poles: list
    weights: list
    u_knots: list
    u_mults: list
    v_knots: list
    v_mults: list
    u_degree: int
    v_degree: int


@dataclass
class FaceData:
    """What the compensation takes of a nominal face (see module docstring).

    ``surface``: the :class:`RawSurface` of the work surface; ``bounds``: the face's
    parameter bounds ``(u0, u1, v0, v1)``; ``outward``: +1 when the face's outward normal is
    Su x Sv, -1 when the face is reversed; ``converted``: what the surface was when it had to
    be converted to a B-spline (e.g. ``'Cylinder'``), else None; ``line_ends``: the
    :func:`line_ends` of its edges; ``boundary``: its :func:`boundary_polylines` as lists
    of ``(u, v)``, or None when not asked for."""

    face_name: str
    surface: RawSurface
    bounds: tuple
    outward: int
    converted: str = None
    line_ends: list = None
    boundary: list = None


def geometry_box(shape):
    """The bounding box of ``shape``'s geometry, as it is for the shape read from its file:
    measured on a copy, without the triangulation the GUI draws or a CAM operation meshes
    on the shape itself (with one, OCCT bounds the mesh instead: the example face's box is
    64.28 mm across, not 64.42 mm, so a region's field radius, a share of it, differed
    between the GUI and the command line)."""
    return shape.copy().BoundBox


def surface_type(face):
    """The face's surface type (``'BSplineSurface'``, ``'Plane'``, ...), or None when
    OpenCASCADE holds no surface for it (a B-spline read with a degree above its limit)."""
    try:
        return face.Surface.TypeId.split("::Geom")[-1]
    except (TypeError, RuntimeError, AttributeError):
        return None


def pick_face(shape, face_name=None, source=None):
    """Return ``(face, 'FaceN')``: the named face, or the only B-spline face of ``shape``."""
    faces = shape.Faces
    if face_name:
        name = face_name.strip()
        if not (name.startswith("Face") and name[4:].isdigit()):
            raise GeometryError("invalid face name %r (expected Face1 .. Face%d)"
                                % (face_name, len(faces)), file=source)
        k = int(name[4:])
        if not 1 <= k <= len(faces):
            raise GeometryError("the shape has no %s (it has %s)"
                                % (name, "one face: Face1" if len(faces) == 1 else
                                   "%d faces: Face1 .. Face%d" % (len(faces), len(faces))),
                                file=source)
        return faces[k - 1], name
    bs = [(k, f) for k, f in enumerate(faces, 1) if surface_type(f) == "BSplineSurface"]
    if len(faces) == 1:
        return faces[0], "Face1"
    if len(bs) == 1:
        return bs[0][1], "Face%d" % bs[0][0]
    kinds = {}
    for f in faces:
        kind = surface_type(f) or "unreadable"
        kinds[kind] = kinds.get(kind, 0) + 1
    raise GeometryError("%s B-spline faces among %d faces (%s): choose one with --face FaceN"
                        % ("no" if not bs else "%d" % len(bs), len(faces),
                           ", ".join("%d %s" % (c, k) for k, c in sorted(kinds.items())))
                        + ("; B-spline faces: " + ", ".join("Face%d" % k for k, _ in bs[:20])
                           if bs else ""), file=source)


def to_bspline_face(face):
    """Return ``(bspline_face, converted)``: the face's geometry as a B-spline face.

    B-spline faces are kept as they are; Bezier, analytic, revolution, extrusion and
    offset surfaces are converted with OCCT (``Face.toNurbs``), which keeps the geometry,
    the boundary (its pcurves move to the B-spline's parametrisation), the order of the
    edges and the orientation.
    """
    import Part

    converted = surface_type(face)
    if converted is None:
        raise GeometryError("the face's surface cannot be read: OpenCASCADE holds no surface "
                            "for it (a B-spline of degree above %d, its limit, or a damaged "
                            "file?)" % MAX_DEGREE)
    if converted == "BSplineSurface":
        return face, None
    try:
        return face.toNurbs().Faces[0], converted
    except (Part.OCCError, RuntimeError, IndexError) as exc:
        raise GeometryError("cannot convert the %s face to a B-spline surface: %s"
                            % (converted, exc)) from exc


def work_surface(bface):
    """The B-spline surface of ``bface`` made non-periodic and cut to the face's UV bounds
    widened by :data:`WORK_MARGIN` (same parametrisation): the surface the compensation
    works on."""
    u0, u1, v0, v1 = bface.ParameterRange
    du, dv = WORK_MARGIN * (u1 - u0), WORK_MARGIN * (v1 - v0)
    u0, u1, v0, v1 = u0 - du, u1 + du, v0 - dv, v1 + dv
    bs = bface.Surface.copy()
    if bs.isUPeriodic():
        bs.setUNotPeriodic()
    if bs.isVPeriodic():
        bs.setVNotPeriodic()
    bu0, bu1, bv0, bv1 = bs.bounds()
    tol = 1e-12
    if u0 > bu0 + tol or u1 < bu1 - tol or v0 > bv0 + tol or v1 < bv1 - tol:
        bs.segment(max(u0, bu0), min(u1, bu1), max(v0, bv0), min(v1, bv1))
    return bs


def raw_surface(bs):
    """The :class:`RawSurface` of a ``Part.BSplineSurface`` (periodic ones made non-periodic
    on a copy: the argument is never modified)."""
    if bs.isUPeriodic() or bs.isVPeriodic():
        bs = bs.copy()
        if bs.isUPeriodic():
            bs.setUNotPeriodic()
        if bs.isVPeriodic():
            bs.setVNotPeriodic()
    with collector_paused():
        poles = [[tuple(p) for p in row] for row in bs.getPoles()]
    weights = bs.getWeights() if bs.isURational() or bs.isVRational() else None
    return RawSurface(poles, weights, bs.getUKnots(), bs.getUMultiplicities(), bs.getVKnots(),
                      bs.getVMultiplicities(), bs.UDegree, bs.VDegree)


def _pcurves(face):
    """``(pcurve, first, last, reversed)`` of every edge of ``face``, wire by wire."""
    for e in (e for w in face.Wires for e in w.childShapes()):
        c2d, a, b = face.curveOnSurface(e)[:3]
        yield c2d, a, b, e.Orientation == "Reversed"


def line_ends(face):
    """The ``((u, v), (u, v))`` ends of every edge of ``face`` in its direction in the wire
    when every edge is a straight line in (u, v), else None (what
    :func:`surfcomp.app.nominal.bounds_whole_domain` needs)."""
    import Part

    ends = []
    for c2d, a, b, rev in _pcurves(face):
        if not isinstance(c2d, (Part.Geom2d.Line2d, Part.Geom2d.Line2dSegment)):
            return None
        p, q = c2d.value(a), c2d.value(b)
        ends.append(((q.x, q.y), (p.x, p.y)) if rev else ((p.x, p.y), (q.x, q.y)))
    return ends


def boundary_points(face, points=EDGE_POINTS):
    """The face's edges as lists of ``(u, v)`` (pcurves sampled at ``points`` evenly spaced
    parameters), each in its direction in the face's wire (see
    :func:`surfcomp.app.nominal.boundary_polylines`)."""
    out = []
    for c2d, a, b, rev in _pcurves(face):
        step = (b - a) / (points - 1)
        ts = [a + k * step for k in range(points - 1)] + [b]
        if rev:
            ts.reverse()
        out.append([(p.x, p.y) for p in (c2d.value(t) for t in ts)])
    return out


def face_data(face, face_name, boundary=False):
    """``(FaceData, bspline_face)`` of ``face`` (``boundary``: with its
    :func:`boundary_points`)."""
    import Part

    bface, converted = to_bspline_face(face)
    try:
        raw = raw_surface(work_surface(bface))
    except (Part.OCCError, ValueError, OverflowError) as exc:
        raise GeometryError("the face's B-spline surface cannot be used: %s" % exc) from None
    data = FaceData(face_name, raw, tuple(bface.ParameterRange),
                    -1 if bface.Orientation == "Reversed" else 1, converted, line_ends(bface),
                    boundary_points(bface) if boundary else None)
    return data, bface
