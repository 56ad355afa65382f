# SPDX-License-Identifier: LGPL-2.1-or-later
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
from scipy.sparse import csr_matrix

from ...errors import ComputationError
from ..chunks import for_chunks, threads
from ..surface.kdtree import cKDTree

_L = 0.5  # damping length of the outside continuation, in grid steps


#: cubic Hermite basis h0..h3 (values at 0/1, slopes at 0/1) in powers 1, a, a^2, a^3
_HERMITE = np.array([[1.0, 0.0, -3.0, 2.0],
                     [0.0, 0.0, 3.0, -2.0],
                     [0.0, 1.0, -2.0, 1.0],
                     [0.0, 0.0, -1.0, 1.0]])


#: points per block of :meth:`GridField.locate_grid`'s Newton iteration
_BLOCK = 1 << 18

#: C[i, j] = sum_kl H[k, i] M[k, l] H[l, j] on flattened (k, l) and (i, j)
_HERMITE_2D = np.kron(_HERMITE, _HERMITE)

#: the seeds and k-d tree of the last map with at most :data:`_SEEDS_KEPT` seeds, by its
#: nodes' (u, v): the grid check (:mod:`surfcomp.core.compensation.grid_check`) and the corrected
# face's
#: construction locate on the same map, and a small grid's seeds cost more than the rest of
#: its locating (docs/benchmarks.md, "Costs behind choices in the code"). Large maps are
#: not kept (memory).
_LAST_SEEDS = []
_SEEDS_KEPT = 100_000


def _powers(a):
    return np.stack([np.ones_like(a), a, a * a, a * a * a], axis=1)


def _dpowers(a):
    return np.stack([np.zeros_like(a), np.ones_like(a), 2.0 * a, 3.0 * a * a], axis=1)


def _solve2(ds, dt, r):
    """Solve ``[ds dt] x = r`` for each point (2 x 2 Jacobian columns ds, dt; (N, 2) each)."""
    det = ds[:, 0] * dt[:, 1] - ds[:, 1] * dt[:, 0]
    det = np.where(np.abs(det) < 1e-300, 1e-300, det)
    return ((r[:, 0] * dt[:, 1] - r[:, 1] * dt[:, 0]) / det,
            (ds[:, 0] * r[:, 1] - ds[:, 1] * r[:, 0]) / det)


def _pchip_slopes(F, axis):
    """PCHIP node slopes along ``axis`` of values at unit spacing (Fritsch & Carlson;
    the slopes of ``scipy.interpolate.PchipInterpolator``, without building its spline):
    inside, the harmonic mean of the neighbouring secants, zero where they differ in
    sign or one is zero; at the ends the one-sided three-point slope, zero when its
    sign differs from the first secant's and at most 3 times that secant when the first
    two secants differ in sign."""
    F = np.moveaxis(F, axis, 0)
    m = np.diff(F, axis=0)
    if F.shape[0] == 2:
        return np.moveaxis(np.concatenate([m, m], axis=0), 0, axis)
    d = np.empty_like(F)
    with np.errstate(divide="ignore", invalid="ignore"):
        mean = 2.0 / (1.0 / m[:-1] + 1.0 / m[1:])
    flat = (np.sign(m[:-1]) != np.sign(m[1:])) | (m[:-1] == 0) | (m[1:] == 0)
    d[1:-1] = np.where(flat, 0.0, mean)
    for end, m0, m1 in ((0, m[0], m[1]), (-1, m[-1], m[-2])):
        e = (3.0 * m0 - m1) / 2.0
        e = np.where(np.sign(e) != np.sign(m0), 0.0,
                     np.where((np.sign(m0) != np.sign(m1)) & (np.abs(e) > 3.0 * np.abs(m0)),
                              3.0 * m0, e))
        d[end] = e
    return np.moveaxis(d, 0, axis)


def _position_ends(F, d, axis):
    """End slopes ``d`` of the (u, v) channels (0 and 1) made the end secant where PCHIP
    gives zero: rows of uneven spacing (a staggered, near-grid layout: secants 0.1, 0.4,
    0.1, ...) make the three-point end slope change sign, and a zero slope of both
    channels leaves the map's linear continuation beyond that border flat, so no point
    beyond it can be located. The secant keeps the ends monotone (at most 3 times it)."""
    F, d = np.moveaxis(F, axis, 0), np.moveaxis(d, axis, 0)
    for end, m0 in ((0, F[1, ..., :2] - F[0, ..., :2]), (-1, F[-1, ..., :2] - F[-2, ..., :2])):
        d[end, ..., :2] = np.where(d[end, ..., :2] == 0.0, m0, d[end, ..., :2])
    return np.moveaxis(d, 0, axis)


class GridField:
    """C1 interpolant of values given on an n x m measurement grid, evaluated at (u, v).

    Parameters
    ----------
    U, V : array_like, shape (n, m)
        Face parameters of the grid nodes (orientation-preserving grid, see
        :mod:`surfcomp.core.surface.grid`).
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
        self._lo = vals.reshape(-1, vals.shape[2]).min(axis=0)
        self._hi = vals.reshape(-1, vals.shape[2]).max(axis=0)
        self._scale = np.array([np.ptp(U) or 1.0, np.ptp(V) or 1.0])

    def _slopes(self):
        """PCHIP node slopes (d/ds, d/dt) of every channel, made on first use."""
        got = self.__dict__.get("_slope_cache")
        if got is None:
            got = self._slope_cache = tuple(_position_ends(self._F, _pchip_slopes(self._F, a), a)
                                            for a in (0, 1))
        return got

    def _kd(self):
        """Seeds in index space and the KD-tree of their (u, v), made on first use."""
        got = self.__dict__.get("_kd_cache")
        if got is None and _LAST_SEEDS:
            nodes, kept = _LAST_SEEDS[0]
            if nodes.shape == self._F.shape[:2] + (2,) and np.array_equal(nodes,
                                                                         self._F[..., :2]):
                got = self._kd_cache = kept
        if got is None:
            n, m = self.shape
            k = max(1, min(4, int(np.sqrt(1e6 / (n * m)))))  # seeds per cell side (<= ~1M)
            ss, tt = np.meshgrid(np.linspace(0, n - 1, k * (n - 1) + 1),
                                 np.linspace(0, m - 1, k * (m - 1) + 1), indexing="ij")
            seed_st = np.stack([ss.ravel(), tt.ravel()], axis=1)
            # one seed per node on dense grids: the map passes through the nodes
            uv = self._F[..., :2].reshape(-1, 2) if k == 1 else \
                self._eval(seed_st[:, 0], seed_st[:, 1], channels=slice(0, 2))[0]
            # (a sliding-midpoint tree: built and queried faster than a balanced one here)
            got = self._kd_cache = (seed_st, cKDTree(uv / self._scale, balanced_tree=False))
            _LAST_SEEDS[:] = [(self._F[..., :2].copy(), got)] \
                if seed_st.shape[0] <= _SEEDS_KEPT else []
        return got

    def _seed(self, uv):
        """Index coordinates of the seed nearest each (u, v) (copies)."""
        seed_st, tree = self._kd()
        _, k = tree.query(uv / self._scale, workers=threads())
        return seed_st[k, 0].copy(), seed_st[k, 1].copy()

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
        other._coeffs = {k: v for k, v in self.__dict__.get("_coeffs", {}).items() if k == (0, 2)}
        other.__dict__.pop("_slope_cache", None)
        other._lo = vals.reshape(-1, vals.shape[2]).min(axis=0)
        other._hi = vals.reshape(-1, vals.shape[2]).max(axis=0)
        return other

    def drop_caches(self):
        """Free what is made again when next needed: the per-cell patch coefficients (16
        numbers per cell and channel: 380 MB for a 1000 x 1000 grid), the node slopes and
        the seeds' KD-tree."""
        for name in ("_coeffs", "_slope_cache", "_kd_cache"):
            self.__dict__.pop(name, None)

    # -- Hermite patches in index space -------------------------------------------------
    def _coefficients(self, channels):
        """Per-cell power-basis coefficients ((n-1)(m-1), c, 16) of the bicubic Hermite
        patches of a channel group (``sum_ij C[ij] a^i b^j``), built once per group."""
        key = (channels.start, channels.stop)
        cache = self.__dict__.setdefault("_coeffs", {})
        if key not in cache:
            n, m = self.shape
            Fs, Ft = (x[..., channels] for x in self._slopes())
            F = self._F[..., channels]
            c = F.shape[2]
            M = np.zeros((n - 1, m - 1, c, 4, 4))  # M[..., k, l] multiplies h_k(a) h_l(b)
            for p in (0, 1):
                for q in (0, 1):
                    M[..., p, q] = F[p:n - 1 + p, q:m - 1 + q]
                    M[..., 2 + p, q] = Fs[p:n - 1 + p, q:m - 1 + q]
                    M[..., p, 2 + q] = Ft[p:n - 1 + p, q:m - 1 + q]
            # power coefficients H^T M H of every patch as one product with kron(H, H)
            cache[key] = (M.reshape(-1, 16) @ _HERMITE_2D).reshape((n - 1) * (m - 1), c, 16)
        return cache[key]

    def _eval(self, s, t, channels=slice(None), deriv=False, block=32768, cross=False):
        """Values (and d/ds, d/dt; with ``cross`` also d2/dsdt as a fourth array) at index
        coordinates inside [0, n-1] x [0, m-1] (in blocks that stay in cache: several
        times faster on millions of points)."""
        C = self._coefficients(channels)
        n, m = self.shape
        N, c = s.size, C.shape[1]
        val = np.empty((N, c))
        ds = np.empty((N, c)) if deriv else 0.0
        dt = np.empty((N, c)) if deriv else 0.0
        dst = np.empty((N, c)) if cross else None

        def job(sl):
            i = np.clip(np.floor(s[sl]).astype(np.int64), 0, n - 2)
            j = np.clip(np.floor(t[sl]).astype(np.int64), 0, m - 2)
            a, b = s[sl] - i, t[sl] - j
            G = C[i * (m - 1) + j]
            A, B = _powers(a), _powers(b)
            val[sl] = np.einsum("nk,nck->nc", (A[:, :, None] * B[:, None, :]).reshape(-1, 16), G)
            if deriv:
                dA, dB = _dpowers(a), _dpowers(b)
                ds[sl] = np.einsum("nk,nck->nc",
                                   (dA[:, :, None] * B[:, None, :]).reshape(-1, 16), G)
                dt[sl] = np.einsum("nk,nck->nc",
                                   (A[:, :, None] * dB[:, None, :]).reshape(-1, 16), G)
                if cross:
                    dst[sl] = np.einsum("nk,nck->nc",
                                        (dA[:, :, None] * dB[:, None, :]).reshape(-1, 16), G)

        for_chunks(job, N, block)
        return (val, ds, dt, dst) if cross else (val, ds, dt)

    def _clamped(self, s, t):
        n, m = self.shape
        return np.clip(s, 0.0, n - 1.0), np.clip(t, 0.0, m - 1.0)

    def _map(self, s, t, deriv=True):
        """(u, v) and the Jacobian at any (s, t); linear continuation outside the grid.
        Without ``deriv`` only the (u, v) (the Jacobian is None)."""
        sc, tc = self._clamped(s, t)
        if deriv:
            val, ds, dt, dst = self._eval(sc, tc, slice(0, 2), deriv=True, cross=True)
            es, et = (s - sc)[:, None], (t - tc)[:, None]
            # beyond one border only, the base point slides along it: its slope's change
            # along the border times the distance out belongs to the Jacobian (without it
            # Newton crawls on points many cells out: 30 steps on a turned grid)
            return (val + ds * es + dt * et, ds + dst * np.where(es == 0, et, 0.0),
                    dt + dst * np.where(et == 0, es, 0.0))
        val = self._eval(sc, tc, slice(0, 2))[0]
        out = np.nonzero((s != sc) | (t != tc))[0]
        if out.size:    # the linear continuation (no cross derivative needed)
            _, ds, dt = self._eval(sc[out], tc[out], slice(0, 2), deriv=True)
            val[out] += ds * (s - sc)[out, None] + dt * (t - tc)[out, None]
        return val, None, None

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
        s, t = self._seed(uv)
        # points nearest a border sample may lie many cells beyond it, where Newton's
        # limited steps would need ~log2(distance) more iterations: they start one linear
        # step out (along the border at most one cell)
        n, m = self.shape
        out = np.flatnonzero((s == 0) | (s == n - 1) | (t == 0) | (t == m - 1))
        if out.size:
            s[out], t[out] = self._step_out(uv[out], s[out], t[out], along=1.0)
        return self._newton(uv, s, t, iterations, tol)

    def locate_grid(self, us, vs, stride=4):
        """:meth:`locate` for the tensor grid ``us x vs`` (``meshgrid(..., indexing="ij")``
        order, raveled): a grid whose node u depends on the row only and v on the column
        only is inverted along one line each way; otherwise every ``stride``-th point is
        located and the rest start Newton from the interpolated coarse solution.

        Returns
        -------
        s, t : ndarray, shape (len(us) * len(vs),)
        """
        us = np.ravel(us).astype(float)
        vs = np.ravel(vs).astype(float)
        U, V = self._F[..., 0], self._F[..., 1]
        if (np.max(np.ptp(U, axis=1)) <= 1e-12 * self._scale[0]
                and np.max(np.ptp(V, axis=0)) <= 1e-12 * self._scale[1]):
            # u(s, t) = u(s) and v(s, t) = v(t) exactly (Hermite weights sum to one)
            s_line = self.locate(us, np.full(us.size, V[0, 0]))[0]
            t_line = self.locate(np.full(vs.size, U[0, 0]), vs)[1]
            ss, tt = np.meshgrid(s_line, t_line, indexing="ij")
            return ss.ravel(), tt.ravel()
        iu = np.unique(np.r_[np.arange(0, us.size, stride), us.size - 1])
        iv = np.unique(np.r_[np.arange(0, vs.size, stride), vs.size - 1])
        cu, cv = np.meshgrid(us[iu], vs[iv], indexing="ij")
        cs, ct = (a.reshape(cu.shape) for a in self.locate(cu.ravel(), cv.ravel()))
        seeds = []
        for c in (cs, ct):
            along_v = np.stack([np.interp(np.arange(vs.size), iv, row) for row in c])
            seeds.append(np.stack([np.interp(np.arange(us.size), iu, col)
                                   for col in along_v.T], axis=1).ravel())
        uu, vv = np.meshgrid(us, vs, indexing="ij")
        uv = np.stack([uu.ravel(), vv.ravel()], axis=1)
        # a miss of 1e-7 grid cells moves a field value by less than 1e-7 of the value
        # step between neighbouring nodes (1e-5 um for 100 um steps)
        cells = max(self.shape) - 1
        # in blocks: the iteration's temporaries stay ~100 MB (960 MB at once for 1599^2)
        for k in range(0, uv.shape[0], _BLOCK):
            sl = slice(k, k + _BLOCK)
            seeds[0][sl], seeds[1][sl] = self._newton(uv[sl], seeds[0][sl], seeds[1][sl],
                                                      tol=1e-7 / cells)
        return seeds[0], seeds[1]

    def _newton(self, uv, s, t, iterations=30, tol=1e-13):
        """Solve map(s, t) = uv from the given starting points (Newton, steps limited to
        one grid cell; only the points not yet converged are iterated)."""
        act = np.arange(uv.shape[0])
        for _ in range(iterations):
            # residuals first (values only), the Jacobian only where a step is needed
            r = uv[act] - self._map(s[act], t[act], deriv=False)[0]
            keep = ~np.all(np.abs(r) <= tol * self._scale, axis=1)
            act, r = act[keep], r[keep]
            if act.size == 0:
                break
            _, ds, dt = self._map(s[act], t[act])
            dS, dT = _solve2(ds, dt, r)
            # steps are limited to one cell inside the grid; beyond its border, where the
            # map is continued linearly, to one cell more than the distance to the border
            sa, ta = s[act], t[act]
            sc, tc = self._clamped(sa, ta)
            room = 1.0 + np.maximum(np.abs(sa - sc), np.abs(ta - tc))
            step = np.maximum(np.abs(dS), np.abs(dT))
            lim = np.where(step > room, room / np.maximum(step, 1e-300), 1.0)
            s[act] += lim * dS
            t[act] += lim * dT
        if act.size:
            val, _, _ = self._map(s[act], t[act])
            miss = np.abs(uv[act] - val)
            failed = act[np.any(miss > 1e-9 * self._scale, axis=1)]
            if failed.size:
                s[failed], t[failed] = self._beyond(uv[failed])
        return s, t

    def _beyond(self, uv):
        """Index coordinates of points where Newton failed: allowed only beyond the grid
        (a distorted border can make its linear continuation fold there); each point is
        placed by one linear step from the nearest border sample, so the bounded outside
        continuation applies. Points that have a sample inside the grid nearest raise."""
        n, m = self.shape
        s0, t0 = self._seed(uv)
        border = (s0 == 0) | (s0 == n - 1) | (t0 == 0) | (t0 == m - 1)
        if not np.all(border):
            bad = int(np.argmin(border))
            raise ComputationError("could not locate (u, v) = (%g, %g) on the measurement grid"
                                   % tuple(uv[bad]))
        return self._step_out(uv, s0, t0)

    def _step_out(self, uv, s0, t0, along=0.0):
        """One linear step from border samples (s0, t0) towards ``uv``: outward only (the
        point stays beyond the border it is nearest to), along a border at most ``along``
        cells."""
        n, m = self.shape
        val, ds, dt = self._map(s0, t0)
        dS, dT = _solve2(ds, dt, uv - val)

        def part(d, x, last):
            return np.where(x == 0, np.minimum(d, 0), np.where(x == last, np.maximum(d, 0),
                                                               np.clip(d, -along, along)))
        return s0 + part(dS, s0, n - 1), t0 + part(dT, t0, m - 1)

    def at_index(self, s, t):
        """Field values at index coordinates (continued outside, clipped to the node range)."""
        s = np.ravel(s).astype(float)
        t = np.ravel(t).astype(float)
        sc, tc = self._clamped(s, t)
        val = self._eval(sc, tc, slice(2, None))[0]
        out = np.nonzero((s != sc) | (t != tc))[0]  # continued beyond the border
        if out.size:
            _, ds, dt = self._eval(sc[out], tc[out], slice(2, None), deriv=True)
            es, et = (s - sc)[out, None], (t - tc)[out, None]
            b = val[out]
            # each direction's excursion g L tanh(e / L) is kept inside the node range by
            # shortening L where the border value is near a bound (still C1 at the border:
            # its slope there stays g); a hard clip alone would leave a kink that the
            # spline space rings around
            share = np.where((es != 0) & (et != 0), 0.5, 1.0)

            def excursion(g, e):
                head = np.where(g * e > 0, self._hi - b, b - self._lo) * share
                L = np.clip(head / np.maximum(np.abs(g), 1e-300), 1e-12, _L)
                return g * L * np.tanh(e / L)

            val[out] = b + excursion(ds, es) + excursion(dt, et)
        val = np.clip(val, self._lo, self._hi)
        return val[:, 0] if self._scalar else val

    def linear_at(self, s, t):
        """The bilinear interpolant in index space at (s, t) as a sparse (N, n * m) matrix
        (clamped to the grid outside it): a linear stand-in for :meth:`with_values` in
        the residual iteration, which only moves the node values by the small misses
        left (``base + linear_at(s, t) @ change`` instead of a new Hermite field)."""
        n, m = self.shape
        s, t = self._clamped(np.ravel(s).astype(float), np.ravel(t).astype(float))
        i = np.minimum(np.floor(s).astype(np.int64), n - 2)
        j = np.minimum(np.floor(t).astype(np.int64), m - 2)
        a, b = s - i, t - j
        cols = np.stack([i * m + j, i * m + j + 1, (i + 1) * m + j, (i + 1) * m + j + 1], 1)
        w = np.stack([(1 - a) * (1 - b), (1 - a) * b, a * (1 - b), a * b], 1)
        # four distinct columns per row, in order: the CSR arrays directly (no COO sort)
        return csr_matrix((w.ravel(), cols.ravel(), np.arange(0, 4 * s.size + 1, 4)),
                          shape=(s.size, n * m))

    def __call__(self, u, v):
        """Field values at face parameters (u, v) (arrays of equal shape)."""
        shape = np.shape(u)
        s, t = self.locate(u, v)
        out = self.at_index(s, t)
        return out.reshape(shape) if self._scalar else out.reshape(shape + (out.shape[-1],))
