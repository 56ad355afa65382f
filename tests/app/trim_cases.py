# SPDX-License-Identifier: LGPL-2.1-or-later
"""The trimmed faces, solids, fields and checks shared by the trim tests (test_trim.py,
test_trim_neighbours.py)."""

import os
import subprocess
import sys

import FreeCAD
import numpy as np
import Part

from surfcomp.app.convert import surface_from_part
from surfcomp.app.nominal import boundary_polylines
from surfcomp.core.surface import bspline
from surfcomp.core.surface.trimmed import domain_integral, knots_of
from tests.app.helpers import EXAMPLE_STEP, ROOT, realised_by_occt, write_cmm_csv
from tests.conftest import REALDATA

UM = 1e-3
BOXED_SPHERE = os.path.join(REALDATA, "cad", "axom_data", "boxed_sphere.step")
PIPE = os.path.join(REALDATA, "cad", "PyGeM", "test_pipe.step")


# -- the test parts ------------------------------------------------------------------------

def circle_face(r=0.35, hole=None):
    """The example surface trimmed by the circle of radius ``r`` around (0.5, 0.5) in (u, v)
    (r = 0.35: 1 edge, 457.5 mm^2), optionally with a circular hole ``((u, v), radius)``."""
    bs = Part.read(EXAMPLE_STEP).Faces[0].Surface
    c = Part.Geom2d.Circle2d(FreeCAD.Base.Vector2d(0.5, 0.5), r)
    face = Part.Face(bs, Part.Wire([c.toShape(bs)]))
    if hole:
        h = Part.Geom2d.Circle2d(FreeCAD.Base.Vector2d(*hole[0]), hole[1])
        face.cutHoles([Part.Wire([h.toShape(bs)])])
        face.fix(1e-7, 1e-7, 1e-7)                  # the hole's wire runs the other way
    assert face.isValid()
    return face


HOLE = ((0.5, 0.55), 0.1)


def extruded(face, height=20.0):
    """``face`` as the top of a solid extruded ``height`` mm down; (solid, top index)."""
    solid = face.extrude(FreeCAD.Vector(0, 0, -height))
    top = max(range(len(solid.Faces)), key=lambda k: solid.Faces[k].CenterOfMass.z)
    assert solid.isValid() and solid.ShapeType == "Solid"
    return solid, top


def pipe_solid():
    """PyGeM's pipe (6 NURBS faces, separate shells in the file) sewn into a solid."""
    from surfcomp.app.cadread import read_cad

    shell = Part.Shape(read_cad(PIPE))
    shell.sewShape(1e-2)
    solid = Part.Solid(shell)
    if solid.Volume < 0:
        solid.reverse()
    assert solid.isValid() and len(solid.Faces) == 6 and len(solid.Edges) == 12
    return solid


def raw_deviation(P):
    """The machined part's deviation (mm) at points P: 14 um mean, smooth."""
    x, y = P[..., 0], P[..., 1]
    return (0.0115 + 0.010 * np.sin(np.pi * x / 45.0) * np.cos(np.pi * y / 60.0)
            - 0.004 * (y / 45.0) ** 2)


def grid(nominal, n, box=None, margin=0.0):
    """Points, outward normals and (u, v) of an n x n grid over ``box`` (fractions of the
    face's UV range: (u0, u1, v0, v1)) shrunk by ``margin``."""
    (u0, u1), (v0, v1) = nominal.surface.u_range, nominal.surface.v_range
    a0, a1, b0, b1 = box or (0.0, 1.0, 0.0, 1.0)
    s = np.linspace(a0 + margin, a1 - margin, n)
    t = np.linspace(b0 + margin, b1 - margin, n)
    U, V = np.meshgrid(u0 + (u1 - u0) * s, v0 + (v1 - v0) * t, indexing="ij")
    P = bspline.evaluate(nominal.surface, U, V)
    N = bspline.normals(nominal.surface, U, V) * nominal.outward
    return P, N, U, V


#: the square inscribed in the circle (fractions of the face's UV box, the circle's
#: bounding square): the probe stays on the trimmed face
INSIDE = (0.16, 0.84, 0.16, 0.84)


def measure(path, nominal, n, dev, box=None, margin=0.0):
    """Write a CMM file with deviations ``dev(P, U, V)``; return (P, N, U, V, d)."""
    P, N, U, V = grid(nominal, n, box, margin)
    d = dev(P, U, V)
    write_cmm_csv(path, P, N, d)
    return P, N, U, V, d


def bump(nominal, amplitude=0.014, shrink=0.6):
    """Deviations that vanish near the face's boundary: a cos^4 bump around the (u, v)
    point farthest from the trim, of radius ``shrink`` times that distance."""
    (u0, u1), (v0, v1) = nominal.surface.u_range, nominal.surface.v_range
    face = nominal.bspline_face
    edge = (np.concatenate(boundary_polylines(face, 200)) - [u0, v0]) / [u1 - u0, v1 - v0]
    best, centre = 0.0, None
    for a in np.linspace(0.05, 0.95, 31):
        for b in np.linspace(0.05, 0.95, 31):
            if face.isPartOfDomain(u0 + a * (u1 - u0), v0 + b * (v1 - v0)):
                dist = np.hypot(edge[:, 0] - a, edge[:, 1] - b).min()
                if dist > best:
                    best, centre = dist, (a, b)
    radius = shrink * best

    def dev(P, U, V):
        r = np.hypot((U - u0) / (u1 - u0) - centre[0], (V - v0) / (v1 - v0) - centre[1])
        return amplitude * np.cos(0.5 * np.pi * np.minimum(r / radius, 1.0)) ** 4

    return dev


# -- independent checks --------------------------------------------------------------------

def realised_ok(face, P, N, d, on_face=None, reach=0.5, sample=40):
    """Largest |realised - intended| correction (mm) at a seeded sample of the measured
    points on the face, measured by OCCT on ``face`` along the nominal normals (the
    pipeline's own check figure covers every point)."""
    P, N, d = P.reshape(-1, 3), N.reshape(-1, 3), np.ravel(d)
    k = np.arange(d.size) if on_face is None else np.nonzero(on_face)[0]
    k = np.random.default_rng(17).choice(k, size=min(sample, k.size), replace=False)
    return float(np.abs(realised_by_occt(face, P[k], N[k], reach=reach) - d[k]).max())


def max_tolerance(shape):
    return max([e.Tolerance for e in shape.Edges] + [v.Tolerance for v in shape.Vertexes])


def boundary_move(nominal_face, new_face, corrected, samples=60):
    """Per sample of the nominal face's boundary: (distance to the new face's boundary,
    the correction there = |S_c - S| at the same (u, v)) in mm."""
    s = nominal_face.Surface
    new_edges = Part.Compound(new_face.Edges)
    out = []
    for e in nominal_face.Edges:
        c2d, a, b = nominal_face.curveOnSurface(e)[:3]
        for t in np.linspace(a, b, samples):
            w = c2d.value(float(t))
            x = s.value(w.x, w.y)
            out.append((new_edges.distToShape(Part.Vertex(x))[0],
                        (corrected.value(w.x, w.y) - x).Length))
    return np.array(out)


def flux_change(old_face, new_face, field):
    """Flux of ``field(points) . (Su x Sv)`` through ``new_face`` minus through
    ``old_face`` (both B-spline faces, same parametrisation), on one scan grid: the volume
    change of a solid whose other faces carry no flux of that field (div field = 1)."""
    sa, sb = surface_from_part(old_face.Surface), surface_from_part(new_face.Surface)
    la, lb = boundary_polylines(old_face), boundary_polylines(new_face)
    pts = np.concatenate(la + lb)
    box = (pts[:, 0].min(), pts[:, 0].max())
    knots = knots_of(sa, sb)

    def density(surf):
        def f(u, v):
            p, su, sv = bspline.derivatives(surf, u, v, order=1)
            return np.einsum("ij,ij->i", field(p), np.cross(su, sv))
        return f

    sign = -1.0 if old_face.Orientation == "Reversed" else 1.0
    return sign * (domain_integral(density(sb), lb, box=box, knots=knots)
                   - domain_integral(density(sa), la, box=box, knots=knots))


def z_field(p):
    """(0, 0, z): no flux through vertical walls."""
    out = np.zeros_like(p)
    out[:, 2] = p[:, 2]
    return out


def radial_field(p):
    """(x, y, 0) / 2: no flux through planes normal to z."""
    out = 0.5 * p.copy()
    out[:, 2] = 0.0
    return out


def mesh_volume(shape, max_length):
    import MeshPart

    return MeshPart.meshFromShape(Shape=shape, MaxLength=max_length).Volume


def other_faces_untouched(before, after, changed):
    """Faces other than ``changed`` (0-based) keep their surfaces: same type and points."""
    for k, (a, b) in enumerate(zip(before.Faces, after.Faces)):
        if k in changed:
            continue
        assert a.Surface.TypeId == b.Surface.TypeId, k
        u0, u1, v0, v1 = a.ParameterRange
        for s, t in ((0.3, 0.4), (0.7, 0.6)):
            uv = (u0 + s * (u1 - u0), v0 + t * (v1 - v0))
            assert (a.Surface.value(*uv) - b.Surface.value(*uv)).Length < 1e-12, k


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "surfcomp", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)


def brep_file(shape, tmp_path, name="part.brep"):
    path = tmp_path / name
    shape.exportBrep(str(path))
    return path
