# SPDX-License-Identifier: LGPL-2.1-or-later
"""Where a corrected face meets its neighbours in a solid or shell: the geometry of a CAD
system's "replace face" (app layer; Part surfaces and curves, numpy for the small solves).

The corrected surface ``Sc`` has the nominal face's UV parametrisation, so every edge of the
nominal face has a 2D curve (pcurve) on it. :func:`plan` decides, edge by edge, how the
corrected face meets the rest of the shape:

* **kept**: the corrected surface moves the edge by at most :data:`PRECISION` (no neighbour
  needs re-trimming; the edge keeps the nominal's pcurve and its tolerance covers the move);
* **free**: no neighbour (an open shell's border): the nominal's pcurve;
* **degenerate** (a pole): it must stay a point on the corrected surface;
* **re-trimmed**: a neighbour meets the face at an angle. The new common edge is the
  intersection of ``Sc`` with the neighbour's surface ``Sg``: at samples ``t`` of the nominal
  edge, Newton's method finds the point on both surfaces in the plane through the nominal
  edge point normal to its tangent (4 unknowns: ``(u, v)`` on ``Sc``, ``(a, b)`` on ``Sg``);
  the ``(u, v)`` are interpolated as a 2D B-spline (the new pcurve on ``Sc``), with samples
  doubled until the curve between them stays within :data:`CURVE_TOL` of both surfaces;
* **tangent**: a neighbour meets the face at less than :data:`TANGENT_ANGLE` while the
  correction moves the edge: no intersection exists or it runs far along the neighbour, so
  the replacement is refused with the edge, the faces and the gap named;
* **region**: the neighbour is corrected too (a region of faces, ``plan(region=...)``): the
  edge keeps the nominal's pcurve, which both corrected surfaces follow. Where it ends at a
  re-trimmed neighbour, its end slides to where it meets that neighbour's surface.

A vertex the corrected surface moves by more than :data:`PRECISION` slides along the edge
that leaves the face there (between its two neighbours) to the point where that edge's curve
meets ``Sc`` (Newton, 3 unknowns); that edge is re-trimmed to it. The neighbours keep their
surfaces. OCCT's surface-surface intersection is the reference in the tests; it is not used
here because on these near-parallel offsets it returns the curve in pieces with gaps.
"""

import math
from dataclasses import dataclass, field

import FreeCAD
import numpy as np
import Part

from ..errors import GeometryError

#: modelling precision (mm): an edge or vertex the correction moves by no more stays where it
#: is (its tolerance covers the move); edge tolerances of the result must stay within it
PRECISION = 1e-4
#: neighbours meeting the face at less than this angle (degrees) are tangent: they cannot be
#: re-trimmed to meet a corrected face that moved off them
TANGENT_ANGLE = 10.0
#: largest distance (mm) of a re-trimmed edge's pcurve, between its samples, from the
#: intersection of the two surfaces
CURVE_TOL = 1e-6
#: Newton's method stops when every residual is below this (mm)
_NEWTON_TOL = 1e-10
_NEWTON_STEPS = 30
#: samples along a re-trimmed edge: start, most
_SAMPLES = 32
_MAX_SAMPLES = 4096

KEPT, FREE, DEGENERATE, RETRIM, REGION = "kept", "free", "degenerate", "re-trimmed", "region"


@dataclass
class EdgePlan:
    """How edge ``k`` of the face (``face.Edges[k]``) meets the rest of the shape."""

    k: int
    edge: object                 # the edge in the shape
    pedge: object                # the same edge in the face that carries the pcurves
    pcurve: tuple                # (Geom2d curve, first, last) on the corrected surface
    kind: str = FREE
    neighbour: object = None     # the other face at this edge
    move: float = 0.0            # largest distance the corrected surface moves it (mm)
    seam: bool = False           # a seam of the face itself (the neighbour is the face)
    samples: tuple = None        # re-trimmed: (t, nominal points, new points, (a, b) on
    #                              the neighbour), shapes (n,), (n, 3), (n, 3), (n, 2)
    surface: object = None       # the nominal surface (of the pcurves)
    pcurve0: tuple = None        # the nominal pcurve
    ends: tuple = (None, None)   # vertex numbers (in face.Vertexes) at first, last


@dataclass
class SideEdge:
    """An edge leaving a moved vertex of the face: re-trimmed to end on the corrected face."""

    edge: object
    first: float
    last: float
    vertex: int                  # number of the face's vertex (in face.Vertexes)
    at_last: bool                # that vertex is at the curve's last parameter


@dataclass
class Plan:
    """What :func:`plan` found: new pcurves on the corrected surface for the re-trimmed
    edges, the vertices' new places, the side edges to re-trim."""

    edges: list
    points: list                 # per face vertex: FreeCAD.Vector on the corrected surface
    side: list = field(default_factory=list)
    names: object = None

    def pcurves(self):
        """``{k: (Geom2d curve, first, last)}`` of every edge (for the face builder)."""
        return {p.k: p.pcurve for p in self.edges}

    def retrimmed_faces(self):
        """Numbers (1-based) of the neighbouring faces whose boundary was re-trimmed."""
        faces = {self.names.face_no(p.neighbour) for p in self.edges if p.kind == RETRIM}
        for s in self.side:
            for f in self.names.shape.ancestorsOfType(s.edge, Part.Face):
                faces.add(self.names.face_no(f))
        return sorted(faces)


class Names:
    """``FaceN``/``EdgeN`` numbers of sub-shapes of ``shape`` (as FreeCAD numbers them)."""

    def __init__(self, shape, face=None, region=()):
        self.shape = shape
        self.face = face
        self.region = list(region)      # faces corrected with ``face`` (a region's)
        self._faces = self._index(shape.Faces)
        self._edges = self._index(shape.Edges)

    @staticmethod
    def _index(items):
        out = {}
        for n, s in enumerate(items, 1):
            out.setdefault(s.hashCode(), []).append((n, s))
        return out

    @staticmethod
    def _find(table, s):
        for n, t in table.get(s.hashCode(), ()):
            if t.isSame(s):
                return n
        raise GeometryError("a sub-shape is not part of the shape")

    def face_no(self, f):
        return self._find(self._faces, f)

    def edge_no(self, e):
        return self._find(self._edges, e)

    def in_region(self, f):
        return any(f.isSame(g) for g in self.region)

    def between(self, plan):
        return "Edge%d between Face%d and Face%d" % (
            self.edge_no(plan.edge), self.face_no(self.face),
            self.face_no(plan.neighbour)) if plan.neighbour is not None else \
            "Edge%d of Face%d" % (self.edge_no(plan.edge), self.face_no(self.face))


def _vec(p):
    return np.array((p.x, p.y, p.z), dtype=float)


def _d1(surf, u, v):
    """Point and first derivatives of a Part surface, as numpy vectors."""
    return (_vec(surf.value(u, v)), _vec(surf.getDN(u, v, 1, 0)),
            _vec(surf.getDN(u, v, 0, 1)))


def _solve(residual, x, what):
    """Newton's method on ``residual(x) -> (r, J)``; ``x`` a numpy vector."""
    for _ in range(_NEWTON_STEPS):
        r, jac = residual(x)
        if np.max(np.abs(r)) < _NEWTON_TOL:
            return x
        try:
            x = x - np.linalg.solve(jac, r)
        except np.linalg.LinAlgError:
            break
    raise GeometryError("%s: the corrected surface and the neighbouring geometry do not "
                        "meet there (no converging intersection)" % what)


def section_point(sc, sg, uv, ab, x0, t, what, dt=None):
    """The point of ``sc`` and ``sg`` in the plane through ``x0`` normal to the unit vector
    ``t``, near ``uv`` on ``sc`` and ``ab`` on ``sg``: ``(uv, ab, point, duv)``.

    ``dt = (dx0, dtangent)``, the derivatives of ``x0`` and ``t`` along a curve parameter,
    gives ``duv``, the derivative of ``uv`` along it (implicit differentiation); else None.
    """

    def residual(x):
        p, pu, pv = _d1(sc, x[0], x[1])
        q, qa, qb = _d1(sg, x[2], x[3])
        r = np.append(p - q, np.dot(p - x0, t))
        jac = np.zeros((4, 4))
        jac[:3, 0], jac[:3, 1], jac[:3, 2], jac[:3, 3] = pu, pv, -qa, -qb
        jac[3, 0], jac[3, 1] = np.dot(pu, t), np.dot(pv, t)
        return r, jac

    x = _solve(residual, np.array([uv[0], uv[1], ab[0], ab[1]], dtype=float), what)
    point = _vec(sc.value(x[0], x[1]))
    duv = None
    if dt is not None:
        jac = residual(x)[1]
        rhs = np.zeros(4)
        rhs[3] = np.dot(dt[0], t) - np.dot(point - x0, dt[1])
        duv = np.linalg.solve(jac, rhs)[:2]
    return x[:2], x[2:], point, duv


def curve_point(sc, curve, uv, s, what):
    """Where the 3D ``curve`` meets ``sc``, near ``uv`` and curve parameter ``s``:
    ``(uv, s, point)``."""

    def residual(x):
        p, pu, pv = _d1(sc, x[0], x[1])
        c, cd = (_vec(w) for w in curve.getD1(x[2]))
        jac = np.stack([pu, pv, -cd], axis=1)
        return p - c, jac

    x = _solve(residual, np.array([uv[0], uv[1], s], dtype=float), what)
    return x[:2], float(x[2]), _vec(sc.value(x[0], x[1]))


def _uv(c2d, t):
    w = c2d.value(float(t))
    return w.x, w.y


def _angle(n1, n2):
    """Angle (degrees, 0 .. 90) between the tangent planes with normals n1, n2."""
    c = abs(float(np.dot(n1, n2)) / (np.linalg.norm(n1) * np.linalg.norm(n2)))
    return math.degrees(math.acos(min(1.0, c)))


def _pcurve(face, edge):
    c2d, a, b = face.curveOnSurface(edge)[:3]
    return c2d, a, b


def _edge_plans(names, face, pface, sc):
    plans = []
    pedges = pface.Edges
    for k, e in enumerate(face.Edges):
        pe = pedges[k]
        if pe.Degenerated != e.Degenerated or (
                not e.Degenerated and e.distToShape(pe.Vertexes[0])[0] > 1e-6):
            raise GeometryError("the B-spline form of the face has its edges in another order")
        p = EdgePlan(k, e, pe, _pcurve(pface, pe), surface=pface.Surface)
        p.pcurve0 = p.pcurve
        c2d, a, b = p.pcurve
        ts = np.linspace(a, b, 17)
        if e.Degenerated:
            pts = np.array([_vec(sc.value(*_uv(c2d, t))) for t in ts])
            p.kind, p.move = DEGENERATE, float(np.max(np.linalg.norm(pts - pts.mean(0), axis=1)))
        else:
            # the correction along the edge (the edge's 3D curve may lie off the surface by
            # its own tolerance, which stays as it is)
            p.move = max(float(np.linalg.norm(_vec(sc.value(*_uv(c2d, t)))
                                              - _vec(pface.Surface.value(*_uv(c2d, t)))))
                         for t in ts)
            others = [g for g in names.shape.ancestorsOfType(e, Part.Face) if not g.isSame(face)]
            if e.isSeam(face):
                p.neighbour, p.seam = face, True
            elif len(others) > 1:
                raise GeometryError("%s is shared by %d faces (a non-manifold edge)"
                                    % (names.between(p), len(others) + 1))
            elif others:
                p.neighbour = others[0]
            p.kind = (FREE if p.neighbour is None else
                      REGION if not p.seam and names.in_region(p.neighbour) else
                      KEPT if p.move <= PRECISION else RETRIM)
        plans.append(p)
    return plans


def _check_tangency(names, pface, plans, label):
    """Refuse a re-trim where the neighbour is tangent (or the face's own seam)."""
    for p in plans:
        if p.kind != RETRIM:
            continue
        c2d, a, b = p.pcurve
        sg = p.neighbour.Surface
        angle = 90.0
        for t in np.linspace(a, b, 9):
            x = p.pedge.valueAt(t)
            n1 = _vec(pface.Surface.normal(*_uv(c2d, t)))
            n2 = _vec(sg.normal(*sg.parameter(x)))
            angle = min(angle, _angle(n1, n2))
        if p.seam or angle < TANGENT_ANGLE:
            other = ("add Face%d to the region" % names.face_no(p.neighbour)) \
                if names.region and not p.seam else "the face alone (--face-only, Output = face)"
            raise GeometryError(
                "%s: cannot replace Face%d in its shape: %s is %s and the corrected face "
                "lies up to %.2f um off it there (a tangent neighbour cannot be re-trimmed to "
                "meet it); use a correction that vanishes along that edge, or %s"
                % (label, names.face_no(names.face), names.between(p),
                   "a seam of the face" if p.seam else
                   "tangent to its neighbour (%.1f degrees)" % angle, p.move * 1e3, other))


def _vertex_uv(face, plans):
    """Per vertex of ``face``: its (u, v) (from a pcurve end) and the edge ends there."""
    verts = face.Vertexes
    uv = [None] * len(verts)
    for p in plans:
        c2d, a, b = p.pcurve
        ends = []
        for t in (a, b):
            x = p.pedge.valueAt(t) if not p.edge.Degenerated else p.pedge.Vertexes[0].Point
            j = min(range(len(verts)), key=lambda i: (verts[i].Point - x).Length)
            ends.append(j)
            if uv[j] is None:
                w = c2d.value(t)
                uv[j] = (w.x, w.y)
        p.ends = tuple(ends)
    return uv


def _side_edges(names, face, vertex):
    """Edges of the shape at ``vertex`` that are not edges of ``face`` (nor degenerate)."""
    own = face.Edges
    return [e for e in names.shape.ancestorsOfType(vertex, Part.Edge)
            if not e.Degenerated and not any(e.isSame(o) for o in own)]


def _move_vertex(names, face, sc, j, uv, plans, label):
    """New place of vertex ``j`` when the correction moves it: on the side edge."""
    vertex = face.Vertexes[j]
    at = [p for p in plans if j in p.ends]
    if not any(p.kind == RETRIM for p in at):   # free or degenerate edges: it moves with Sc
        return _vec(sc.value(*uv)), None, uv
    side = _side_edges(names, face, vertex)
    where = "%s: Vertex at (%.3f, %.3f, %.3f) of Face%d" % (
        (label,) + tuple(vertex.Point) + (names.face_no(face),))
    joint = [p for p in at if p.kind == REGION]
    if joint:
        return _junction(names, sc, j, joint, [p for p in at if p.kind == RETRIM], side, where)
    if len(side) != 1:
        if not side and len({p.neighbour.hashCode() for p in at if p.neighbour}) <= 1:
            return None, None, uv           # on one neighbour only: from the edge's samples
        raise GeometryError("%s: the correction moves it by %.2f um and %d edges of the "
                            "neighbours meet there (expected one edge to slide along)"
                            % (where, np.linalg.norm(_vec(sc.value(*uv))
                                                     - _vec(face.Surface.value(*uv))) * 1e3,
                               len(side)))
    e = side[0]
    curve = e.Curve
    s0, s1 = e.ParameterRange
    at_last = (e.valueAt(s1) - vertex.Point).Length < (e.valueAt(s0) - vertex.Point).Length
    s = s1 if at_last else s0
    nuv, s_new, point = curve_point(sc, curve, uv, s, "%s (Edge%d)" % (where, names.edge_no(e)))
    tangent = _vec(curve.getD1(s_new)[1])
    normal = _vec(sc.normal(*nuv))
    if 90.0 - _angle(tangent, normal) < TANGENT_ANGLE:
        raise GeometryError("%s: Edge%d, which leaves the face there, is tangent to the "
                            "corrected surface" % (where, names.edge_no(e)))
    first, last = (s0, s_new) if at_last else (s_new, s1)
    if not last > first:
        raise GeometryError("%s: the correction moves the vertex past the other end of Edge%d"
                            % (where, names.edge_no(e)))
    return point, SideEdge(e, first, last, j, at_last), tuple(nuv)


def _junction(names, sc, j, joint, cut, side, where):
    """Vertex ``j`` where an edge shared with another corrected face of the region
    (``joint``) meets a re-trimmed neighbour (``cut``): the point where that edge, moved
    with ``sc`` along its nominal pcurve, meets the neighbour's surface; the edge's pcurve
    range ends there. ``(point, None, uv)``."""
    if len(joint) != 1 or len({p.neighbour.hashCode() for p in cut}) != 1 or \
            any(not any(names.in_region(f) for f in names.shape.ancestorsOfType(e, Part.Face))
                for e in side):
        raise GeometryError("%s: the correction moves it and more than one face outside the "
                            "region meets it there (expected one neighbour to re-trim)" % where)
    p = joint[0]
    c2d, a, b = p.pcurve
    last = p.ends[1] == j
    sg = cut[0].neighbour.Surface
    h = 1e-7 * (b - a)

    def residual(x):
        q, qa, qb = _d1(sg, x[1], x[2])
        s, su, sv = _d1(sc, *_uv(c2d, x[0]))
        duv = (np.array(_uv(c2d, x[0] + h)) - np.array(_uv(c2d, x[0] - h))) / (2 * h)
        return s - q, np.stack([su * duv[0] + sv * duv[1], -qa, -qb], axis=1)

    t = b if last else a
    x = _solve(residual, np.array((t,) + tuple(sg.parameter(p.pedge.valueAt(t)))),
               "%s (%s)" % (where, names.between(p)))
    if not (x[0] > a if last else x[0] < b):
        raise GeometryError("%s: the correction moves it past the other end of %s"
                            % (where, names.between(p)))
    p.pcurve = (c2d, a, float(x[0])) if last else (c2d, float(x[0]), b)
    uv = _uv(c2d, x[0])
    return _vec(sc.value(*uv)), None, uv


def _frame(p, t):
    """Point, unit tangent and their derivatives along the parameter at ``t`` of the nominal
    edge as its pcurve on the nominal surface (smooth where the edge's 3D curve is only an
    approximation of it); derivatives by central differences."""
    c2d, a, b = p.pcurve0
    surf = p.surface
    h = 1e-4 * (b - a)
    x = [_vec(surf.value(*_uv(c2d, t + k * h))) for k in (-1, 0, 1)]
    d1 = (x[2] - x[0]) / (2 * h)
    d2 = (x[2] - 2 * x[1] + x[0]) / (h * h)
    speed = np.linalg.norm(d1)
    tan = d1 / speed
    return x[1], tan, d1, (d2 - np.dot(d2, tan) * tan) / speed


def _interpolate(ts, uvs, duvs, closed):
    """A 2D B-spline through ``uvs`` at parameters ``ts`` with derivatives ``duvs``."""
    pts = [FreeCAD.Base.Vector2d(*w) for w in uvs]
    tans = [FreeCAD.Base.Vector2d(*d) for d in duvs]
    curve = Part.Geom2d.BSplineCurve2d()
    if closed:
        curve.interpolate(Points=pts[:-1], Parameters=[float(t) for t in ts], PeriodicFlag=True,
                          Tangents=tans[:-1], TangentFlags=[True] * (len(pts) - 1))
    else:
        curve.interpolate(Points=pts, Parameters=[float(t) for t in ts], Tangents=tans,
                          TangentFlags=[True] * len(pts))
    return curve


def _wrap(surf, ab):
    """``ab`` moved by the period into the bounds of a closed (or periodic) surface when it
    lies outside them (beyond the seam, where a closed B-spline is only extrapolated);
    None when it lies inside or the surface is open there."""
    bounds = surf.bounds()
    out = list(ab)
    moved = False
    for k, closed in enumerate((surf.isUClosed(), surf.isVClosed())):
        lo, hi = bounds[2 * k], bounds[2 * k + 1]
        period = hi - lo
        if not closed or not math.isfinite(period) or period <= 0:
            continue
        slack = 1e-9 * period
        if out[k] < lo - slack or out[k] > hi + slack:
            out[k] = lo + (out[k] - lo) % period
            moved = True
    return np.array(out) if moved else None


def _end_parameter(p, t, target):
    """The parameter near ``t`` where the plane normal to ``edge`` passes through
    ``target`` (the nominal edge extended beyond its end if need be)."""
    for _ in range(_NEWTON_STEPS):
        x0, tan, d1, dtan = _frame(p, t)
        g = np.dot(target - x0, tan)
        if abs(g) < _NEWTON_TOL:
            break
        t -= g / (np.dot(target - x0, dtan) - np.dot(d1, tan))
    return float(t)


def _edge_curve(names, sc, p, ends, label):
    """The re-trimmed edge's pcurve on ``sc``: samples (Newton, with their derivatives)
    interpolated, refined until it stays within CURVE_TOL of the intersection between the
    samples.

    ``ends`` gives, per end, None (the section there is the end) or ``(uv, point)``: the
    vertex the edge must end at. The samples run between the parameters whose section
    planes pass through the ends, so the pcurve's parametrisation has no kink there.

    Returns ``(curve, first, last, samples)``; ``samples`` = ``(t, nominal points, new
    points, (a, b) on the neighbour)`` of the last refinement (for the volume of the strip
    the neighbour gains or loses)."""
    c2d, a, b = p.pcurve
    sg = p.neighbour.Surface
    what = "%s: %s" % (label, names.between(p))
    closed = p.ends[0] == p.ends[1]
    reach = 10.0 * p.move + 0.01

    def section(t, uv, ab, x0=None):
        frame = _frame(p, float(t))
        x0 = frame[0] if x0 is None else x0
        for guess in (ab, None):
            if guess is None:
                guess = sg.parameter(FreeCAD.Vector(*x0))
            try:
                out = section_point(sc, sg, uv, guess, x0, frame[1], what, frame[2:])
                wrapped = _wrap(sg, out[1])
                if wrapped is not None:       # past the seam of a closed neighbour
                    out = section_point(sc, sg, out[0], wrapped, x0, frame[1], what,
                                        frame[2:])
            except GeometryError:
                continue
            if np.linalg.norm(out[2] - x0) <= reach:
                return out
        raise GeometryError("%s: the corrected surface and the neighbour do not meet near "
                            "(%.4f, %.4f, %.4f)" % ((what,) + tuple(x0)))

    t0 = a if ends[0] is None else _end_parameter(p, a, ends[0][1])
    t1 = b if ends[1] is None else _end_parameter(p, b, ends[1][1])
    n = _SAMPLES
    ab = sg.parameter(p.pedge.valueAt(a))
    while True:
        ts = np.linspace(t0, t1, n + 1)
        uvs, duvs, abs_, off = [], [], [], [0.0, 0.0]
        for i, t in enumerate(ts):
            w = c2d.value(float(t))
            uv, ab, x, duv = section(t, (w.x, w.y), ab)
            end = 0 if i == 0 else 1 if i == n else None
            if end is not None and ends[end] is not None:
                uv = ends[end][0]
                off[end] = float(np.linalg.norm(_vec(sc.value(*uv)) - x))
            uvs.append(tuple(uv))
            duvs.append(tuple(duv))
            abs_.append(ab)
        curve = _interpolate(ts, uvs, duvs, closed)
        err = 0.0
        for i, t in enumerate(0.5 * (ts[1:] + ts[:-1])):
            w = curve.value(float(t))
            x = _vec(sc.value(w.x, w.y))
            onto = section(t, (w.x, w.y), 0.5 * (abs_[i] + abs_[i + 1]), x)[2]
            # a vertex kept within PRECISION off the neighbour bends the end intervals
            allow = off[0] if i == 0 else off[1] if i == n - 1 else 0.0
            err = max(err, float(np.linalg.norm(onto - x)) - allow)
        if err <= CURVE_TOL:
            old = np.array([_frame(p, float(t))[0] for t in ts])
            new = np.array([_vec(sc.value(*w)) for w in uvs])
            return curve, float(t0), float(t1), (ts, old, new, np.array(abs_))
        if n >= _MAX_SAMPLES:
            raise GeometryError("%s: the intersection with the neighbour cannot be followed "
                                "within %.3g um (%.3g um with %d samples)"
                                % (what, CURVE_TOL * 1e3, err * 1e3, n))
        n *= 2


def plan(shape, index, pface, sc, label="compensation", region=()):
    """How ``shape.Faces[index]``, replaced by a face on ``sc``, meets the rest of ``shape``.

    Parameters
    ----------
    shape : Part.Shape
    index : int
        0-based face number.
    pface : Part.Face
        The same face with its pcurves in the parametrisation of ``sc`` (the face itself
        when it is a B-spline face; its ``toNurbs`` form otherwise), edges in the same order.
    sc : Part.BSplineSurface
        The corrected surface.
    region : list of Part.Face, optional
        Faces of ``shape`` corrected with this one (a region's): their common edges keep
        their pcurves (kind ``region``), they are not re-trimmed.

    Returns
    -------
    Plan

    Raises
    ------
    GeometryError
        A tangent neighbour (or the face's own seam) where the correction moves the edge,
        a pole the correction opens, a moved vertex with no single edge to slide along.
    """
    face = shape.Faces[index]
    names = Names(shape, face, region)
    plans = _edge_plans(names, face, pface, sc)
    _check_tangency(names, pface, plans, label)
    for p in plans:
        if p.kind == DEGENERATE and p.move > PRECISION:
            raise GeometryError("%s: the correction opens the pole of Face%d at Edge%d by "
                                "%.2f um (it must be the same all round a pole)"
                                % (label, index + 1, names.edge_no(p.edge), p.move * 1e3))
    uv = _vertex_uv(pface, plans)
    points, side = [None] * len(uv), []
    for j, w in enumerate(uv):
        x = _vec(sc.value(*w))
        if np.linalg.norm(x - _vec(pface.Surface.value(*w))) <= PRECISION:
            points[j] = x
            continue
        points[j], s, uv[j] = _move_vertex(names, face, sc, j, w, plans, label)
        if s is not None:
            side.append(s)
    for p in plans:
        if p.kind != RETRIM:
            continue
        ends = tuple((uv[j], points[j]) if points[j] is not None else None for j in p.ends)
        curve, a, b, p.samples = _edge_curve(names, sc, p, ends, label)
        p.pcurve = (curve, a, b)
    for j, x in enumerate(points):
        if x is None:               # from the re-trimmed edge's own end sample
            p = next(q for q in plans if j in q.ends and q.kind == RETRIM)
            c2d, a, b = p.pcurve
            w = c2d.value(a if p.ends[0] == j else b)
            points[j] = _vec(sc.value(w.x, w.y))
    return Plan(plans, [FreeCAD.Vector(*x) for x in points], side, names)
