# SPDX-License-Identifier: LGPL-2.1-or-later
"""Compensate a region of several faces of one shape at once (issue 30; app layer).

The points are located on every face of the region and each is given to its nearest face
(:func:`surfcomp.core.compensation.region_field.assign`); the filter and the correction field work
over the whole region in space (:mod:`surfcomp.core.compensation.region_field`), and every face is
rebuilt from one displacement (:mod:`surfcomp.core.compensation.region_build`), so faces that share
an edge stay closed along it. The faces are then put back in the shape and sewn at
:data:`surfcomp.app.retrim.PRECISION`; continuity (gap and normal angle along every shared
edge), the volume change and the realised correction at the points are measured on the
result, with OpenCASCADE.

In a closed solid the faces outside the region that meet it are re-trimmed
(:mod:`surfcomp.app.region_retrim`); in a compound of faces a region whose correction moves
an edge shared with a face outside it is refused naming the two faces.
"""

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from ..core.compensation import region_build, region_edges, region_field
from ..core.limits import FIELD_SHARE, FIELD_SPACINGS  # noqa: F401  (region.FIELD_SHARE)
from ..core.surface.bspline import derivatives, evaluate, normals
from ..core.surface.projection import Projector
from ..core.surface.trimmed import area_samples, inside  # noqa: F401  (region.inside)
from ..errors import GeometryError, InputError
from .convert import surface_from_part
from .face_data import geometry_box, to_bspline_face, work_surface
from .nominal import boundary_polylines

#: nominal edges of two faces closer than this (mm) are one shared edge
SHARE_TOL = 0.05
#: samples along an edge for the continuity figures and the sharp-edge polylines
EDGE_SAMPLES = 200
#: nominal normals closer than this (degrees) along an edge: the faces meet G1
G1_ANGLE = 0.1
#: the shortest length (share of the band) over which a sharp edge's exactness changes
EASE_SHARE = 0.5


@dataclass
class RegionFace:
    index: int
    name: str
    face: object
    bface: object
    surface: object
    outward: int
    polylines: list
    points: int = 0
    coverage: float = 0.0
    built: object = None
    part_surface: object = None
    projector: object = None
    normals_cache: dict = field(default_factory=dict, repr=False)

    def project(self, points, max_distance=None):
        """Closest points on the face's nominal; one projection engine per face (its seed
        grid and tables cost about a second on a blade side, and a run projects onto each
        face a dozen times)."""
        return self.engine(len(points)).project(np.asarray(points, dtype=float), max_distance)

    def engine(self, count):
        """The face's projection engine, made for ``count`` points on first use."""
        if self.projector is None:      # seeds as dense as project() takes for a cloud
            self.projector = Projector(self.surface, min_samples=count // 16)
        return self.projector


@dataclass
class SharedEdge:
    a: int
    b: int
    edge_a: int
    edge_b: int
    samples: np.ndarray
    nominal_angle: float
    figures: dict = field(default_factory=dict)


def parse_faces(text, shape):
    """``'Face1,Face3'`` -> 0-based indices (``'auto'`` -> None)."""
    if text.strip().lower() == "auto":
        return None
    out = []
    for name in (t.strip() for t in text.split(",")):
        if not name.startswith("Face") or not name[4:].isdigit():
            raise InputError("faces: %r is not a face name (expected FaceN, N from 1 to %d, "
                             "or auto)" % (name, len(shape.Faces)), options=("faces",))
        k = int(name[4:])
        if not 1 <= k <= len(shape.Faces):
            raise InputError("faces: the shape has no %s (it has Face1 to Face%d)"
                             % (name, len(shape.Faces)), options=("faces",))
        if k - 1 not in out:
            out.append(k - 1)
    return out


def region_face(shape, k):
    face = shape.Faces[k]
    bface, _ = to_bspline_face(face)
    if any(e.isSeam(bface) for e in bface.Edges):
        raise GeometryError("Face%d has a seam (a closed surface): split it first" % (k + 1))
    u0, u1, v0, v1 = bface.ParameterRange
    surf = surface_from_part(work_surface(bface), (u0, u1), (v0, v1))
    if surf.weights is not None and not surf.rational:
        surf = type(surf)(surf.poles, surf.knots_u, surf.knots_v, surf.degree_u,
                          surf.degree_v, None, surf.u_range, surf.v_range)
    outward = -1 if bface.Orientation == "Reversed" else 1
    return RegionFace(k, "Face%d" % (k + 1), face, bface, surf, outward,
                      boundary_polylines(bface, 200))


def locate(faces, base, max_offset, found=None):
    """Project ``base`` (N, 3) on every face: (face index or -1, u, v, normal, distance).
    ``found``: the :func:`project_all` of these faces, when already done."""
    dist, res = found if found is not None else project_all(faces, base, max_offset)
    n = len(base)
    owner = region_field.assign(dist, max_offset)
    u, v, normal, signed = (np.full(n, np.nan), np.full(n, np.nan), np.full((n, 3), np.nan),
                            np.full(n, np.nan))
    for i, (idx, p) in enumerate(res):
        if p is None:
            continue
        mine = owner[idx] == i
        k = idx[mine]
        u[k], v[k] = p.u[mine], p.v[mine]
        normal[k] = p.normal[mine] * faces[i].outward
        signed[k] = p.distance[mine] * faces[i].outward
    return owner, u, v, normal, signed


def project_all(faces, base, max_offset):
    """Each face's distance from every point that may have it as its nearest face, inside
    its trim (F, N; inf elsewhere), and the projections ``(indices, Projection)`` per face.

    In two rounds (:mod:`surfcomp.app.region_project`): each point first on the face of
    its nearest sample, then on the other faces only where a lower bound of their distance
    does not exceed the distance found (a blade side's box holds the other side's points,
    which lie off the face and cost twice a point on it)."""
    from .region_project import two_rounds

    return two_rounds(faces, base, max_offset, _sample_distances(faces, base, max_offset))


def _sample_distances(faces, base, max_offset, n=200):
    """Per face, which points may have it as their nearest face, from an n x n grid of
    samples on each: a face's distance from a point is at least its nearest sample's less
    the grid's covering radius, and at most the nearest sample's on any face. (A blade
    side's box holds the other side's points too; projecting them would double the work.)
    Returns that (F, N) mask and, per point, the face of its nearest sample (-1: none)."""
    from ..core.surface.bspline import evaluate_grid

    low = np.full((len(faces), len(base)), np.inf)
    near = np.full((len(faces), len(base)), np.inf)
    for i, f in enumerate(faces):
        bb = geometry_box(f.face)
        idx = np.flatnonzero(np.all((base >= np.array([bb.XMin, bb.YMin, bb.ZMin]) - max_offset)
                                    & (base <= np.array([bb.XMax, bb.YMax, bb.ZMax])
                                       + max_offset), axis=1))
        if not len(idx):
            continue
        u0, u1, v0, v1 = f.bface.ParameterRange
        g = evaluate_grid(f.surface, np.linspace(u0, u1, n), np.linspace(v0, v1, n))
        r = covering_radius(g)
        # a point farther than max_offset + r from every sample is not near the face: the
        # bound ends its search early (most of a small cap's box is the sides' points)
        d, _ = cKDTree(g.reshape(-1, 3)).query(base[idx], k=1,
                                               distance_upper_bound=max_offset + r,
                                               workers=-1)
        low[i, idx] = d - r
        near[i, idx] = d
    high = np.min(near, axis=0)
    first = np.where(np.isfinite(high), np.argmin(near, axis=0), -1)
    return (low <= np.minimum(high, max_offset)[None, :] + 1e-9), first


def covering_radius(g):
    """Half the longest cell diagonal of a grid of points ``g`` (nu, nv, 3): every point
    of the surface lies within it of a sample."""
    return 0.5 * float(max(np.max(np.linalg.norm(g[1:, 1:] - g[:-1, :-1], axis=2)),
                           np.max(np.linalg.norm(g[1:, :-1] - g[:-1, 1:], axis=2))))


def face_samples(f, n=60):
    """Points on the face (inside its trim) and the area each stands for
    (:func:`surfcomp.core.surface.trimmed.area_samples`)."""
    return area_samples(f.surface, f.bface.ParameterRange, f.polylines, n)


def _edge_points(edge, n=EDGE_SAMPLES):
    ts = np.linspace(edge.FirstParameter, edge.LastParameter, n)
    return np.array([tuple(edge.valueAt(float(t))) for t in ts])


def prefetch_normals(faces, sets):
    """Fill the faces' normal caches (:func:`normals_at`) for the point sets ``sets``
    (``(face index, points (K, 3))``) with one projection per face: the projection of a
    point does not depend on the others projected with it, and one call of a few thousand
    edge points costs about what one of two hundred does (the edge points need the
    engine's search for other minima, set up per call); each set then gets its own pass
    along its points (:func:`_project_along`), as :func:`normals_at` gives it."""
    todo = {}
    for i, pts in sets:
        pts = np.ascontiguousarray(pts, dtype=float)
        key = pts.tobytes()
        if len(pts) and key not in faces[i].normals_cache:
            todo.setdefault(i, {})[key] = pts
    for i, parts in todo.items():
        f = faces[i]
        allp = np.concatenate(list(parts.values()))
        p = f.project(allp)
        ends = np.cumsum([len(pts) for pts in parts.values()])
        found = [(p.u[e - len(pts):e], p.v[e - len(pts):e])
                 for e, pts in zip(ends, parts.values())]
        # each set's own pass along its points, all sets in the same Newton runs
        for key, (u, v) in zip(parts, _along(f, list(parts.values()), found)):
            f.normals_cache[key] = (normals(f.surface, u, v), u, v)


def normals_at(f, pts):
    """Outward unit normals of face ``f``'s nominal at its points nearest ``pts`` (K, 3),
    and their parameters. Kept per face and point set: the sharp edges, the neighbour check
    and the continuity figures ask for the same edge samples."""
    pts = np.ascontiguousarray(pts, dtype=float)
    key = pts.tobytes()
    if key not in f.normals_cache:      # the surface's normals: the orientation may change
        u, v = _project_along(f, pts)
        f.normals_cache[key] = (normals(f.surface, u, v), u, v)
    n, u, v = f.normals_cache[key]
    return n * f.outward, u, v


def _project_along(f, pts, found=None):
    """Parameters of the points nearest ``pts`` (K, 3), points in order along a curve (an
    edge's samples). Each point is tried again by Newton from its neighbours' feet, the
    closest foot kept: next to a blade side's boundary the projection stopped
    1 um off the face once in 200 samples, and where the pressure side
    curls back on itself (0.08 mm radius) it found a foot 0.06 um away with its normal
    115 degrees off the edge's own; either turned the sharp edge's vector there.
    ``found``: the projection's ``(u, v)`` of ``pts``, when already made."""
    if found is None:
        p = f.project(pts)
        found = (p.u, p.v)
    return _along(f, [pts], [found])[0]


def _along(f, sets, found):
    """:func:`_project_along` of several point sets at once (one Newton run per pass and
    direction for all of them: a run's set-up costs more than two hundred points'
    iterations); each point's neighbours are those of its own set."""
    u = [x[0].copy() for x in found]
    v = [x[1].copy() for x in found]
    take_sets = [k for k, pts in enumerate(sets) if len(pts) >= 2
                 and np.any(np.isfinite(u[k]) & np.isfinite(v[k]))]
    if not take_sets:
        return list(zip(u, v))
    pts = np.concatenate([sets[k] for k in take_sets])
    U, V = np.concatenate([u[k] for k in take_sets]), np.concatenate([v[k] for k in take_sets])
    starts = np.cumsum([0] + [len(sets[k]) for k in take_sets])
    P = np.ascontiguousarray(pts.T)
    ok = np.isfinite(U) & np.isfinite(V)
    best = np.full(len(pts), np.inf)
    best[ok] = np.linalg.norm(evaluate(f.surface, U[ok], V[ok]) - pts[ok], axis=1)
    # each point's neighbour before it and after it in its set (the ends take the other)
    before = np.concatenate([s + np.r_[1, np.arange(e - s - 1)]
                             for s, e in zip(starts[:-1], starts[1:])])
    after = np.concatenate([s + np.r_[np.arange(1, e - s), e - s - 2]
                            for s, e in zip(starts[:-1], starts[1:])])
    for _ in range(2):      # a wrong foot's neighbours may have been wrong too
        for seed in (before, after):
            ok = np.isfinite(best[seed])
            u2, v2, D, _conv = f.projector.newton.run(P[:, ok], U[seed[ok]], V[seed[ok]])
            # the closer point on the face wins, converged or not (Newton stops short of
            # a foot on the face's boundary at times; it is still a point of the face)
            d = np.linalg.norm(D[0] - P[:, ok], axis=0)
            k = np.flatnonzero(ok)
            take = d < best[k] - 1e-12
            best[k[take]], U[k[take]], V[k[take]] = d[take], u2[take], v2[take]
    for j, k in enumerate(take_sets):
        u[k], v[k] = U[starts[j]:starts[j + 1]], V[starts[j]:starts[j + 1]]
    return list(zip(u, v))


def _vec(p):
    import FreeCAD

    return FreeCAD.Vector(*map(float, p))


def _near_polyline(points, poly):
    """Largest distance of ``points`` from the polyline ``poly`` (both (K, 3))."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    worst = 0.0
    for p in points:
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(
            np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
        worst = max(worst, float(np.min(np.linalg.norm(a + t[:, None] * ab - p, axis=1))))
    return worst


def shared_edges(shape, faces, all_faces=False, angles=True):
    """Edges shared by two faces of the region (and, with ``all_faces``, by a region face
    and any other face of ``shape``: ``b`` is then the shape's face index, negative-coded
    as ``-1 - index``), found geometrically so unsewn shells count too. Without ``angles``
    the nominal angle along each edge is not measured (NaN)."""
    out = []
    polys = {}

    def poly(k, j, e):
        if (k, j) not in polys:
            polys[(k, j)] = _edge_points(e, 64)
        return polys[(k, j)]

    region = {f.index: i for i, f in enumerate(faces)}
    shape_faces = shape.Faces
    boxes, edges = {}, {}

    def of(k):      # a face's box and (edge, degenerated, length), read from OCC once
        if k not in edges:
            g = shape_faces[k]
            boxes[k] = geometry_box(g)
            edges[k] = [(e, e.Degenerated, e.Length) for e in g.Edges]
        return boxes[k], edges[k]

    for i, f in enumerate(faces):
        others = range(len(shape_faces)) if all_faces else [g.index for g in faces[i + 1:]]
        box_a, edges_a = of(f.index)
        for k in others:
            if k == f.index or (all_faces and k in region):
                continue
            box_b, edges_b = of(k)
            if not box_a.intersect(box_b):
                continue
            for ja, jb, ea in _matches(edges_a, edges_b, lambda j, e, k=f.index: poly(k, j, e),
                                       lambda j, e, k=k: poly(k, j, e)):
                b = region[k] if not all_faces else -1 - k
                out.append(SharedEdge(i, b, ja, jb, _edge_points(ea), float("nan")))
    if angles:
        # every normal the run asks for along the edges, one projection per face
        prefetch_normals(faces, [(j, p) for e in out for j in (e.a, e.b) if j >= 0
                                 for p in edge_point_sets(e.samples)])
        for e in out:
            g = faces[e.b] if e.b >= 0 else shape.Faces[-1 - e.b]
            e.nominal_angle = _nominal_angle(faces[e.a], g, e.samples)
    return out


def edge_point_sets(samples):
    """The point sets along an edge whose normals the run takes: the samples (sharp
    edges, continuity), every tenth (the nominal angle) and the midpoints (continuity)."""
    return samples, samples[::10], midpoints(samples)


def midpoints(samples):
    return 0.5 * (samples[1:] + samples[:-1])


def _matches(edges_a, edges_b, poly_a, poly_b):
    """``(ja, jb, edge a)`` of the edges of two faces (``(edge, degenerated, length)``)
    that are one edge: lengths within 1 %, and every eighth point of a's polyline
    (``poly_a(j, edge)``) within SHARE_TOL of b's."""
    for ja, (ea, degenerated_a, length_a) in enumerate(edges_a):
        if degenerated_a or length_a < 1e-6:
            continue
        pa = poly_a(ja, ea)
        for jb, (eb, degenerated_b, length_b) in enumerate(edges_b):
            if degenerated_b or abs(length_b - length_a) > 0.01 * length_a + SHARE_TOL:
                continue
            if _near_polyline(pa[::8], poly_b(jb, eb)) <= SHARE_TOL:
                yield ja, jb, ea


def _nominal_angle(f, g, pts):
    na, _, _ = normals_at(f, pts[::10])
    if isinstance(g, RegionFace):
        nb, _, _ = normals_at(g, pts[::10])
    else:
        nb = []
        for p in pts[::10]:
            u, v = g.Surface.parameter(_vec(p))
            nb.append(tuple(g.normalAt(u, v)))
        nb = np.array(nb)
    return max(_angle(a, b) for a, b in zip(na, nb))


def _angle(a, b):
    c = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def sharp_edges(faces, edges, band, field=None):
    """The :class:`~surfcomp.core.compensation.region_edges.SharpEdges` of the region's edges that
    are not G1, with the normals and in-face directions at their samples, each edge's vector
    turned to its vertices' near them
    (:func:`~surfcomp.core.compensation.region_edges.at_vertices`); with ``field`` (the
    correction), each edge's second-order vector
    (:mod:`~surfcomp.core.compensation.region_second`), nil at vertices."""
    pts, mit, cl, eid, nrm, ids, inw = [], [], [], [], [], [], []
    for k, e in enumerate(edges):
        if e.nominal_angle <= G1_ANGLE:
            continue
        fa, fb = faces[e.a], faces[e.b]
        na, nb = normals_at(fa, e.samples)[0], normals_at(fb, e.samples)[0]
        ia, ib = _inward(fa, e.edge_a, e.samples, na), _inward(fb, e.edge_b, e.samples, nb)
        m, c = region_build.miters(na, nb, ia, ib)
        inw.append(np.stack([ia, ib], axis=1))
        pts.append(e.samples)
        mit.append(m)
        cl.append(c)
        eid.append(np.full(len(m), k))
        nrm.append(np.stack([na, nb], axis=1))
        ids.append(np.tile([e.a, e.b], (len(m), 1)))
    if not pts:
        return None
    pts, eid, nrm = np.concatenate(pts), np.concatenate(eid), np.concatenate(nrm)
    mit, exact, away = region_edges.at_vertices(
        pts, np.concatenate(mit), np.concatenate(cl), eid, nrm, 0.5 * band,
        region_edges.knife_limit(region_build.MITER_ANGLE), SHARE_TOL, _collapsed(faces),
        away=True)
    exact = region_edges.eased(exact, eid, pts, EASE_SHARE * band)
    ids = np.concatenate(ids)
    out = region_edges.SharpEdges(pts, mit, exact, eid, band, nrm, ids, np.concatenate(inw))
    if field is not None:
        out.second = away[:, None] * _second(faces, edges, pts, mit, eid, nrm, field)
    return out


def _second(faces, edges, pts, mit, eid, nrm, field):
    """Each sharp edge sample's second-order vector: both faces' second-order normal terms
    for the slide the edge's vector ``-delta m`` gives them, combined into one vector."""
    from ..core.compensation.region_second import edge_vector, normal_term

    out = np.zeros_like(mit)
    delta = field(pts)
    for k in np.unique(eid):
        idx = np.flatnonzero(eid == k)
        e = edges[k]
        q = []
        for side, i in enumerate((e.a, e.b)):
            _n, u, v = normals_at(faces[i], e.samples)
            S, *derivs = derivatives(faces[i].surface, u, v, order=2)
            n = nrm[idx, side]
            q.append(normal_term(S, *derivs, n, -delta[idx, None] * mit[idx], field))
        out[idx] = edge_vector(nrm[idx, 0], nrm[idx, 1], *q)
    return out


def _collapsed(faces):
    """Points where a region face collapses (the vertices of its degenerated edges)."""
    return np.array([tuple(e.Vertexes[0].Point) for f in faces for e in f.face.Edges
                     if e.Degenerated and e.Vertexes]).reshape(-1, 3)


def _inward(f, j, p, n):
    """Unit directions in face ``f`` at the points ``p`` (K, 3) of its edge ``j`` (outward
    normals ``n``), normal to the edge, into the face: the face's boundary runs with the
    face on its left about the face's own normal (its surface's, turned by its
    ``Orientation``), so no probe off the edge is needed (a probe is pulled back onto the
    edge at a surface's natural boundary)."""
    own = -1 if f.face.Orientation == "Reversed" else 1
    t = np.gradient(p, axis=0) * run_direction(f.face.Edges[j], p)
    d = np.cross(n * (f.outward * own), t)
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)


def run_direction(edge, p):
    """+1 where the face holding ``edge`` runs through it in the order of its points ``p``
    (K, 3), -1 where against (the edge's curve direction, reversed where the face takes the
    edge ``Reversed``, which includes the face's own orientation)."""
    a, b = p[len(p) // 4], p[(3 * len(p)) // 4]
    ta, tb = (edge.Curve.parameter(_vec(x)) for x in (a, b))
    return (1 if tb > ta else -1) * (1 if edge.Orientation == "Forward" else -1)


def continuity(faces, edges):
    """Largest gap (um) and normal angle (degrees) along every shared edge, measured on the
    corrected surfaces at the nominal edge's points and halfway between them (the edge's
    vectors are built at the points: a figure taken only there would not see a gap between
    them); fills ``edge.figures``."""
    for e in edges:
        fa, fb = faces[e.a], faces[e.b]
        mids = midpoints(e.samples)
        ma, ua, va = (np.concatenate(x) for x in zip(normals_at(fa, e.samples),
                                                      normals_at(fa, mids)))
        mb, ub, vb = (np.concatenate(x) for x in zip(normals_at(fb, e.samples),
                                                      normals_at(fb, mids)))
        pa, pb = evaluate(fa.built.surface, ua, va), evaluate(fb.built.surface, ub, vb)
        qa, qb = evaluate(fa.surface, ua, va), evaluate(fb.surface, ub, vb)
        na = normals(fa.built.surface, ua, va) * fa.outward
        nb = normals(fb.built.surface, ub, vb) * fb.outward
        angles = np.array([_angle(a, b) for a, b in zip(na, nb)])
        nominal = np.array([_angle(a, b) for a, b in zip(ma, mb)])
        e.figures = {"faces": [fa.name, fb.name], "edge": "%s.Edge%d" % (fa.name, e.edge_a + 1),
                     "g1": e.nominal_angle <= G1_ANGLE,
                     "nominal_angle_deg": e.nominal_angle,
                     "max_gap_um": float(np.max(np.linalg.norm(pa - pb, axis=1))) * 1e3,
                     "nominal_gap_um": float(np.max(np.linalg.norm(qa - qb, axis=1))) * 1e3,
                     # where the nominal faces are apart (a tip cap 41 um off its side), the
                     # gap the correction adds, sample by sample
                     "max_gap_beyond_nominal_um": float(np.max(
                         np.linalg.norm(pa - pb, axis=1) - np.linalg.norm(qa - qb, axis=1))) * 1e3,
                     "max_angle_deg": float(np.max(angles)),
                     "max_angle_change_deg": float(np.max(np.abs(angles - nominal)))}
    return [e.figures for e in edges]
