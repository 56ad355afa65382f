# SPDX-License-Identifier: LGPL-2.1-or-later
"""The one face builder: the corrected face (and the nominal's shape with it) for every
route - the command line's ``-o``, the freecadcmd job, the document features and the GUI.

The corrected surface has the nominal's UV parametrisation, so the nominal face's boundary
(outer wire and holes, as 2D curves on the surface) is rebuilt on it unchanged: a trimmed
face stays trimmed, holes stay holes, and the boundary moves only by the correction there.

In a solid or shell the corrected face replaces the nominal face as a CAD system's "replace
face" does (:func:`replace_face`): the neighbouring faces keep their surfaces and are
re-trimmed where they meet the corrected surface (:mod:`surfcomp.app.retrim`), so the
result is closed with edge tolerances at the modelling precision, not by a gap-covering
tolerance.
"""

from dataclasses import dataclass, field

import FreeCAD  # noqa: F401  (Part needs FreeCAD imported first)
import numpy as np
import Part

from ..core.limits import NIL_INTEGRAL
from ..core.surface.bspline import clamped
from ..errors import GeometryError
from . import retrim
from .convert import surface_to_part
from .volumes import correction_volume, volume_change

#: modelling precision (mm): the largest edge tolerance of a corrected face or shape
PRECISION = retrim.PRECISION
#: the solid's volume change and the correction's integral must agree this well (relative)
VOLUME_CHECK = 0.02


@dataclass
class Output:
    """A compensation's output shape and what it did to the nominal's shape.

    ``kind`` is ``face`` (the corrected face alone) or ``shape`` (the nominal's shape with
    the face replaced). Volumes in mm^3: ``correction_volume`` is the integral of the
    correction over the face (positive = material removed), ``volume_change`` the solid's
    volume after minus before (None for a face or a shape without solids), which should be
    ``-correction_volume``.
    """

    shape: object
    kind: str
    edge_tolerance: float        # largest tolerance of the corrected face's edges, vertices
    correction_volume: float = 0.0
    volume_change: float = None
    retrimmed: list = field(default_factory=list)
    #: the corrected surface (surfcomp.core.surface.bspline.Surface) when ``shape`` is the face
    #: bounded by its knot domain, which surfcomp.io.step_face writes from the pole net
    natural: object = None

    def volume_mismatch(self):
        """``volume_change / -correction_volume - 1`` (None without a volume change, or for
        a nil correction)."""
        if self.volume_change is None or not abs(self.correction_volume) >= NIL_INTEGRAL:
            return None
        return self.volume_change / -self.correction_volume - 1.0

    def as_dict(self):
        mismatch = self.volume_mismatch()
        return {"kind": self.kind, "faces": len(self.shape.Faces),
                "solids": len(self.shape.Solids),
                "max_edge_tolerance_mm": self.edge_tolerance,
                "correction_integral_mm3": self.correction_volume,
                "volume_change_mm3": self.volume_change,
                "volume_change_vs_integral": mismatch,
                "retrimmed_faces": ["Face%d" % k for k in self.retrimmed]}

    def warnings(self, label):
        """A warning when the volume change and the correction's integral disagree."""
        mismatch = self.volume_mismatch()
        if mismatch is None or abs(mismatch) <= VOLUME_CHECK or \
                abs(self.volume_change + self.correction_volume) < 1e-6:
            return []
        return ["%s: the solid's volume changed by %.4f mm^3 where the correction gives "
                "%.4f mm^3 (-integral of delta dA; %+.1f %%, more than %g %%)"
                % (label, self.volume_change, -self.correction_volume, 100 * mismatch,
                   100 * VOLUME_CHECK)]


def _index(items, e):
    for k, x in enumerate(items):
        if x.isSame(e):
            return k
    raise GeometryError("an edge of the face's wire is not an edge of the face")


def check_rebuildable(face, source=None):
    """Refuse, before any work, a face whose corrected form cannot be built: one with a seam
    (a closed surface such as a full sphere or cylinder), which a corrected surface does not
    close again (:func:`rebuild_face` would refuse it after the computation)."""
    if any(e.isSeam(face) for e in face.Edges):
        raise GeometryError("the face has a seam (a closed surface such as a full sphere or "
                            "cylinder): a corrected surface does not close it; split the face "
                            "at the seam first (expected an open face)", file=source)


def rebuild_face(face, bs, pcurves=None):
    """The face ``face`` with its surface replaced by ``bs`` (same parametrisation).

    The boundary is rebuilt from the face's own 2D curves (pcurves) on the new surface,
    so trimmed faces and holes keep their place in parameter space; ``pcurves`` replaces
    some of them: ``{k: (Geom2d curve, first, last)}`` for ``face.Edges[k]`` (the
    re-trimmed edges of :func:`replace_face`).
    """
    pcurves = pcurves or {}
    edges = face.Edges
    outer = face.OuterWire
    wires = [outer] + [w for w in face.Wires if not w.isSame(outer)]
    # the pcurves of a face meet within its vertices' tolerance, not exactly
    vtol = max([1e-7] + [v.Tolerance for v in face.Vertexes])
    new_wires = []
    for w in wires:
        new = []
        for e in w.Edges:
            if e.isSeam(face):
                raise GeometryError("the face has a seam (a closed surface): a corrected "
                                    "surface does not close it")
            k = _index(edges, e)
            c2d, a, b = pcurves.get(k) or face.curveOnSurface(e)[:3]
            new.append(c2d.toShape(bs, a, b))
            new[-1].fixTolerance(vtol, Part.Vertex)
        new_wires.append(Part.Wire(new))
    out = Part.Face(bs, new_wires[0])
    if len(new_wires) > 1:
        out = out.cutHoles(new_wires[1:]) or out
    if face.Orientation == "Reversed":
        out.reverse()
    if not _valid(out):
        out.fix(1e-7, 1e-7, PRECISION)
    if not _valid(out) or len(out.Edges) != len(face.Edges) or \
            len(out.Wires) != len(face.Wires):
        raise GeometryError("cannot rebuild the face on the corrected surface (%d wires, %d "
                            "edges instead of %d, %d)" % (len(out.Wires), len(out.Edges),
                                                          len(face.Wires), len(face.Edges)))
    return out


def natural_face(face, surf, samples=5):
    """True when ``face`` is the face bounded by the knot domain of ``surf`` (the Surface
    of ``face.Surface``; polynomial and clamped): one wire of four edges, each running
    along its own side of the domain. A side collapsed to a point (a degenerated edge,
    which OpenCASCADE leaves out of the STEP loop) is not one."""
    if surf.weights is not None or not clamped(surf) or len(face.Wires) != 1 or \
            len(face.Edges) != 4 or any(e.Degenerated for e in face.Edges):
        return False
    domain = np.array([surf.knots_u[0], surf.knots_u[-1], surf.knots_v[0], surf.knots_v[-1]])
    tol = 1e-12 * max(1.0, float(np.max(np.abs(domain))))
    if np.max(np.abs(np.array(face.ParameterRange) - domain)) > tol:
        return False
    sides = set()
    for e in face.Edges:
        pcurve = face.curveOnSurface(e)
        if not pcurve:
            return False
        c2d, a, b = pcurve[:3]
        uv = np.array([[c2d.value(t).x, c2d.value(t).y] for t in np.linspace(a, b, samples)])
        side = [k for k in range(4) if np.max(np.abs(uv[:, k // 2] - domain[k])) <= tol]
        if len(side) != 1:
            return False
        sides.add(side[0])
    return len(sides) == 4


def _valid(shape):
    """isValid and a clean BRepCheck."""
    if not shape.isValid():
        return False
    try:
        shape.check()
    except ValueError:
        return False
    return True


def _tolerance(shape):
    return max([e.Tolerance for e in shape.Edges] + [v.Tolerance for v in shape.Vertexes])


def _nearest(items, point, what):
    vertex = Part.Vertex(point)
    dist = [x.distToShape(vertex)[0] for x in items]
    k = int(np.argmin(dist))
    if dist[k] > 10 * PRECISION:
        raise GeometryError("the rebuilt face has no %s at (%.4f, %.4f, %.4f)"
                            % ((what,) + tuple(point)))
    return items[k]


def _oriented(shape, like):
    shape.Orientation = like.Orientation
    return shape


def replace_face(shape, index, pface, bs, label="compensation"):
    """``shape`` with ``shape.Faces[index]`` replaced by its boundary on ``bs``, the
    neighbours re-trimmed to meet it (:func:`surfcomp.app.retrim.plan`).

    Parameters
    ----------
    shape : Part.Shape
        A solid, shell or compound holding the face.
    index : int
        0-based face number.
    pface : Part.Face
        The face with its pcurves in the parametrisation of ``bs`` (itself when it is a
        B-spline face), edges in the same order as the face in ``shape``.
    bs : Part.BSplineSurface
        The corrected surface.

    Returns
    -------
    (Part.Shape, surfcomp.app.retrim.Plan)
        The shape (same faces in the same order; the other faces keep their surfaces) and
        how its neighbours were re-trimmed.

    Raises
    ------
    GeometryError
        A tangent neighbour where the correction moves the edge (naming edge, faces and
        gap), or a result that is not valid, not closed like the nominal, or whose edge
        tolerances exceed :data:`PRECISION`.
    """
    plan = retrim.plan(shape, index, pface, bs, label)
    new = rebuild_face(pface, bs, plan.pcurves())
    out = shape.replaceShape(replacement_pairs(shape.Faces[index], new, bs, plan))
    out.fix(1e-7, 1e-7, PRECISION)
    _check_replaced(shape, out, index, label)
    return out, plan


def replacement_pairs(old, new, bs, plan):
    """``(old, new)`` sub-shape pairs for ``Shape.replaceShape``: the face ``old`` by ``new``
    (on ``bs``), the edges and vertices its neighbours share with it by ``new``'s, the side
    edges shortened as ``plan`` (:func:`surfcomp.app.retrim.plan`) says. Edges shared with
    another corrected face of a region are left out (that face is replaced whole)."""
    pairs = [(old, new)]
    new_edges = new.Edges
    for p in plan.edges:
        if p.kind == retrim.REGION:
            continue
        c2d, a, b = p.pcurve
        mid = c2d.value(0.5 * (a + b))
        pairs.append((p.edge, _oriented(_nearest(new_edges, bs.value(mid.x, mid.y), "edge"),
                                        p.edge)))
    new_vertexes = new.Vertexes
    vmap = {}
    for j, v in enumerate(old.Vertexes):
        vmap[j] = _oriented(_nearest(new_vertexes, plan.points[j], "vertex"), v)
        pairs.append((v, vmap[j]))
    for s in plan.side:
        e = Part.Edge(s.edge.Curve, s.first, s.last)
        moved, kept = (e.lastVertex(), e.firstVertex()) if s.at_last else \
            (e.firstVertex(), e.lastVertex())
        far = _nearest(s.edge.Vertexes, kept.Point, "vertex")
        pairs += [(moved, _oriented(vmap[s.vertex], moved)), (kept, _oriented(far, kept)),
                  (s.edge, _oriented(e, s.edge))]
    return pairs


def _check_replaced(shape, out, index, label):
    problems = []
    if not _valid(out):
        problems.append("not valid")
    if len(out.Faces) != len(shape.Faces):
        problems.append("%d faces instead of %d" % (len(out.Faces), len(shape.Faces)))
    if len(out.Solids) != len(shape.Solids):
        problems.append("%d solids instead of %d" % (len(out.Solids), len(shape.Solids)))
    closed = [s.isClosed() for s in shape.Shells]
    if [s.isClosed() for s in out.Shells] != closed:
        problems.append("its shells are not closed as the nominal's are")
    if not problems:
        for k, (a, b) in enumerate(zip(shape.Faces, out.Faces)):
            if k != index and a.Surface.TypeId != b.Surface.TypeId:
                problems.append("Face%d changed its type" % (k + 1))
                break
        if out.Faces[index].Surface.TypeId != "Part::GeomBSplineSurface":
            problems.append("Face%d is not the corrected surface" % (index + 1))
        # the edges the correction moves by at most PRECISION keep their own tolerance
        tol = _tolerance(out.Faces[index])
        allowed = PRECISION + _tolerance(shape.Faces[index])
        if tol > allowed:
            problems.append("edge tolerance %.3g mm (more than %g mm)" % (tol, allowed))
    if problems:
        raise GeometryError("%s: cannot replace Face%d in the nominal's shape (%s); use the "
                            "face alone (--face-only, Output = face)"
                            % (label, index + 1, ", ".join(problems)))


def has_neighbours(shape, face):
    """True when ``face`` sits in a shell (or solid) of ``shape`` with other faces, not a
    lone face (a STEP file of one face reads back as a shell of that face)."""
    return len(shape.Faces) > 1 and any(any(f.isSame(face) for f in s.Faces)
                                        for s in shape.Shells)


def corrected_shape(nominal, corrected, output="face", label="compensation"):
    """The output shape of a compensation: an :class:`Output`.

    Parameters
    ----------
    nominal : surfcomp.app.nominal.Nominal
        ``nominal.face`` is the face ``nominal.face_name`` of ``nominal.shape``.
    corrected : surfcomp.core.surface.bspline.Surface
    output : {'face', 'solid'}
        ``face``: the nominal face's boundary on the corrected surface. ``solid``:
        ``nominal.shape`` with the face replaced and its neighbours re-trimmed
        (:func:`replace_face`): same number and order of faces; a lone face (in no shell or
        solid) gives the face.
    """
    from .face_data import to_bspline_face

    bs = surface_to_part(corrected)
    integral = correction_volume(nominal, corrected)
    shape = nominal.shape
    idx = int(nominal.face_name[4:]) - 1
    if output == "face" or shape is None or not has_neighbours(shape, shape.Faces[idx]):
        new = rebuild_face(nominal.bspline_face, bs)
        return Output(new, "face", _tolerance(new), integral,
                      natural=corrected if natural_face(new, corrected) else None)
    pface = to_bspline_face(shape.Faces[idx])[0]
    out, plan = replace_face(shape, idx, pface, bs, label)
    change = None
    if any(s.isClosed() and any(f.isSame(shape.Faces[idx]) for f in s.Faces)
           for s in shape.Shells):
        change = volume_change(nominal, corrected, out.Faces[idx], plan)
    return Output(out, "shape", _tolerance(out.Faces[idx]), integral, change,
                  plan.retrimmed_faces())
