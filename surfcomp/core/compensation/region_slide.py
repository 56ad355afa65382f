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

The criterion (:func:`edge_slide`): the point's distance to the nearest sharp edge
(polyline of the edge's samples) is less than the displacement's part along the face at
the point in the direction from the edge to the point, ``D . t`` with ``t`` the unit
direction from the edge's nearest point to the point, in the point's tangent plane. Only
an edge that moves *into* the face (a convex edge corrected inwards, a concave one
corrected outwards) passes a point: elsewhere the corrected face extends beyond the
nominal edge and the line meets it, and the point is checked as any other. A point on
the edge itself (no direction from the edge to it, under :data:`ON_EDGE` mm) is not
classified: it stays with the checked points.
"""

import numpy as np

from .region_build import displacement

#: a point nearer to an edge than this (mm) has no direction from the edge: not classified
ON_EDGE = 1e-9


def edge_slide(x, n, delta, sharp):
    """The slide of the edge nearest to each point towards it, and the distance.

    ``x`` (M, 3) points of one face, ``n`` (M, 3) its outward unit normals there, ``delta``
    (M,) the correction in mm (positive inwards), ``sharp``: the region's
    :class:`~surfcomp.core.compensation.region_edges.SharpEdges` as the face sees them
    (``for_face``) or None.

    Returns ``(slide, distance)`` in mm: the displacement's part along the face towards the
    point, from the nearest edge (0 beyond the reach of every edge, negative where the edge
    moves away from the point), and the distance to that edge (inf beyond the reach). A
    point lies beyond its face's moved edge where ``slide > distance``.
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
    # only an edge within the largest slide can be passed
    reach = float(np.max(np.linalg.norm(along, axis=1)))
    foot, dist = sharp.feet(x, reach)
    t = x - foot
    t -= np.einsum("ij,ij->i", t, n)[:, None] * n
    size = np.linalg.norm(t, axis=1)
    ok = np.isfinite(dist) & (size > ON_EDGE)
    slide[ok] = np.einsum("ij,ij->i", along[ok], t[ok]) / size[ok]
    return slide, dist
