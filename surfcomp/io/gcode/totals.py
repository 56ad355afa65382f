# SPDX-License-Identifier: LGPL-2.1-or-later
"""Whole-program figures of a compensation, added up a block of output points at a time.

A program compensated block by block (:mod:`.stream`) keeps none of its points: the
predicted errors before and after (:class:`PointTotals`) and the bounds check
(:class:`BoundsCheck`) take each block's points and keep only sums, maxima and the few
points that may still be refused. A result that holds all its points
(:class:`surfcomp.io.gcode.result.CompensationResult`) computes them the same way, in one
block.
"""

import numpy as np

from ...errors import GCodeError

#: the largest correction may exceed the largest model error at the programmed points by
#: this fraction: ``|X' - X| = |E(X')|`` differs from ``|E(X)|`` by at most the model's
#: slope times the correction, and no machine's errors change by 10 % of a millimetre
#: per millimetre
CORRECTION_SLACK = 0.1


class _Norms:
    """``n``, max, sum and sum of squares of ``|v|``, largest ``|v_i|`` per axis."""

    def __init__(self):
        self.n = 0
        self.max = self.sum = self.sumsq = 0.0
        self.comp = np.zeros(3)

    def add(self, vectors):
        if vectors.shape[0] == 0:
            return
        m = np.linalg.norm(vectors, axis=1)
        self.n += int(vectors.shape[0])
        self.max = max(self.max, float(m.max()))
        self.sum += float(np.add.reduce(m))
        self.sumsq += float(np.add.reduce(m ** 2))
        self.comp = np.maximum(self.comp, np.abs(vectors).max(axis=0))

    def as_dict(self):
        """As :func:`surfcomp.core.axis.axis_checks.error_stats`."""
        if not self.n:
            return {"n": 0, "max_mm": 0.0, "mean_mm": 0.0, "rms_mm": 0.0,
                    "max_component_mm": [0.0, 0.0, 0.0]}
        return {"n": self.n, "max_mm": self.max, "mean_mm": self.sum / self.n,
                "rms_mm": float(np.sqrt(self.sumsq / self.n)),
                "max_component_mm": self.comp.tolist()}


class PointTotals:
    """Predicted errors before/after compensation and the largest correction, over the
    output points whose axes are all known."""

    def __init__(self, model):
        self.model = model
        self.before, self.after = _Norms(), _Norms()
        self.unknown = 0
        self.max_correction = 0.0

    def add(self, nominal, emitted, known):
        nom, emi = nominal[known], emitted[known]
        self.unknown += int((~known).sum())
        self.before.add(self.model.error(nom))
        self.after.add(self.model.actual(emi) - nom)
        if nom.shape[0]:
            corr = np.linalg.norm(emi - nom, axis=1)
            self.max_correction = max(self.max_correction, float(corr.max()))

    def predicted(self):
        return {"before": self.before.as_dict(), "after": self.after.as_dict(),
                "points_unknown_axes": self.unknown}


class BoundsCheck:
    """Refuse an output that moves a point farther than the model can explain
    (:meth:`surfcomp.io.gcode.result.CompensationResult.check_bounds`), its points given
    a block at a time.

    The limit depends on the model's largest error over all the program's points, which
    only grows: a point within the limit of the points seen so far stays within it, so
    only the points beyond it are kept until :meth:`finish`.
    """

    def __init__(self, model, max_error=None):
        self.model = model
        self.max_error = max_error
        self.n = 0
        self.largest = 0.0
        self.error_over = 0
        self.error_first = None     # (error, nominal, line) of the first point over max_error
        self.kept = []              # (corr, emitted, nominal, line) of points maybe over

    def add(self, nominal, emitted, line, resolution=0.0):
        """One block of points; ``resolution`` at most the final one."""
        if nominal.shape[0] == 0:
            return
        self.n += nominal.shape[0]
        corr = np.linalg.norm(emitted - nominal, axis=1)
        error = np.linalg.norm(self.model.error(nominal), axis=1)
        if self.max_error is not None:
            over = np.flatnonzero(~(error <= self.max_error))
            if over.size and self.error_first is None:
                k = over[0]
                self.error_first = (float(error[k]), nominal[k].copy(), _line(line, k))
            self.error_over += int(over.size)
        self.largest = float(np.maximum(self.largest, error.max()))     # NaN stays
        maybe = np.flatnonzero(~(corr <= self._limit(resolution)))
        if maybe.size:
            self.kept.append((corr[maybe], emitted[maybe], nominal[maybe],
                              None if line is None else line[maybe]))
        self._prune(resolution)

    def _limit(self, resolution):
        return (1.0 + CORRECTION_SLACK) * self.largest + resolution + 1e-9

    def _prune(self, resolution):
        limit = self._limit(resolution)
        kept = []
        for corr, emitted, nominal, line in self.kept:
            sel = ~(corr <= limit)
            if sel.any():
                kept.append((corr[sel], emitted[sel], nominal[sel],
                             None if line is None else line[sel]))
        self.kept = kept

    def finish(self, resolution, source=None):
        """Raise the :class:`GCodeError` of the first point out of bounds, if any."""
        if self.n == 0:
            return
        if self.error_over:
            error, nominal, line = self.error_first
            raise GCodeError("the error model predicts an error of %.6g mm at the programmed "
                             "point (%.6g, %.6g, %.6g) mm, more than max_error %g mm (%d "
                             "point(s)): check the units of the error file, or whether the "
                             "program leaves the measured travel (the error functions are "
                             "extrapolated there)"
                             % ((error,) + tuple(nominal) + (self.max_error, self.error_over)),
                             file=source, line=line, options=("max_error",))
        self._prune(resolution)
        if self.kept:
            corr, emitted, nominal, line = self.kept[0]
            count = sum(c[0].size for c in self.kept)
            raise GCodeError("the compensated command (%.6g, %.6g, %.6g) mm for the "
                             "programmed point (%.6g, %.6g, %.6g) mm moves it by %.6g mm, "
                             "more than the error model explains (its largest error at the "
                             "program's points is %.6g mm; %d point(s) affected): nothing "
                             "was written"
                             % (tuple(emitted[0]) + tuple(nominal[0])
                                + (corr[0], self.largest, count)),
                             file=source, line=_line(line, 0))


def _line(line, k):
    return None if line is None else int(line[k])
