# SPDX-License-Identifier: LGPL-2.1-or-later
"""Circular and helical arcs of G2/G3 moves: centres, points, chord counts (no FreeCAD).

An arc lies in one of three planes, named by their G code: ``17`` (XY), ``18`` (ZX) and
``19`` (YZ). :data:`PLANES` gives, per plane, the indices of its first and second axis and
of the linear (helix) axis, in the order LinuxCNC and RS274/NGC use (G18: Z first, X
second), so that "clockwise" is seen from the positive end of the plane normal. Lengths
in mm.
"""

import math

import numpy as np

from ...errors import InputError

#: plane code -> (first axis, second axis, linear axis)
PLANES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}
#: absolute and relative tolerance on the two radii of an arc (mm, fraction)
ARC_RADIUS_TOL = (0.005, 1e-3)
#: in-plane distance (mm) under which an arc's end equals its start: a full circle
FULL_CIRCLE_TOL = 1e-9


def radius_tolerance(radius):
    """Largest accepted difference (mm) between an arc's start and end radius."""
    return max(ARC_RADIUS_TOL[0], ARC_RADIUS_TOL[1] * radius)


def centre_from_radius(start, end, radius, plane, clockwise):
    """Centre of an arc given by its radius (``R`` word).

    Parameters
    ----------
    start, end : sequence of 3 float
        mm.
    radius : float
        mm; negative: the arc longer than half a turn.
    plane : {17, 18, 19}
    clockwise : bool
        G2 (True) or G3.

    Returns
    -------
    list of 3 float
        The centre: the plane's two coordinates computed, the third copied from ``start``.

    Raises
    ------
    InputError
        Start and end coincide (a full circle needs a centre), or the radius is smaller
        than half the chord (beyond :data:`ARC_RADIUS_TOL`).
    """
    p, q, _l = PLANES[int(plane)]
    s, e = start, end
    dx, dy = e[p] - s[p], e[q] - s[q]
    chord = math.hypot(dx, dy)
    if chord < FULL_CIRCLE_TOL:
        raise InputError("R-format arc with coinciding start and end (a full circle needs "
                         "I/J/K)")
    half = chord / 2.0
    rr = abs(radius)
    if rr < half - radius_tolerance(rr):
        raise InputError("arc radius R%g is smaller than half the distance to the end point "
                         "(%.4f mm)" % (radius, half))
    h = math.sqrt(max(rr * rr - half * half, 0.0))
    # unit vector to the right of the chord direction
    rx, ry = dy / chord, -dx / chord
    side = 1.0 if clockwise else -1.0
    if radius < 0:
        side = -side
    c = list(s)
    c[p] = (s[p] + e[p]) / 2.0 + side * h * rx
    c[q] = (s[q] + e[q]) / 2.0 + side * h * ry
    return c


def check_centre(start, end, centre, plane):
    """Refuse an arc whose end is not on the circle through its start.

    Raises
    ------
    InputError
        The start and end radii differ by more than :func:`radius_tolerance`, or the
        radius is zero.
    """
    p, q, _l = PLANES[int(plane)]
    r0 = math.hypot(start[p] - centre[p], start[q] - centre[q])
    r1 = math.hypot(end[p] - centre[p], end[q] - centre[q])
    if abs(r0 - r1) > radius_tolerance(max(r0, r1)):
        raise InputError("arc end point is not on the circle: radius %.4f mm at the start, "
                         "%.4f mm at the end" % (r0, r1))
    if r0 < FULL_CIRCLE_TOL:
        raise InputError("arc with zero radius")


def arc_params(start, end, centre, plane, clockwise, turns):
    """Swept angle and radii of an arc.

    Returns
    -------
    (theta, r0, r1, a0)
        Signed swept angle (rad; negative clockwise; a full turn when start and end
        coincide, plus ``turns - 1`` further turns), start and end radius (mm) and the
        start angle (rad) in the plane.
    """
    s, e, c = start, end, centre
    p, q, _l = PLANES[int(plane)]
    a0 = math.atan2(s[q] - c[q], s[p] - c[p])
    a1 = math.atan2(e[q] - c[q], e[p] - c[p])
    r0 = math.hypot(s[p] - c[p], s[q] - c[q])
    r1 = math.hypot(e[p] - c[p], e[q] - c[q])
    full = math.hypot(e[p] - s[p], e[q] - s[q]) < FULL_CIRCLE_TOL
    if clockwise:
        theta = -((a0 - a1) % (2 * math.pi))
        if full or theta == 0.0:
            theta = -2 * math.pi
        theta -= 2 * math.pi * (turns - 1)
    else:
        theta = (a1 - a0) % (2 * math.pi)
        if full or theta == 0.0:
            theta = 2 * math.pi
        theta += 2 * math.pi * (turns - 1)
    return theta, r0, r1, a0


def arc_points(start, end, centre, plane, clockwise, turns, n):
    """Points on an arc (helix) at ``n`` equal angle steps, the last one ``end``.

    Parameters
    ----------
    start, end, centre : array_like (3,)
        mm; only the plane's two coordinates of ``centre`` are used.
    plane : {17, 18, 19}
    clockwise : bool
        G2 (True) or G3, seen from the positive end of the plane normal.
    turns : int
        Full turns (P word; 1 = less than one turn, or one full circle if start = end).
    n : int
        Number of steps.

    Returns
    -------
    ndarray (n, 3)
        The radius changes linearly with the angle from the start radius to the end radius
        (as controllers interpolate slightly inconsistent arcs); the linear axis moves
        linearly with the angle (helix).
    """
    s, e, c = (np.asarray(v, dtype=float) for v in (start, end, centre))
    theta, r0, r1, a0 = arc_params(s, e, c, plane, clockwise, turns)
    p, q, w = PLANES[int(plane)]
    f = np.arange(1, n + 1) / n
    ang = a0 + theta * f
    r = r0 + (r1 - r0) * f
    out = np.empty((n, 3))
    out[:, p] = c[p] + r * np.cos(ang)
    out[:, q] = c[q] + r * np.sin(ang)
    out[:, w] = s[w] + (e[w] - s[w]) * f
    out[-1] = e
    return out


def arc_step_counts(start, end, centre, plane, clockwise, turns, segment_length,
                    arc_tolerance):
    """The two lower bounds on an arc's number of chords, as floats (may be huge).

    Returns
    -------
    (by_length, by_angle)
        ``length / segment_length`` (the arc's length along the helix) and
        ``|theta| / dphi`` with ``dphi`` the largest angle step whose sagitta
        ``r (1 - cos(dphi / 2))`` stays within ``arc_tolerance`` (at most a quarter turn;
        infinite when the tolerance is too small for any chord).
    """
    s, e, c = (np.asarray(v, dtype=float) for v in (start, end, centre))
    theta, r0, r1, _a0 = arc_params(s, e, c, plane, clockwise, turns)
    _p, _q, w = PLANES[int(plane)]
    r = max(r0, r1)
    length = math.hypot(0.5 * (r0 + r1) * theta, e[w] - s[w])
    dphi = math.pi / 2
    if arc_tolerance < r:
        dphi = min(dphi, 2.0 * math.acos(1.0 - arc_tolerance / r))
    # a tolerance below the float resolution of the radius gives dphi = 0: no chord fits
    return length / segment_length, (abs(theta) / dphi if dphi > 0 else math.inf)


def arc_steps(start, end, centre, plane, clockwise, turns, segment_length, arc_tolerance):
    """Number of chords for an arc: each at most ``segment_length`` long and deviating at
    most ``arc_tolerance`` (mm) from the arc (sagitta ``r (1 - cos(dphi / 2))``), and at
    least 4 per full turn."""
    by_length, by_angle = arc_step_counts(start, end, centre, plane, clockwise, turns,
                                          segment_length, arc_tolerance)
    return max(1, int(math.ceil(by_length - 1e-9)), int(math.ceil(by_angle - 1e-9)))
