"""Results of a compensation: the rewritten program and the points it commands."""

from dataclasses import dataclass

import numpy as np

from ...core.axis_errors import error_stats
from .interpreter import Program


@dataclass
class GCodeResult:
    """The rewritten program and what was done.

    Attributes
    ----------
    data : bytes
        The output program.
    stats : dict
        ``lines_in``, ``lines_out``, ``lines_changed`` (input lines rewritten),
        ``lines_added``, ``moves``, ``moves_split`` (G1 moves split), ``arcs_converted``,
        ``points`` (output move end points).
    nominal, emitted : ndarray (N, 3)
        For every output move end point: the programmed point on the path (mm) and the
        command written (mm, after rounding). Axes not yet known hold the assumed value.
    known : ndarray (N,) bool
        Every axis of the point had a known program position.
    warnings : list of str
    """

    data: bytes
    stats: dict
    nominal: np.ndarray
    emitted: np.ndarray
    known: np.ndarray
    warnings: list
    program: Program = None

    def predicted(self, model):
        """Predicted positional error at the output points (known ones), before/after.

        ``before`` = ``|E(X)|`` for the programmed points; ``after`` = ``|X' + E(X') - X|``
        for the commands written (rounding and chord effects included).
        """
        k = self.known
        before = model.error(self.nominal[k])
        after = model.actual(self.emitted[k]) - self.nominal[k]
        return {"before": error_stats(before), "after": error_stats(after),
                "points_unknown_axes": int((~k).sum())}


@dataclass
class CommandsResult:
    """Compensated command list.

    Attributes
    ----------
    commands : list
        Per output command either an ``int`` (index of an input command kept unchanged)
        or a ``(name, parameters)`` pair.
    stats, nominal, emitted, known, warnings
        As in :class:`GCodeResult` (``lines_*`` count commands).
    """

    commands: list
    stats: dict
    nominal: np.ndarray
    emitted: np.ndarray
    known: np.ndarray
    warnings: list
    program: Program = None

    predicted = GCodeResult.predicted
