# SPDX-License-Identifier: LGPL-2.1-or-later
"""What a compensation returns, and the bookkeeping both writers share.

Both writers (G-code text, :mod:`.emitter`; Path command lists, :mod:`.commands`) return
a :class:`CompensationResult` with the same fields, so the command line and the Path
dressup read one shape: the output, statistics, warnings, and for every output move end
point the programmed point and the command written.
"""

from dataclasses import dataclass

import numpy as np

from .totals import BoundsCheck, PointTotals


@dataclass
class CompensationResult:
    """A compensated program and what was done.

    Attributes
    ----------
    output : bytes or list
        The output program: G-code bytes (:class:`GCodeResult`) or a command list
        (:class:`CommandsResult`).
    stats : dict
        ``lines_in``, ``lines_out``, ``lines_changed`` (input lines rewritten),
        ``lines_added``, ``moves``, ``moves_split`` (G1 moves split), ``arcs_converted``,
        ``points`` (output move end points); for command lists the ``lines_*`` count
        commands.
    nominal, emitted : ndarray (N, 3)
        For every output move end point: the programmed point on the path (mm) and the
        command written (mm, after rounding). Axes not yet known hold the assumed value.
    known : ndarray (N,) bool
        Every axis of the point had a known program position.
    warnings : list of str
    program : surfcomp.io.gcode.Program
        The interpreted input.
    line : ndarray (N,) int
        1-based number of the input line (or command) each output point comes from.
    """

    output: object
    stats: dict
    nominal: np.ndarray
    emitted: np.ndarray
    known: np.ndarray
    warnings: list
    program: object = None
    line: np.ndarray = None

    def predicted(self, model):
        """Predicted positional error at the output points (known ones), before/after.

        ``before`` = ``|E(X)|`` for the programmed points; ``after`` = ``|X' + E(X') - X|``
        for the commands written (rounding and chord effects included).
        """
        totals = PointTotals(model)
        totals.add(self.nominal, self.emitted, self.known)
        return totals.predicted()

    def corrections(self):
        """``|emitted - nominal|`` (mm) at the points whose axes are all known, shape (n,)."""
        return np.linalg.norm(self.emitted[self.known] - self.nominal[self.known], axis=1)

    def max_correction(self):
        """Largest distance (mm) by which a known point was moved (0 without points)."""
        corr = self.corrections()
        return float(corr.max()) if corr.size else 0.0

    def check_bounds(self, model, resolution, source=None, max_error=None):
        """Refuse an output that moves a point farther than the model can explain.

        Every command written must be finite, and no point may be moved by more than
        ``(1 + CORRECTION_SLACK)`` times the model's largest error at the program's
        points plus the output rounding (all points, known axes or not). With
        ``max_error``, the model's error at every programmed point must not exceed it
        either (an extrapolation that far is a unit mistake or a program outside the
        measured travel), which bounds every correction absolutely.

        Parameters
        ----------
        model : surfcomp.core.axis.axis_errors.AxisErrorModel
            The model the output was compensated with.
        resolution : float
            Largest rounding (mm) of one point: half a unit of the last decimal written
            on each axis, summed in quadrature.
        source : str, optional
            File name for messages.
        max_error : float, optional
            Largest plausible error (mm) of the machine.

        Raises
        ------
        GCodeError
            Naming the line of the first point out of bounds.
        """
        check = BoundsCheck(model, max_error)
        check.add(self.nominal, self.emitted, self.line, resolution)
        check.finish(resolution, source)


class GCodeResult(CompensationResult):
    """:class:`CompensationResult` of G-code text; ``output`` (also ``data``) is bytes."""

    @property
    def data(self):
        return self.output


class CommandsResult(CompensationResult):
    """:class:`CompensationResult` of a command list.

    ``output`` (also ``commands``) holds per output command either an ``int`` (index of an
    input command kept unchanged) or a ``(name, parameters)`` pair.
    """

    @property
    def commands(self):
        return self.output


class OutputState:
    """What the machine holds after the output written so far, and the points written.

    Parameters
    ----------
    start : sequence of 3 float or None
        Known start position (program units), or None (nothing held yet).
    """

    def __init__(self, start=None):
        #: value of each axis the machine holds (program units), None when not known
        self.held = [None, None, None] if start is None else [float(v) for v in start]
        self.nominal, self.emitted, self.known, self.line = [], [], [], []
        self.chunks = []                # points recorded before those in the lists, as arrays
        self.changed = self.added = self.split = self.converted = 0

    def forget(self, axes):
        """The program moved these axes to positions it does not know (G53, G28, G30)."""
        for a in axes:
            self.held[a] = None

    def hold_programmed(self, info):
        """A line written as programmed: the machine holds its axis words' values."""
        for a in range(3):
            k = info.axis_words[a]
            if k is not None:
                v = info.words[k].value
                self.held[a] = v if info.absolute else self.held[a] + v

    def record(self, line, nominal, compensated, known, factor=1.0):
        """One output move end point of input line ``line`` (1-based): programmed point
        and compensated command (mm).

        The command recorded is what the machine holds (the written value, ``factor`` mm
        per program unit) on known axes, the compensated value on the others.
        """
        held = self.held
        self.line.append(line)
        self.nominal.append(nominal)
        self.emitted.append([held[a] * factor if (known[a] and held[a] is not None)
                             else compensated[a] for a in range(3)])
        self.known.append(known[0] and known[1] and known[2])

    def record_kept(self, line, point, known):
        """The end point (mm) of a move of input line ``line`` written as programmed."""
        self.line.append(line)
        self.nominal.append(point)
        self.emitted.append(point)
        self.known.append(known[0] and known[1] and known[2])

    def _lists(self):
        pts = (np.array(self.nominal, dtype=float).reshape(-1, 3),
               np.array(self.emitted, dtype=float).reshape(-1, 3),
               np.array(self.known, dtype=bool), np.array(self.line, dtype=int))
        self.nominal, self.emitted, self.known, self.line = [], [], [], []
        return pts

    def record_many(self, line, nominal, emitted):
        """Output move end points as arrays: input lines ``line`` (1-based), programmed
        points and the commands the machine holds (mm, every axis known)."""
        if self.line:
            self.chunks.append(self._lists())
        self.chunks.append((nominal, emitted, np.ones(line.size, dtype=bool), line))

    def take_points(self):
        """The points recorded since the last call as arrays ``(nominal, emitted, known,
        line)``, then forgotten (a program written block by block)."""
        pts = self._lists()
        if self.chunks:
            pts = tuple(np.concatenate(p) for p in zip(*self.chunks, pts))
            self.chunks = []
        return pts

    def stats(self, lines_in, lines_out, moves, points):
        return {"lines_in": lines_in, "lines_out": lines_out, "lines_changed": self.changed,
                "lines_added": self.added, "moves": moves, "moves_split": self.split,
                "arcs_converted": self.converted, "points": points}

    def result(self, cls, output, lines_in, lines_out, prog):
        """The :class:`CompensationResult` subclass ``cls`` of what was recorded."""
        stats = self.stats(lines_in, lines_out, prog.n_moves,
                           len(self.nominal) + sum(c[3].size for c in self.chunks))
        nominal, emitted, known, line = self.take_points()
        return cls(output, stats, nominal, emitted, known, list(prog.warnings), prog, line)
