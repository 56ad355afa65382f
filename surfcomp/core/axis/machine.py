# SPDX-License-Identifier: LGPL-2.1-or-later
"""A 3-axis machine with known geometric errors, to validate a compensation (no FreeCAD).

It stands in for the real machine in tests and benchmarks: it moves the tool by the error
of an axis error model (Dobariya 2015, eq. 14) plus terms no polynomial model represents,
and measures its own per-axis errors the way a laser interferometer would.
"""

import numpy as np

from .axes import AXES, as_points, axis_index


class SimulatedMachine:
    """A 3-axis machine with known geometric errors, for validation.

    The tool lands at ``X + E_true(X)`` with ``E_true`` composed as in eq. 14 from a
    polynomial :class:`surfcomp.core.axis.axis_errors.AxisErrorModel` plus optional
    non-polynomial per-slide terms (e.g. a periodic ball-screw error) that a
    linear/quadratic fit cannot represent.

    Parameters
    ----------
    model : AxisErrorModel
        The polynomial part (its reference is the machine's reference point).
    extra : dict, optional
        ``{'x': f}`` with ``f(t) -> (n, 3)``: additional error (mm) of slide ``x`` at travel
        ``t = X_x - r_x``; should be 0 at ``t = 0`` so that the measurement at the
        reference stays ``e0``.
    """

    def __init__(self, model, extra=None):
        self.model = model
        self.extra = {k.lower(): f for k, f in (extra or {}).items()}
        for k in self.extra:
            axis_index(k)

    def error(self, points):
        """True tool-position error at commanded points (mm), shape (..., 3)."""
        p = as_points(points)
        e = self.model.error(p)
        for ax, f in self.extra.items():
            a = axis_index(ax)
            t = (p[..., a] - self.model.reference[a]).reshape(-1)
            e = e + np.asarray(f(t), dtype=float).reshape(p.shape)
        return e

    def actual(self, points):
        """Where the tool lands for commanded points (mm)."""
        p = as_points(points)
        return p + self.error(p)

    def measure(self, positions, noise=0.0, seed=0):
        """Simulate the per-axis measurement (one slide moves, the others at the reference).

        Parameters
        ----------
        positions : mapping
            ``{'x': positions (n,)}`` (mm).
        noise : float
            Standard deviation (mm) of Gaussian measurement noise per reading.
        seed : int
            Seed of ``numpy.random.default_rng``.

        Returns
        -------
        dict
            ``{'x': (positions (n,), errors (n, 3))}``, the input of
            :func:`surfcomp.core.axis.axis_errors.fit_axis_errors`.
        """
        rng = np.random.default_rng(seed)
        out = {}
        for ax in AXES:
            if ax not in positions and ax.upper() not in positions:
                continue
            p = np.asarray(positions.get(ax, positions.get(ax.upper())), dtype=float)
            pts = np.repeat(self.model.reference[None, :], p.size, axis=0)
            pts[:, axis_index(ax)] = p
            e = self.error(pts)
            if noise:
                e = e + rng.normal(0.0, noise, e.shape)
            out[ax] = (p.copy(), e)
        return out
