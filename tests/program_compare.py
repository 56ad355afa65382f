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

from tests.toolpath_checks import drop_cutter, projector


def feed_points(moves):
    """End points (mm) of the ``STRAIGHT_FEED`` moves of rs274's canonical moves."""
    return np.array([m["end"] for m in moves if m["kind"] == "STRAIGHT_FEED"])


def surface_distance(surface, outward, radius, a, b, carry=None, near=0.5, window=0.02):
    """Distance (mm) along the normal of program A's tips ``a`` (N, 3) from program B's tip
    surface (samples ``b``), at A's points of the cut.

    A's points of the cut: its ball touches the nominal inside its border (within 0.2 mm),
    a sample of B lies within ``near`` mm in XY, and the tip is within ``window`` mm of the
    drop-cutter height of ``carry`` there. The window (20 um, ten times what is tested)
    leaves out the points a vertical plunge or retract gets when it is split in the blend
    zone: they lie up to millimetres above the surface and are no samples of it. A route
    that moved the cut wrongly would lose its points from the comparison, so callers check
    their number as well. ``carry``: the surface B was cut on (default ``surface``), whose
    drop surface carries B's samples to A's XY.

    Returns
    -------
    (distance, xy_shift)
        ``distance`` (k,) and the XY distance to the sample of B each was carried from.
    """
    carry = surface if carry is None else carry
    z_here, pr = drop_cutter(carry, outward, a[:, :2], a[:, 2], radius)
    dist, k = cKDTree(b[:, :2]).query(a[:, :2])
    z_there, _ = drop_cutter(carry, outward, b[k, :2], b[k, 2], radius)
    own = projector(surface, len(a)).project(a + [0.0, 0.0, radius])
    touching = ~own.outside & (np.abs(own.distance * outward - radius) <= 0.2)
    use = touching & ~pr.outside & (dist <= near) & (np.abs(a[:, 2] - z_here) <= window)
    zb = b[k, 2] + (z_here - z_there)
    nz = pr.normal[:, 2] * outward
    return ((a[:, 2] - zb) * nz)[use], dist[use]
