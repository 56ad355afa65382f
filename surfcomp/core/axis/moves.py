# SPDX-License-Identifier: LGPL-2.1-or-later
"""Move planning for the axis error compensation: sample, compensate and split moves.

Works on the moves of a program as arrays (no FreeCAD, no G-code text): any object with

- ``kind`` (m,) int: 0 rapid, 1 line, 2 clockwise arc, 3 counter-clockwise arc;
- ``start``, ``end``, ``centre`` (m, 3): mm (``centre`` NaN for lines);
- ``plane`` (m,) int 17/18/19 and ``turns`` (m,) int (see :mod:`surfcomp.core.axis.arcs`),

such as :class:`surfcomp.io.gcode.Program`. Each programmed point ``X`` gets the command
``X'`` with ``X' + E(X') = X`` (:meth:`surfcomp.core.axis.axis_errors.AxisErrorModel.compensate`).
"""

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from .. import limits
from ..progress import report
from .arcs import arc_points, arc_step_counts, arc_steps

#: shortest accepted segment length (mm) and most points :func:`plan_moves` may sample
#: (:mod:`surfcomp.core.limits`)
MIN_SEGMENT_LENGTH = limits.MIN_SEGMENT_LENGTH
MAX_SEGMENTS = limits.MAX_SEGMENTS


@dataclass
class MovePlan:
    """Compensated output points of every move.

    Attributes
    ----------
    offsets : ndarray (m + 1,) int
        Points of move ``j`` are ``[offsets[j], offsets[j + 1])``; the last is its end.
    nominal, compensated : ndarray (N, 3)
        Programmed points on the path (mm) and the commands that make the tool land there.
    split : ndarray (m,) bool
        The move is written as more than one piece (a split line or a converted arc).
    keep : ndarray (m,) bool
        The move is left exactly as programmed (an arc whose compensation is below
        ``still`` everywhere).
    chord_deviation : ndarray (m,)
        For G1 moves longer than the segment length: largest distance (mm) of the
        compensated intermediate points from the compensated chord (0 otherwise).
    """

    offsets: np.ndarray
    nominal: np.ndarray
    compensated: np.ndarray
    split: np.ndarray
    keep: np.ndarray
    chord_deviation: np.ndarray

    def points(self, j):
        return self.compensated[self.offsets[j]:self.offsets[j + 1]]


@dataclass
class SegmentEstimate:
    """How many points :func:`plan_moves` would sample (floats: they may be huge).

    Attributes
    ----------
    total : float
        All sampled points: one per rapid move, the pieces of every line and arc.
    by_angle : float
        Of ``total``, the pieces of arcs whose count is set by the arc tolerance rather
        than by the segment length.
    length : float
        Length (mm) of the G1 moves and arcs (helix length).
    """

    total: float
    by_angle: float
    length: float

    def __add__(self, other):
        """The estimate of two parts of a program together."""
        return SegmentEstimate(self.total + other.total, self.by_angle + other.by_angle,
                               self.length + other.length)


def estimate_segments(prog, segment_length, arc_tolerance):
    """Count the points :func:`plan_moves` would sample, without sampling them.

    Parameters
    ----------
    prog : moves
        The program's moves (module docstring).
    segment_length, arc_tolerance : float
        As in :func:`plan_moves` (mm, positive).

    Returns
    -------
    SegmentEstimate
        Exactly the number of points :func:`plan_moves` samples, as floats.
    """
    kind = np.asarray(prog.kind)
    lines = kind == 1
    length = np.linalg.norm(prog.end - prog.start, axis=1)
    with np.errstate(over="ignore"):
        pieces = np.maximum(1.0, np.ceil(length[lines] / segment_length - 1e-9))
    total = float((kind == 0).sum()) + float(pieces.sum())
    by_angle = 0.0
    arc_length = 0.0
    for j in np.flatnonzero(kind >= 2):
        by_len, by_ang = arc_step_counts(prog.start[j], prog.end[j], prog.centre[j],
                                         prog.plane[j], kind[j] == 2, prog.turns[j],
                                         segment_length, arc_tolerance)
        n_len = max(1.0, math.ceil(by_len - 1e-9)) if math.isfinite(by_len) else by_len
        n_ang = math.ceil(by_ang - 1e-9) if math.isfinite(by_ang) else by_ang
        total += max(n_len, n_ang)
        if n_ang > n_len:
            by_angle += n_ang
        arc_length += by_len * segment_length
    return SegmentEstimate(total, by_angle, float(length[lines].sum()) + arc_length)


def check_segments(prog, segment_length, arc_tolerance, max_segments=MAX_SEGMENTS,
                   names=("segment length", "arc tolerance"), source=None):
    """Refuse a plan that would sample more than ``max_segments`` points.

    Parameters
    ----------
    prog : moves
    segment_length, arc_tolerance : float
        mm.
    max_segments : int
    names : (str, str)
        What to call the segment length and the arc tolerance in the message (the
        command line passes its option names).
    source : str, optional
        File name for the message.

    Returns
    -------
    SegmentEstimate

    Raises
    ------
    InputError
        Naming the estimate, the limit and the setting that causes it.
    """
    est = estimate_segments(prog, segment_length, arc_tolerance)
    if est.total > max_segments:
        refuse_segments(est, prog.n_moves, segment_length, arc_tolerance, max_segments, names,
                        source)
    return est


def refuse_segments(est, n_moves, segment_length, arc_tolerance, max_segments=MAX_SEGMENTS,
                    names=("segment length", "arc tolerance"), source=None):
    """Raise the :class:`InputError` of :func:`check_segments` for the estimate ``est`` of
    a program of ``n_moves`` moves (a program read in blocks adds up their estimates)."""
    if est.by_angle > est.total / 2:
        raise InputError("%s %g mm: the program would be split into about %.3g segments "
                         "(%.3g of them chords of arcs, set by this tolerance), more than the "
                         "%d one compensation may write (memory and time); expected a "
                         "larger %s" % (names[1], arc_tolerance, est.total, est.by_angle,
                                        max_segments, names[1]), file=source)
    # every move adds at most one piece to length / segment_length
    needed = est.length / max(max_segments - n_moves, 1)
    raise InputError("%s %g mm: the program's %.6g mm of G1 moves and arcs would be split "
                     "into about %.3g segments, more than the %d one compensation may write "
                     "(memory and time); expected a %s of at least %.3g mm"
                     % (names[0], segment_length, est.length, est.total, max_segments,
                        names[0], _ceil3(needed)), file=source)


def _ceil3(x):
    """``x`` rounded up to three significant digits."""
    if not (math.isfinite(x) and x > 0):
        return x
    e = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.ceil(x / e) * e


def check_lengths(segment_length, tolerance, arc_tolerance,
                  names=("segment length", "tolerance", "arc tolerance")):
    """Refuse settings outside their domain (NaN and infinity included).

    ``segment_length`` finite and at least :data:`MIN_SEGMENT_LENGTH`; ``tolerance``
    finite and >= 0; ``arc_tolerance`` finite and > 0 (mm).
    """
    if not (math.isfinite(segment_length) and segment_length >= MIN_SEGMENT_LENGTH):
        raise InputError("%s %r: expected a positive length of at least %g mm (1 um)"
                         % (names[0], segment_length, MIN_SEGMENT_LENGTH))
    if not (math.isfinite(tolerance) and tolerance >= 0):
        raise InputError("%s %r: expected a finite length >= 0 mm" % (names[1], tolerance))
    if not (math.isfinite(arc_tolerance) and arc_tolerance > 0):
        raise InputError("%s %r: expected a finite length > 0 mm"
                         % (names[2], arc_tolerance))


def plan_moves(prog, model, segment_length=2.0, tolerance=1e-4, arc_tolerance=1e-3,
               still=0.0, progress=None, max_segments=MAX_SEGMENTS):
    """Sample, compensate and split the moves of a program (vectorised).

    Parameters
    ----------
    prog : moves
        The program's moves (module docstring), e.g. :class:`surfcomp.io.gcode.Program`.
    model : surfcomp.core.axis.axis_errors.AxisErrorModel
        In program coordinates (mm).
    segment_length : float
        Longest piece (mm) a G1 move or an arc chord is split into.
    tolerance : float
        A G1 move is split only if its compensated points leave the compensated chord by
        more than this (mm).
    arc_tolerance : float
        Largest chord-to-arc deviation (mm) of a converted arc.
    still : float or ndarray (m,)
        An arc whose compensation is at most this (mm) at every sample stays unchanged.
    max_segments : int
        Most points to sample (:func:`check_segments`).

    Returns
    -------
    MovePlan

    Raises
    ------
    InputError
        Settings outside their domain (:func:`check_lengths`) or too many segments.
    """
    check_lengths(segment_length, tolerance, arc_tolerance)
    check_segments(prog, segment_length, arc_tolerance, max_segments,
                   source=getattr(prog, "source", None))
    m = prog.n_moves
    kind = prog.kind
    report(progress, 0.0, "sampling %d moves" % m)
    nseg = np.ones(m, dtype=int)
    lines = kind == 1
    length = np.linalg.norm(prog.end - prog.start, axis=1)
    nseg[lines] = np.maximum(1, np.ceil(length[lines] / segment_length - 1e-9)).astype(int)
    for j in np.flatnonzero(kind >= 2):
        nseg[j] = arc_steps(prog.start[j], prog.end[j], prog.centre[j], prog.plane[j],
                            kind[j] == 2, prog.turns[j], segment_length, arc_tolerance)
    still = np.broadcast_to(np.asarray(still, dtype=float), (m,))
    dev, keep, split = np.zeros(m), np.zeros(m, dtype=bool), np.zeros(m, dtype=bool)
    nominal, comp = [], []
    # the samples of a run of moves at a time: the points kept are those of the split
    # moves and the ends, so the memory follows the output, not the samples
    bounds = np.cumsum(nseg)
    a = 0
    while a < m:
        b = max(a + 1, int(np.searchsorted(bounds, bounds[a] - nseg[a] + PLAN_CHUNK,
                                           side="right")))
        report(progress, a / max(m, 1), "compensating moves %d to %d" % (a + 1, b))
        part = _plan_part(prog, model, nseg, a, min(b, m), tolerance, still, dev, keep, split)
        nominal.append(part[0])
        comp.append(part[1])
        a = b
    new_n = np.where(split, nseg, 1)
    new_off = np.zeros(m + 1, dtype=int)
    np.cumsum(new_n, out=new_off[1:])
    report(progress, 1.0, "planned")
    return MovePlan(new_off, np.concatenate(nominal or [np.zeros((0, 3))]),
                    np.concatenate(comp or [np.zeros((0, 3))]), split, keep, dev)


#: samples planned at a time by :func:`plan_moves` (a few tens of MB of temporaries)
PLAN_CHUNK = 200_000


def _plan_part(prog, model, nseg_all, a, b, tolerance, still, dev, keep, split):
    """Sample, compensate and decide moves ``a`` to ``b - 1``: fills ``dev``, ``keep``,
    ``split`` there; returns the (nominal, compensated) points kept (split moves' pieces
    and every move's end)."""
    kind = prog.kind[a:b]
    start, end = prog.start[a:b], prog.end[a:b]
    nseg = nseg_all[a:b]
    m = b - a
    lines = kind == 1
    arcs = np.flatnonzero(kind >= 2)
    offsets = np.zeros(m + 1, dtype=int)
    np.cumsum(nseg, out=offsets[1:])
    total = int(offsets[-1])
    owner = np.repeat(np.arange(m), nseg)
    step = np.arange(total) - offsets[owner] + 1
    frac = step / nseg[owner]
    nominal = start[owner] + (end - start)[owner] * frac[:, None]
    for j in arcs:
        g = a + j
        nominal[offsets[j]:offsets[j + 1]] = arc_points(
            prog.start[g], prog.end[g], prog.centre[g], prog.plane[g], prog.kind[g] == 2,
            prog.turns[g], nseg[j])
    last = offsets[1:] - 1
    nominal[last] = end
    comp = model.compensate(nominal)
    comp_start = model.compensate(start)
    d_part = dev[a:b]
    multi = np.flatnonzero(lines & (nseg > 1))
    if multi.size:
        sel = np.isin(owner, multi)
        own = owner[sel]
        chord = comp_start[own] + (comp[last[own]] - comp_start[own]) * frac[sel][:, None]
        d = np.linalg.norm(comp[sel] - chord, axis=1)
        np.maximum.at(d_part, own, d)
    split_line = lines & (nseg > 1) & (d_part > tolerance)
    if arcs.size:
        moved = np.abs(comp - nominal).max(axis=1)
        worst = np.zeros(m)
        np.maximum.at(worst, owner, moved)
        worst = np.maximum(worst, np.abs(comp_start - start).max(axis=1))
        keep[a + arcs] = worst[arcs] <= still[a:b][arcs]
    split[a:b] = split_line | ((kind >= 2) & ~keep[a:b] & (nseg > 1))
    take = np.repeat(split[a:b], nseg)
    take[last] = True
    return nominal[take], comp[take]
