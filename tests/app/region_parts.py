# SPDX-License-Identifier: LGPL-2.1-or-later
"""Test parts, documents and measurement files for the region compensation (issue 30)."""

import hashlib
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def compensate(*args, timeout=900):
    """``python3 -m surfcomp compensate ARGS`` from the checkout, its output captured."""
    return subprocess.run([sys.executable, "-m", "surfcomp", "compensate", *map(str, args)],
                          cwd=ROOT, capture_output=True, text=True, timeout=timeout)


def run(*args):
    """``compensate ARGS`` run in this process (``run_in_process``, tests/app/helpers.py): for
    the runs whose results a test checks; a refused run stays a process (:func:`compensate`)."""
    from tests.app.helpers import run_in_process

    return run_in_process("compensate", *args)


def sha256(path):
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def block_document(path, solid, mirror=True, build=None):
    """Save a document at ``path`` holding ``solid`` as the Part feature "Block", with a
    "Mirror" of it (its user) unless ``mirror`` is false; ``build(doc, block)`` adds more
    before it is saved. Returns what ``build`` returned."""
    import FreeCAD

    doc = FreeCAD.newDocument("regionshop")
    try:
        block = doc.addObject("Part::Feature", "Block")
        block.Shape = solid
        if mirror:
            m = doc.addObject("Part::Mirroring", "Mirror")
            m.Source = block
            m.Normal = FreeCAD.Vector(1, 0, 0)
        doc.recompute()
        extra = build(doc, block) if build else None
        doc.saveAs(str(path))
        return extra
    finally:
        FreeCAD.closeDocument(doc.Name)


def g1_shop(folder, count, seed):
    """The G1 block saved as ``folder/shop.FCStd`` (Block and its Mirror) and ``count``
    points on each of its two top faces carrying :func:`ridge_field`, in ``folder/g1.csv``:
    ``(document, csv, solid, pts, nrm, dev)``."""
    solid, tops = g1_top_solid()
    path = os.path.join(str(folder), "shop.FCStd")
    block_document(path, solid)
    return (path,) + g1_points(folder, solid, tops, count, seed)


def g1_step(folder, count, seed):
    """The G1 block as ``folder/g1.step`` and :func:`g1_points`: ``(step, csv, solid, pts,
    nrm, dev)``."""
    solid, tops = g1_top_solid()
    step = os.path.join(str(folder), "g1.step")
    solid.exportStep(step)
    return (step,) + g1_points(folder, solid, tops, count, seed)


def g1_points(folder, solid, tops, count, seed):
    """``count`` points on each of the G1 block's top faces carrying :func:`ridge_field`,
    in ``folder/g1.csv``: ``(csv, solid, pts, nrm, dev)``."""
    pts, nrm, dev = sample_faces([solid.Faces[k] for k in tops], count, ridge_field,
                                 seed=seed)
    csv = os.path.join(str(folder), "g1.csv")
    write_csv(csv, pts, nrm, dev)
    return csv, solid, pts, nrm, dev


def _h(x, y):
    return 5.0 + 0.6 * np.sin(x / 5.0) + 0.4 * np.cos(y / 4.0)


def g1_top_solid():
    """A 20 x 10 mm block whose top is two bicubic B-spline faces meeting G1 along x = 10
    (one surface cut in two), with planar walls and bottom: a closed solid of 7 faces.
    Returns ``(solid, top face indices)``."""
    import FreeCAD
    import Part

    V = FreeCAD.Vector
    nu, nv = 10, 7
    ku = [0.0] * 4 + list(np.linspace(0, 20, nu - 2)[1:-1]) + [20.0] * 4
    kv = [0.0] * 4 + list(np.linspace(0, 10, nv - 2)[1:-1]) + [10.0] * 4
    gre_u = [sum(ku[i + 1:i + 4]) / 3 for i in range(nu)]
    gre_v = [sum(kv[i + 1:i + 4]) / 3 for i in range(nv)]
    poles = [[V(x, y, float(_h(x, y))) for y in gre_v] for x in gre_u]
    bs = Part.BSplineSurface()
    mu = [4] + [1] * (nu - 4) + [4]
    mv = [4] + [1] * (nv - 4) + [4]
    bs.buildFromPolesMultsKnots(poles, mu, mv, sorted(set(ku)), sorted(set(kv)), False, False,
                                3, 3)
    left, right = bs.copy(), bs.copy()
    left.segment(0, 10, 0, 10)
    right.segment(10, 20, 0, 10)
    tops = [left.toShape(), right.toShape()]
    z = {(x, y): bs.value(x, y).z for x in (0, 10, 20) for y in (0, 10)}

    def top_edge(face, coord, val):
        return [e for e in face.Edges if at(e, coord, val)][0]

    def at(e, coord, val):
        return all(abs(getattr(e.valueAt(t), coord) - val) < 1e-9
                   for t in (e.FirstParameter, e.LastParameter))

    walls = []
    for y in (0.0, 10.0):
        e1 = top_edge(tops[0], "y", y)
        e2 = top_edge(tops[1], "y", y)
        edges = [e1, e2, Part.makeLine(V(20, y, z[(20, y)]), V(20, y, 0)),
                 Part.makeLine(V(20, y, 0), V(0, y, 0)), Part.makeLine(V(0, y, 0),
                                                                    V(0, y, z[(0, y)]))]
        walls.append(Part.Face(Part.Wire(Part.__sortEdges__(edges))))
    for x, f in ((0.0, 0), (20.0, 1)):
        e = top_edge(tops[f], "x", x)
        edges = [e, Part.makeLine(V(x, 10, z[(x, 10)]), V(x, 10, 0)),
                 Part.makeLine(V(x, 10, 0), V(x, 0, 0)), Part.makeLine(V(x, 0, 0),
                                                                   V(x, 0, z[(x, 0)]))]
        walls.append(Part.Face(Part.Wire(Part.__sortEdges__(edges))))
    bottom = Part.Face(Part.makePolygon([V(0, 0, 0), V(20, 0, 0), V(20, 10, 0), V(0, 10, 0),
                                         V(0, 0, 0)]))
    shell = Part.Shell(tops + walls + [bottom])
    shell.sewShape(1e-7)
    solid = Part.Solid(shell)
    if solid.Volume < 0:
        solid.reverse()
    tops_idx = [k for k, f in enumerate(solid.Faces)
                if f.Surface.TypeId == "Part::GeomBSplineSurface"]
    return solid, tops_idx


def smooth_window(t, inner=1.0, width=2.0):
    s = np.clip((t - inner) / width, 0, 1)
    return s * s * s * (s * (6 * s - 15) + 10)


def ridge_field(p, amplitude=0.02):
    """Largest on the common edge x = 10, zero within 1 mm of the block's walls."""
    x, y = p[:, 0], p[:, 1]
    return amplitude * np.exp(-((x - 10.0) / 3.0) ** 2) * smooth_window(x) * \
        smooth_window(20 - x) * smooth_window(y) * smooth_window(10 - y)


def sample_faces(faces, count, field, seed=0, noise=0.0):
    """Points on the faces (uniform in each face's UV range, inside its trim), their
    outward normals and the deviation ``field(points)`` (+ noise)."""
    rng = np.random.default_rng(seed)
    pts, nrm = [], []
    for f in faces:
        u0, u1, v0, v1 = f.ParameterRange
        # a face that fills its parameter rectangle holds every sample (asking OCCT costs
        # more than the point itself)
        whole = abs(f.Surface.toShape(u0, u1, v0, v1).Area - f.Area) <= 1e-9 * f.Area
        k = 0
        while k < count:
            u, v = rng.uniform(u0, u1), rng.uniform(v0, v1)
            if not (whole or f.isPartOfDomain(u, v)):
                continue
            p = f.Surface.value(u, v)
            n = f.normalAt(u, v)
            pts.append(tuple(p))
            nrm.append(tuple(n))
            k += 1
    pts, nrm = np.array(pts), np.array(nrm)
    dev = field(pts) + noise * rng.standard_normal(len(pts))
    return pts, nrm, dev


def write_csv(path, pts, nrm, dev):
    with open(path, "w") as fh:
        fh.write("x_nom,y_nom,z_nom,i,j,k,dev\n")
        for p, n, d in zip(pts, nrm, dev):
            fh.write("%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.9f\n" % (tuple(p) + tuple(n) + (d,)))



BLADE = ("upper", "lower", "tip", "root")


def blade_faces(folder):
    """The four faces of the BladeX blade (suction and pressure sides, tip and root caps),
    as read from their IGES files: they meet within 9 um but OpenCASCADE's sewing does not
    join the sides' knife edges, so the blade is a compound of faces, not a solid."""
    import os

    import Part

    return [Part.read(os.path.join(folder, name + ".iges")).Faces[0] for name in BLADE]


def blade_outward(faces):
    """The blade's faces turned so their normals point out of the blade: the pressure side
    (``lower``: its normal points at the suction side, 3.5 mm away mid-chord) and the tip
    cap (its normal points to +z at the blade's -z end) face into it as read. Measurements
    carry outward normals; the region finds the same orientation itself."""
    return [f.reversed() if name in ("lower", "tip") else f for name, f in zip(BLADE, faces)]


def leading_edge(faces, samples=400):
    """Points along the spanwise edge the two sides share that is nearer the blade's
    axis of rotation (its leading edge as BladeX builds it), shape (samples, 3)."""
    upper, lower = faces[0], faces[1]
    best = None
    for e in upper.Edges:
        mid = e.valueAt(0.5 * (e.FirstParameter + e.LastParameter))
        if lower.distToShape(__import__("Part").Vertex(mid))[0] > 0.02:
            continue
        if best is None or e.Length < best.Length:
            best = e
    ts = np.linspace(best.FirstParameter, best.LastParameter, samples)
    return np.array([tuple(best.valueAt(float(t))) for t in ts])


def around_edge_field(edge_points, amplitude=0.03, width=12.0):
    """A deviation largest along the edge and running around it onto both sides."""
    from scipy.spatial import cKDTree

    tree = cKDTree(edge_points)

    def field(p):
        d, _ = tree.query(p)
        return amplitude * np.exp(-(d / width) ** 2)

    return field


def beside_edge(face, vs, dists):
    """Points of ``face`` at ``dists`` (mm, along the face) from its edge u = u1 (the
    BladeX sides' trailing edge) at parameters ``vs``, and their normals."""
    _u0, u1, _v0, _v1 = face.ParameterRange
    pts, nrm = [], []
    for v in vs:
        su = np.linalg.norm(np.array(face.Surface.getDN(u1, v, 1, 0)))
        for d in dists:
            u = u1 - d / su
            pts.append(tuple(face.Surface.value(u, v)))
            nrm.append(tuple(face.normalAt(u, v)))
    return np.array(pts), np.array(nrm)
