# SPDX-License-Identifier: LGPL-2.1-or-later
"""Points the moved edge of their face slides past (issue 30; numpy/scipy only).

Next to a sharp edge the displacement of a region turns to the edge's miter
(:mod:`surfcomp.core.compensation.region_build`): its normal component stays the
correction and its part along the face, the *slide*, moves the face's edge along the face
by that much, as the intersection of two offset faces moves (a wedge whose normals are
72 deg apart, offset inwards by ``delta``, ends ``delta (1 - cos 72) / sin 108 = 0.73
delta`` short of the offset of its nominal edge, on each face). A measured point nearer to
the edge than that slide has no corrected face along its normal line: the corner is cut
back by design, and the check of the realised correction (a Newton on the corrected face,
its parameters held to the face) stops on the corrected face's boundary and reads the
face's curl over the rest of the slide (``kappa s^2 / 2``), not a fit error.

The criterion (:func:`edge_slide`): the point's distance from the nearest sharp edge's
sample polyline is less than the displacement's part along the face at the point in the
direction into the face, ``D . t``: ``t`` the face's own direction into itself, normal to
the edge, at the edge's sample nearest to the point (``SharpEdges.own_inward``), laid in
the point's tangent plane. Its sign is checked per edge against the face's own points
between :data:`VOTE_MIN` and :data:`VOTE_REACH` from the edge (most must lie on its side;
else it is turned round), a guard for the directions taken from the faces' boundary
orientation: on the BladeX blade they point into the face at every edge (a step of 10 um
along them stays on the face, the step against them leaves it, at 40 samples an edge but
one of the pressure side's 179 deg edge with its tip cap), and the vote of 20 000 points
of the pressure side turns none of its four edges; where a face curls away within the
vote's reach (the leading edge) some of its points lie behind the edge's line, without
changing the majority. The distance is unsigned: the two faces of an edge need not meet
exactly (the BladeX sides' trailing edges lie up to 3.3 um apart), and a point 1 um from
its own face's edge may lie 2 um beyond the polyline: it counts 2 um away, the stricter
reading. Only an edge that moves *into* the face (a convex edge corrected inwards, a
concave one corrected outwards) passes a point: elsewhere the corrected face extends
beyond the nominal edge, the line meets it, and the point is checked as any other. The
threshold is uncertain by the faces' gap along the edge; a point that near it misses by
little (the curl's sagitta over the difference). Along an edge of other faces (a point
near a vertex) ``t`` is the direction from the polyline to the point, and a point on that
polyline (under :data:`ON_EDGE` mm) is not classified: it stays with the checked points.
"""

import numpy as np

from .region_build import displacement

#: a point nearer to an edge than this (mm) has no direction from the edge: not classified
ON_EDGE = 1e-9
#: the face's points within this (mm) of an edge, and farther than VOTE_MIN (beyond the
#: gap of two faces' edges), check the sign of its direction into the face
VOTE_REACH = 1.0
VOTE_MIN = 0.01


def edge_slide(x, n, delta, sharp):
    """The slide of the edge nearest to each point towards it, and the distance.

    ``x`` (M, 3) points of one face, ``n`` (M, 3) its outward unit normals there, ``delta``
    (M,) the correction in mm (positive inwards), ``sharp``: the region's
    :class:`~surfcomp.core.compensation.region_edges.SharpEdges` as the face sees them
    (``for_face``) or None.

    Returns ``(slide, distance)`` in mm: the displacement's part along the face into it
    at each point, from the nearest edge (0 beyond the reach of every edge, negative where
    the edge moves out of the face), and the point's distance from that edge's sample
    polyline (inf beyond the reach). A point lies beyond its face's moved edge where
    ``slide > distance``.
    """
    x = np.asarray(x, dtype=float)
    slide = np.zeros(len(x))
    dist = np.full(len(x), np.inf)
    if sharp is None or len(sharp.points) == 0 or not len(x):
        return slide, dist
    n = np.asarray(n, dtype=float)
    delta = np.asarray(delta, dtype=float)
    D = displacement(x, n, delta, sharp)
    along = D - np.einsum("ij,ij->i", D, n)[:, None] * n
    # only an edge within the largest slide can be passed; the farther points vote
    reach = float(np.max(np.linalg.norm(along, axis=1)))
    foot, near_dist, near = sharp.feet(x, max(reach, VOTE_REACH))
    found = near >= 0
    off = np.where(found[:, None], x - foot, 0.0)
    t = off.copy()
    mine = np.zeros(len(x), dtype=bool)
    own = getattr(sharp, "own_inward", None)
    if own is not None:
        inward = own[np.where(found, near, 0)]
        mine = found & np.isfinite(inward[:, 0])
        _checked(inward, off, near_dist, sharp.edge[np.where(found, near, 0)], mine)
        t[mine] = inward[mine]
    t -= np.einsum("ij,ij->i", t, n)[:, None] * n
    size = np.linalg.norm(t, axis=1)
    ok = found & (size > ON_EDGE) & (mine | (near_dist > ON_EDGE))
    slide[ok] = np.einsum("ij,ij->i", along[ok], t[ok]) / size[ok]
    dist[ok] = near_dist[ok]
    return slide, dist


def _checked(inward, off, dist, edge, mine):
    """Turn round, in place, the directions into the face of the edges most of whose
    points between VOTE_MIN and VOTE_REACH lie on the other side."""
    side = np.sign(np.einsum("ij,ij->i", off, inward))
    voter = mine & (dist > VOTE_MIN) & (dist <= VOTE_REACH)
    for e in np.unique(edge[mine]):
        of = edge == e
        if np.sum(side[voter & of]) < 0:
            inward[of & mine] *= -1.0
