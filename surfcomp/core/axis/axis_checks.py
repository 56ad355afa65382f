# SPDX-License-Identifier: LGPL-2.1-or-later
"""What a fitted machine-axis error model predicts and how well (no FreeCAD).

The volumetric error map of a model over the work envelope, the statistics of error
vectors, and the validation of a fitted model against a (simulated) machine with known
errors. The model itself and its fit are in :mod:`surfcomp.core.axis.axis_errors`.
"""

from dataclasses import dataclass, field

import numpy as np

from ..progress import report
from .axes import as_points


# ------------------------------------------------------------------ volumetric error map
@dataclass
class VolumetricMap:
    """Predicted error over a box (the work envelope).

    Attributes
    ----------
    axes : tuple of 3 ndarrays
        Grid coordinates along x, y, z (mm).
    error : ndarray (nx, ny, nz, 3)
        ``E(X)`` at the grid points (mm).
    magnitude : ndarray (nx, ny, nz)
        ``|E(X)|`` (mm).
    """

    axes: tuple
    error: np.ndarray
    magnitude: np.ndarray
    stats: dict = field(default_factory=dict)

    def as_dict(self, include_grid=False):
        d = {"envelope_mm": [[float(a[0]), float(a[-1])] for a in self.axes],
             "shape": list(self.magnitude.shape), **self.stats}
        if include_grid:
            d["axes_mm"] = [a.tolist() for a in self.axes]
            d["error_mm"] = np.round(self.error, 9).tolist()
        return d


def volumetric_map(model, envelope=None, shape=(11, 11, 11)):
    """Predicted volumetric error over the work envelope (Dobariya 2015, sec. 4.1).

    Parameters
    ----------
    model : surfcomp.core.axis.axis_errors.AxisErrorModel
    envelope : array_like (3, 2), optional
        ``[[xmin, xmax], [ymin, ymax], [zmin, zmax]]`` (mm); default the measured travel,
        and the reference for unmeasured slides.
    shape : tuple of 3 int
        Grid points per axis (a slide with an empty range gets one).

    Returns
    -------
    VolumetricMap
        With ``stats``: ``max_mm``, ``mean_mm``, ``rms_mm`` of ``|E|``, ``max_at_mm`` (the
        grid point of the largest error) and ``max_component_mm`` (largest ``|E_i|``).
    """
    if envelope is None:
        env = model.travel.copy()
        missing = ~np.isfinite(env).all(axis=1)
        env[missing] = model.reference[missing, None]
    else:
        env = np.array(envelope, dtype=float).reshape(3, 2)
    axes = tuple(np.linspace(env[k, 0], env[k, 1], 1 if env[k, 0] == env[k, 1] else int(n))
                 for k, n in enumerate(shape))
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    err = model.error(grid)
    mag = np.linalg.norm(err, axis=-1)
    k = np.unravel_index(np.argmax(mag), mag.shape)
    st = {"max_mm": float(mag.max()), "mean_mm": float(mag.mean()),
          "rms_mm": float(np.sqrt(np.mean(mag ** 2))), "max_at_mm": grid[k].tolist(),
          "max_component_mm": np.abs(err).reshape(-1, 3).max(axis=0).tolist()}
    return VolumetricMap(axes, err, mag, st)


def error_stats(vectors):
    """``max``, ``mean``, ``rms`` of ``|v|`` and largest ``|v_i|`` per axis (mm)."""
    v = np.asarray(vectors, dtype=float).reshape(-1, 3)
    if v.shape[0] == 0:
        return {"n": 0, "max_mm": 0.0, "mean_mm": 0.0, "rms_mm": 0.0,
                "max_component_mm": [0.0, 0.0, 0.0]}
    m = np.linalg.norm(v, axis=1)
    return {"n": int(v.shape[0]), "max_mm": float(m.max()), "mean_mm": float(m.mean()),
            "rms_mm": float(np.sqrt(np.mean(m ** 2))),
            "max_component_mm": np.abs(v).max(axis=0).tolist()}


def validate(model, machine, points, progress=None):
    """Positional error of programmed points before and after compensation.

    Parameters
    ----------
    model : surfcomp.core.axis.axis_errors.AxisErrorModel
        The model used to compensate (e.g. fitted from ``machine.measure``).
    machine : SimulatedMachine
        The machine with the true errors.
    points : array_like (n, 3)
        Programmed points (mm).

    Returns
    -------
    dict
        ``before`` (tool error commanding ``X``) and ``after`` (commanding the compensated
        ``X'``): :func:`error_stats` of ``actual - X``; ``reduction`` = 1 - after RMS /
        before RMS.
    """
    p = as_points(points).reshape(-1, 3)
    report(progress, 0.0, "compensating %d points" % p.shape[0])
    before = machine.actual(p) - p
    after = machine.actual(model.compensate(p)) - p
    report(progress, 1.0, "done")
    b, a = error_stats(before), error_stats(after)
    red = 1.0 - a["rms_mm"] / b["rms_mm"] if b["rms_mm"] > 0 else 0.0
    return {"before": b, "after": a, "reduction": red}
