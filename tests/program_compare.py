# SPDX-License-Identifier: LGPL-2.1-or-later
"""Two ball-end finishing programs compared as surfaces (tests of the direct program route).

Both programs are read by LinuxCNC's ``rs274`` (:func:`tests.pure.test_gcode_rs274.rs274`);
their feed moves' end points are tool tips. A drop-cutter program's tips lie on the height
field of the ball's tip over the face, sampled along its cut lines: each point of program A
is compared with that surface of program B at A's XY. B's surface there is its nearest
sample carried to A's XY along the exact drop-cutter surface
(:func:`tests.toolpath_checks.drop_cutter`) of the face B was cut on (the corrected face).
The vertical difference times ``n_z`` at the contact is the distance of the two surfaces
along their normal.
"""

import numpy as np
from scipy.spatial import cKDTree

from tests.toolpath_checks import drop_cutter


def feed_points(moves):
    """End points (mm) of the ``STRAIGHT_FEED`` moves of rs274's canonical moves."""
    return np.array([m["end"] for m in moves if m["kind"] == "STRAIGHT_FEED"])


def surface_distance(surface, outward, radius, a, b, carry=None, near=0.5, contact=1e-3):
    """Distance (mm) along the normal of program A's tips ``a`` (N, 3) from program B's tip
    surface (samples ``b``), at the points of A whose ball touches the face inside its
    border (clearance within ``contact`` mm of the drop surface of ``carry``) and that
    have a sample of B within ``near`` mm in XY. ``carry``: the surface B was cut on
    (default ``surface``), whose drop surface carries B's samples to A's XY.

    Returns
    -------
    (distance, xy_shift)
        ``distance`` (k,) and the XY distance to the sample of B each was carried from.
    """
    carry = surface if carry is None else carry
    z_here, pr = drop_cutter(carry, outward, a[:, :2], a[:, 2], radius)
    gap = pr.distance * outward - radius
    dist, k = cKDTree(b[:, :2]).query(a[:, :2])
    z_there, _ = drop_cutter(carry, outward, b[k, :2], b[k, 2], radius)
    # clearance of A's own ball from the nominal: in contact where the drop surface is
    # within the correction's reach of A's tip
    centre = a + [0.0, 0.0, radius]
    from surfcomp.core.projection import project

    own = project(surface, centre)
    touching = ~own.outside & (np.abs(own.distance * outward - radius) <= 0.2)
    use = touching & ~pr.outside & (dist <= near) & (np.abs(gap) <= contact)
    zb = b[k, 2] + (z_here - z_there)
    nz = pr.normal[:, 2] * outward
    return ((a[:, 2] - zb) * nz)[use], dist[use]
