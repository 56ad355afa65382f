"""Move planning for the axis error compensation: sample, compensate and split moves.

Works on the moves of a program as arrays (no FreeCAD, no G-code text): any object with

- ``kind`` (m,) int: 0 rapid, 1 line, 2 clockwise arc, 3 counter-clockwise arc;
- ``start``, ``end``, ``centre`` (m, 3): mm (``centre`` NaN for lines);
- ``plane`` (m,) int 17/18/19 and ``turns`` (m,) int (see :mod:`surfcomp.core.arcs`),

such as :class:`surfcomp.io.gcode.Program`. Each programmed point ``X`` gets the command
``X'`` with ``X' + E(X') = X`` (:meth:`surfcomp.core.axis_errors.AxisErrorModel.compensate`).
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .arcs import arc_points, arc_steps
from .progress import report


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


def plan_moves(prog, model, segment_length=2.0, tolerance=1e-4, arc_tolerance=1e-3,
               still=0.0, progress=None):
    """Sample, compensate and split the moves of a program (vectorised).

    Parameters
    ----------
    prog : moves
        The program's moves (module docstring), e.g. :class:`surfcomp.io.gcode.Program`.
    model : surfcomp.core.axis_errors.AxisErrorModel
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

    Returns
    -------
    MovePlan
    """
    if not segment_length > 0:
        raise InputError("segment length must be positive (got %r)" % (segment_length,))
    if not (tolerance >= 0 and arc_tolerance > 0):
        raise InputError("tolerances must be positive")
    m = prog.n_moves
    kind = prog.kind
    report(progress, 0.0, "sampling %d moves" % m)
    nseg = np.ones(m, dtype=int)
    lines = kind == 1
    length = np.linalg.norm(prog.end - prog.start, axis=1)
    nseg[lines] = np.maximum(1, np.ceil(length[lines] / segment_length - 1e-9)).astype(int)
    arcs = np.flatnonzero(kind >= 2)
    for j in arcs:
        nseg[j] = arc_steps(prog.start[j], prog.end[j], prog.centre[j], prog.plane[j],
                            kind[j] == 2, prog.turns[j], segment_length, arc_tolerance)
    offsets = np.zeros(m + 1, dtype=int)
    np.cumsum(nseg, out=offsets[1:])
    total = int(offsets[-1])
    owner = np.repeat(np.arange(m), nseg)
    step = np.arange(total) - offsets[owner] + 1
    frac = step / nseg[owner]
    nominal = prog.start[owner] + (prog.end - prog.start)[owner] * frac[:, None]
    for j in arcs:
        nominal[offsets[j]:offsets[j + 1]] = arc_points(
            prog.start[j], prog.end[j], prog.centre[j], prog.plane[j], kind[j] == 2,
            prog.turns[j], nseg[j])
    last = offsets[1:] - 1
    nominal[last] = prog.end
    report(progress, 0.3, "compensating %d points" % total)
    comp = model.compensate(nominal)
    comp_start = model.compensate(prog.start)
    report(progress, 0.8, "splitting")
    dev = np.zeros(m)
    keep = np.zeros(m, dtype=bool)
    multi = np.flatnonzero(lines & (nseg > 1))
    if multi.size:
        sel = np.isin(owner, multi)
        own = owner[sel]
        chord = comp_start[own] + (comp[last[own]] - comp_start[own]) * frac[sel][:, None]
        d = np.linalg.norm(comp[sel] - chord, axis=1)
        np.maximum.at(dev, own, d)
    split_line = lines & (nseg > 1) & (dev > tolerance)
    still = np.broadcast_to(np.asarray(still, dtype=float), (m,))
    if arcs.size:
        moved = np.abs(comp - nominal).max(axis=1)
        worst = np.zeros(m)
        np.maximum.at(worst, owner, moved)
        worst = np.maximum(worst, np.abs(comp_start - prog.start).max(axis=1))
        keep[arcs] = worst[arcs] <= still[arcs]
    is_arc = kind >= 2
    split = split_line | (is_arc & ~keep & (nseg > 1))
    take = np.repeat(split, nseg) | np.isin(np.arange(total), last)
    new_n = np.where(split, nseg, 1)
    new_off = np.zeros(m + 1, dtype=int)
    np.cumsum(new_n, out=new_off[1:])
    report(progress, 1.0, "planned")
    return MovePlan(new_off, nominal[take], comp[take], split, keep, dev)
