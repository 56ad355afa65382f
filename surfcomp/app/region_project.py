# SPDX-License-Identifier: LGPL-2.1-or-later
"""The points of a region located on its faces in two rounds (issue 30; the 200k-point
blade in at most 15 s).

A face's bounding box holds points of its neighbours (a blade side's holds the other
side's, a fraction of a millimetre away at the knife edges). Those points lie off the
face: projecting them costs the engine its search for other minima, about twice the work
of the points on the face for a tenth of the points. So each point is projected first on
the face of its nearest grid sample (:func:`surfcomp.app.region._sample_distances`), and
on another face it may be nearest to only where a lower bound of its distance from that
face (its nearest sample on the face's denser seed grid, less that grid's covering radius)
does not exceed the distance the first round found. A face left out this way is farther
than the one found, so every point's nearest face and its foot on it are those of
projecting it on every face of its mask (the projection of a point does not depend on
the others projected with it)."""

import numpy as np
from scipy.spatial import cKDTree

from ..core.chunks import for_chunks
from ..core.surface.projection import Projection
from ..core.surface.trimmed import inside

#: slack (mm) of the comparison of a lower bound with a distance found
SLACK = 1e-9


def two_rounds(faces, base, max_offset, sampled):
    """:func:`surfcomp.app.region.project_all` from the sample mask and the faces of the
    nearest samples (``sampled``: ``(may (F, N), first (N,))``)."""
    may, first = sampled
    dist = np.full((len(faces), len(base)), np.inf)
    parts = [[] for _ in faces]
    # each engine made for all the points it may get, the faces' at once
    per_face(faces, lambda i: faces[i].engine(int(np.sum(may[i]))) if np.any(may[i]) else None)
    for i in range(len(faces)):
        _project(faces, i, np.flatnonzero(may[i] & (first == i)), base, max_offset, dist,
                 parts)
    best = np.min(dist, axis=0)
    for i, f in enumerate(faces):
        idx = np.flatnonzero(may[i] & (first != i))
        found = np.isfinite(best[idx])
        if np.any(found):
            low = _lower_bound(f, base[idx[found]], best[idx[found]])
            found[found] = low > best[idx[found]] + SLACK
        _project(faces, i, idx[~found], base, max_offset, dist, parts)
    return dist, [_merged(p) for p in parts]


def _project(faces, i, idx, base, max_offset, dist, parts):
    if not len(idx):
        return
    f = faces[i]
    p = f.project(base[idx], max_distance=max_offset)
    parts[i].append((idx, p))
    # a point beyond the face's border (its foot clamped to the boundary) lies off the face,
    # as beyond a trim curve: a wall's point below a top face's edge is not the top's
    ok = p.converged & ~p.outside
    ok[ok] = inside(f.polylines, p.u[ok], p.v[ok])
    dist[i, idx[ok]] = np.abs(p.distance[ok])


def _lower_bound(f, pts, bound):
    """A lower bound of the distance of ``pts`` from face ``f`` (inf beyond ``bound`` plus
    the grid's covering radius), from the samples of the face's projection engine."""
    from .region import covering_radius

    pr = f.engine(len(pts))
    g = pr.samples[0].T.reshape(pr.us.size, pr.vs.size, 3)
    r = covering_radius(g)
    d, _ = cKDTree(g.reshape(-1, 3)).query(pts, k=1, distance_upper_bound=np.max(bound) + r
                                           + SLACK, workers=-1)
    return d - r


def _merged(parts):
    """One ``(indices, Projection)`` of the rounds' parts, by index (``(empty, None)``
    when the face got no point)."""
    if not parts:
        return np.zeros(0, dtype=np.intp), None
    if len(parts) == 1:
        return parts[0]
    idx = np.concatenate([i for i, _ in parts])
    order = np.argsort(idx, kind="stable")
    fields = {}
    for name in ("u", "v", "foot", "normal", "distance", "outside", "converged"):
        fields[name] = np.concatenate([getattr(p, name) for _, p in parts])[order]
    return idx[order], Projection(**fields)


def per_face(faces, job):
    """``job(i)`` for every face, the faces on the chunk threads at once (the work is numpy
    and scipy, which release the interpreter lock; a blade's two sides hold most of the
    points); the results in the faces' order."""
    out = [None] * len(faces)

    def run(sl):
        for i in range(sl.start, sl.stop):
            out[i] = job(i)

    for_chunks(run, len(faces), 1)
    return out
