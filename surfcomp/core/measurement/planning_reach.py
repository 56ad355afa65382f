# SPDX-License-Identifier: LGPL-2.1-or-later
"""Can a 3-axis probe reach a planned point, and in which order are the points visited
(no FreeCAD).

A 3-axis probe (spindle axis +Z) reaches a point ``P`` with outward unit normal ``n`` when

* its approach along the normal leans at most ``max_tilt`` from +Z: ``n_z >= cos(max_tilt)``;
* the stylus ball (radius ``r``) travels clear of the face from the retract position
  ``P + (r + d) n`` to the touch position ``P + r n`` (the approach line, fed along the
  normal): no point of the face comes closer than ``r`` to it, save the touched point
  itself;
* on the vertical line from the safe height down to the retract position (the rapid
  descent, and the rapid climb back on the same line) the ball keeps the clearance ``c``
  from the face: no point of the face comes closer than ``r + c`` to it (the retract
  position itself is ``r + d >= r + c`` from ``P``),

``d`` being the larger of the stand-off and the clearance, where the probing program's
rapid descent ends (:mod:`surfcomp.io.probe_path`); tolerance :data:`CLEAR_TOL`. The
traverses at the safe height keep the clearance above the part's top by construction, so
every rapid move of the program keeps the ball ``c`` from the part.

Here the face is checked at its samples (a point cloud on the trimmed face): a face that
bends back over a point hides it. The rest of the part (a face of a solid) is checked with
OpenCASCADE in :mod:`surfcomp.app.plan_reach`.
"""

import numpy as np
from scipy.spatial import cKDTree

from .planning_face import segment_distance

#: how much closer than the ball radius a face sample may come to a path (mm): the
#: touched point itself lies at exactly the radius
CLEAR_TOL = 1e-3


def tilt_degrees(normals):
    """Angle (degrees) between unit normals (N, 3) and the spindle axis +Z."""
    return np.degrees(np.arccos(np.clip(np.asarray(normals, float)[:, 2], -1.0, 1.0)))


def approach_paths(points, normals, tip_radius, stand_off, safe_z):
    """The probe's paths to each point: ``(touch, standoff, top)`` (N, 3) each: the ball
    centre at contact ``P + r n``, at the retract point ``P + (r + stand_off) n`` (pass
    :attr:`PlanSettings.retract <surfcomp.core.measurement.planning.PlanSettings.retract>`) and
    above it at the safe height (``safe_z``, or the retract point's own z when higher)."""
    P = np.asarray(points, dtype=float)
    n = np.asarray(normals, dtype=float)
    touch = P + tip_radius * n
    standoff = P + (tip_radius + stand_off) * n
    top = standoff.copy()
    top[:, 2] = np.maximum(standoff[:, 2], safe_z)
    return touch, standoff, top


def blocked_by_cloud(a, b, cloud, radius, tree=None, tol=CLEAR_TOL):
    """Which segments ``a``-``b`` (N, 3) pass closer than ``radius - tol`` to a point of
    ``cloud`` (M, 3): bool (N,).

    One ball query per segment (its midpoint, half its length plus ``radius``), then the
    exact point-segment distance of the candidates.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if not len(a) or not len(cloud):
        return np.zeros(len(a), dtype=bool)
    tree = tree if tree is not None else cKDTree(cloud)
    mid = 0.5 * (a + b)
    reach = 0.5 * np.linalg.norm(b - a, axis=1) + radius
    lists = tree.query_ball_point(mid, reach, return_sorted=False)
    counts = np.fromiter((len(x) for x in lists), dtype=np.int64, count=len(lists))
    out = np.zeros(len(a), dtype=bool)
    if not counts.sum():
        return out
    owner = np.repeat(np.arange(len(a)), counts)
    cand = np.concatenate([np.asarray(x, dtype=np.int64) for x in lists if len(x)])
    close = segment_distance(cloud[cand], a[owner], b[owner]) < radius - tol
    out[owner[close]] = True
    return out


# ---------------------------------------------------------------------- visiting order
def travel_length(points):
    """Length (mm) of the polyline through ``points`` (N, 3) in their order."""
    P = np.asarray(points, dtype=float)
    return float(np.linalg.norm(np.diff(P, axis=0), axis=1).sum()) if len(P) > 1 else 0.0


def serpentine(rows, along):
    """Visiting order row by row, every other row reversed: indices (N,).

    ``rows``: the row of every point (int); ``along``: its position along the row."""
    rows = np.asarray(rows)
    along = np.asarray(along, dtype=float)
    order = np.lexsort((along, rows))
    r = rows[order]
    starts = np.flatnonzero(np.r_[True, r[1:] != r[:-1]])
    ends = np.r_[starts[1:], len(order)]
    parts = [order[s:e] if k % 2 == 0 else order[s:e][::-1]
             for k, (s, e) in enumerate(zip(starts, ends))]
    return np.concatenate(parts) if parts else order


def nearest_neighbour(points, start=0):
    """Greedy nearest-neighbour tour through ``points`` (N, 3) from ``start``: indices (N,)."""
    P = np.asarray(points, dtype=float)
    n = len(P)
    if n < 2:
        return np.arange(n)
    tree = cKDTree(P)
    visited = np.zeros(n, dtype=bool)
    order = np.empty(n, dtype=np.int64)
    cur = int(start)
    for k in range(n):
        order[k] = cur
        visited[cur] = True
        if k == n - 1:
            break
        nxt = -1
        want = 8
        while nxt < 0:
            want = min(want, n)
            _, idx = tree.query(P[cur], k=want)
            free = [i for i in np.atleast_1d(idx) if i < n and not visited[i]]
            if free:
                nxt = int(free[0])
            elif want == n:
                nxt = int(np.flatnonzero(~visited)[0])
            want *= 4
        cur = nxt
    return order


#: largest plan the nearest-neighbour tour is tried on (its loop is Python's)
NEAREST_LIMIT = 5000


def visiting_order(points, rows, along, how="auto"):
    """``(order, name, length)``: the visiting order of ``points`` (N, 3) (the stand-off
    positions), its name (``serpentine`` or ``nearest``) and its travel length (mm).

    ``how``: ``serpentine`` (row by row), ``nearest`` (greedy nearest neighbour from the
    serpentine's first point), ``auto`` (the shorter of the two; the nearest-neighbour tour
    only up to :data:`NEAREST_LIMIT` points)."""
    ser = serpentine(rows, along)
    tours = {}
    if how in ("auto", "serpentine"):
        tours["serpentine"] = ser
    if how == "nearest" or (how == "auto" and len(ser) <= NEAREST_LIMIT):
        tours["nearest"] = nearest_neighbour(points, ser[0] if len(ser) else 0)
    lengths = {k: travel_length(np.asarray(points)[o]) for k, o in tours.items()}
    name = min(lengths, key=lengths.get)
    return tours[name], name, lengths[name]
