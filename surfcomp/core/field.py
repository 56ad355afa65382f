"""Smooth correction fields over the face's (u, v), built on the measurement grid (no FreeCAD).

The measured nodes form an n x m grid in index space (s, t) = (i, j), each node
with its (u, v) on the face and one or more values (the intended correction).
Both the node positions and the values are interpolated over index space by a
bicubic Hermite interpolant whose node slopes are PCHIP slopes (Fritsch-Carlson,
``scipy.interpolate.PchipInterpolator``) along each grid direction and whose
cross-derivatives are zero. This gives a C1 field that

* passes exactly through every node value (the intended corrections),
* does not overshoot along grid lines (PCHIP is shape preserving), and is
  clipped to the range of the node values, so noisy ('raw') data can never
  produce a correction larger than the largest intended one,
* reproduces constant and, on uniform data, linear fields exactly.

A point (u, v) is located in index space by Newton's method on the (s, t) ->
(u, v) map, seeded from a KD-tree of map samples.

Outside the measured region (beyond the border rows and columns of the grid,
e.g. the strip the probe could not reach) the map is continued linearly and the
field is continued from its border value with its border slope damped as
``g L tanh(e / L)`` (``e`` the distance beyond the border in grid steps,
``L = 0.5``): C1 across the border, bounded by half a grid step of slope beyond
the border value, and clipped to the node value range like the inside.
"""

import numpy as np
from scipy.interpolate import PchipInterpolator
from scipy.spatial import cKDTree

from ..errors import ComputationError

_L = 0.5  # damping length of the outside continuation, in grid steps


def _h(a):
    a2, a3 = a * a, a * a * a
    return (2 * a3 - 3 * a2 + 1, -2 * a3 + 3 * a2, a3 - 2 * a2 + a, a3 - a2)


def _dh(a):
    a2 = a * a
    return (6 * a2 - 6 * a, -6 * a2 + 6 * a, 3 * a2 - 4 * a + 1, 3 * a2 - 2 * a)


def _pchip_slopes(F, axis):
    n = F.shape[axis]
    x = np.arange(n, dtype=float)
    if n == 2:
        d = np.diff(F, axis=axis)
        return np.concatenate([d, d], axis=axis)
    return PchipInterpolator(x, F, axis=axis).derivative()(x)


class GridField:
    """C1 interpolant of values given on an n x m measurement grid, evaluated at (u, v).

    Parameters
    ----------
    U, V : array_like, shape (n, m)
        Face parameters of the grid nodes (orientation-preserving grid, see
        :mod:`surfcomp.core.grid`).
    values : array_like, shape (n, m) or (n, m, k)
        Values at the nodes (mm); must be finite.
    """

    def __init__(self, U, V, values):
        U = np.asarray(U, dtype=float)
        V = np.asarray(V, dtype=float)
        vals = np.asarray(values, dtype=float)
        self._scalar = vals.ndim == 2
        if self._scalar:
            vals = vals[..., None]
        if U.shape != V.shape or vals.shape[:2] != U.shape or U.ndim != 2:
            raise ValueError("U, V and values must share the grid shape (n, m)")
        if min(U.shape) < 2:
            raise ValueError("a field needs at least a 2 x 2 grid")
        if not np.all(np.isfinite(vals)):
            raise ValueError("field values must be finite at every node")
        self.shape = U.shape
        # channels: u, v, then the values
        F = np.concatenate([U[..., None], V[..., None], vals], axis=2)
        self._F = F
        self._Fs = _pchip_slopes(F, 0)
        self._Ft = _pchip_slopes(F, 1)
        self._lo = vals.reshape(-1, vals.shape[2]).min(axis=0)
        self._hi = vals.reshape(-1, vals.shape[2]).max(axis=0)
        n, m = self.shape
        k = max(1, min(4, int(4e6 // (n * m))))  # samples per cell for the seeds
        ss, tt = np.meshgrid(np.linspace(0, n - 1, k * (n - 1) + 1),
                             np.linspace(0, m - 1, k * (m - 1) + 1), indexing="ij")
        self._seed_st = np.stack([ss.ravel(), tt.ravel()], axis=1)
        uv = self._eval(self._seed_st[:, 0], self._seed_st[:, 1], channels=slice(0, 2))[0]
        self._scale = np.array([np.ptp(U) or 1.0, np.ptp(V) or 1.0])
        self._tree = cKDTree(uv / self._scale)

    def with_values(self, values):
        """A field with the same grid positions and new node values (reuses the
        located map and its KD-tree)."""
        vals = np.asarray(values, dtype=float)
        other = object.__new__(GridField)
        other.__dict__.update(self.__dict__)
        other._scalar = vals.ndim == 2
        if other._scalar:
            vals = vals[..., None]
        F = np.concatenate([self._F[..., :2], vals], axis=2)
        other._F = F
        other._Fs = _pchip_slopes(F, 0)
        other._Ft = _pchip_slopes(F, 1)
        other._lo = vals.reshape(-1, vals.shape[2]).min(axis=0)
        other._hi = vals.reshape(-1, vals.shape[2]).max(axis=0)
        return other

    # -- Hermite patches in index space -------------------------------------------------
    def _eval(self, s, t, channels=slice(None), deriv=False):
        """Values (and d/ds, d/dt) at index coordinates inside [0, n-1] x [0, m-1]."""
        n, m = self.shape
        i = np.clip(np.floor(s).astype(np.int64), 0, n - 2)
        j = np.clip(np.floor(t).astype(np.int64), 0, m - 2)
        a = (s - i)[:, None]
        b = (t - j)[:, None]
        F, Fs, Ft = self._F[..., channels], self._Fs[..., channels], self._Ft[..., channels]
        ha, hb = _h(a), _h(b)
        val = 0.0
        ds = dt = 0.0
        if deriv:
            dha, dhb = _dh(a), _dh(b)
        for p in (0, 1):
            for q in (0, 1):
                f, fs, ft = F[i + p, j + q], Fs[i + p, j + q], Ft[i + p, j + q]
                val = val + f * ha[p] * hb[q] + fs * ha[2 + p] * hb[q] + ft * ha[p] * hb[2 + q]
                if deriv:
                    ds = ds + f * dha[p] * hb[q] + fs * dha[2 + p] * hb[q] + ft * dha[p] * hb[2 + q]
                    dt = dt + f * ha[p] * dhb[q] + fs * ha[2 + p] * dhb[q] + ft * ha[p] * dhb[2 + q]
        return val, ds, dt

    def _clamped(self, s, t):
        n, m = self.shape
        return np.clip(s, 0.0, n - 1.0), np.clip(t, 0.0, m - 1.0)

    def _map(self, s, t):
        """(u, v) and the Jacobian at any (s, t); linear continuation outside the grid."""
        sc, tc = self._clamped(s, t)
        val, ds, dt = self._eval(sc, tc, slice(0, 2), deriv=True)
        es, et = (s - sc)[:, None], (t - tc)[:, None]
        return val + ds * es + dt * et, ds, dt

    # -- public ---------------------------------------------------------------------------
    def locate(self, u, v, iterations=30, tol=1e-13):
        """Index coordinates (s, t) of face parameters (u, v).

        Parameters
        ----------
        u, v : array_like, shape (N,)

        Returns
        -------
        s, t : ndarray, shape (N,)
            May lie outside [0, n-1] x [0, m-1] for points outside the measured region.
        """
        uv = np.stack([np.ravel(u), np.ravel(v)], axis=1).astype(float)
        _, k = self._tree.query(uv / self._scale)
        s, t = self._seed_st[k, 0].copy(), self._seed_st[k, 1].copy()
        for _ in range(iterations):
            val, ds, dt = self._map(s, t)
            r = uv - val
            det = ds[:, 0] * dt[:, 1] - ds[:, 1] * dt[:, 0]
            det = np.where(np.abs(det) < 1e-300, 1e-300, det)
            dS = (r[:, 0] * dt[:, 1] - r[:, 1] * dt[:, 0]) / det
            dT = (ds[:, 0] * r[:, 1] - ds[:, 1] * r[:, 0]) / det
            step = np.maximum(np.abs(dS), np.abs(dT))
            lim = np.where(step > 1.0, 1.0 / np.maximum(step, 1e-300), 1.0)
            s, t = s + lim * dS, t + lim * dT
            if np.all(np.abs(r) <= tol * self._scale):
                break
        val, _, _ = self._map(s, t)
        if np.any(np.abs(uv - val) > 1e-9 * self._scale):
            bad = int(np.argmax(np.abs(uv - val).max(axis=1)))
            raise ComputationError("could not locate (u, v) = (%g, %g) on the measurement grid"
                                   % tuple(uv[bad]))
        return s, t

    def at_index(self, s, t):
        """Field values at index coordinates (continued outside, clipped to the node range)."""
        s = np.ravel(s).astype(float)
        t = np.ravel(t).astype(float)
        sc, tc = self._clamped(s, t)
        val, ds, dt = self._eval(sc, tc, slice(2, None), deriv=True)
        es, et = (s - sc)[:, None], (t - tc)[:, None]
        val = val + ds * _L * np.tanh(es / _L) + dt * _L * np.tanh(et / _L)
        val = np.clip(val, self._lo, self._hi)
        return val[:, 0] if self._scalar else val

    def __call__(self, u, v):
        """Field values at face parameters (u, v) (arrays of equal shape)."""
        shape = np.shape(u)
        s, t = self.locate(u, v)
        out = self.at_index(s, t)
        return out.reshape(shape) if self._scalar else out.reshape(shape + (out.shape[-1],))
