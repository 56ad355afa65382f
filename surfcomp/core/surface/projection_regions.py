# SPDX-License-Identifier: LGPL-2.1-or-later
"""Per-region certificate that a projected foot point is the global one (no FreeCAD).

A foot point ``F`` found by Newton's method is a local minimum of ``|S - P|``; with
``P = F + d n`` every better surface point ``X`` (``|X - P| < |d|``) lies in the ball
``B(F, 2 |d|)``. The face's sample grid is cut into tiles of a few cells; once per
face and per radius :class:`Regions` records for every tile

* its **clearance**: a lower bound of the distance to the tiles that come close in
  space but are far along the face (their parameter offset, measured in the tiles'
  first fundamental form, is more than 3 times the distance between them plus the
  tiles' sizes: another part of the face, e.g. the other leg of a hairpin), and
* for a few radii ``R / 2^m``, the largest principal curvature bending towards
  either side of the face (signed with ``n = Su x Sv``) on the tiles within that
  distance along the same sheet.

A foot with ``2 |d|`` below the clearance and ``|d| kappa < 1/2`` for the curvature
towards ``P`` on its side at the smallest radius covering ``2 |d|`` is the global
minimum: inside the ball the face is one sheet that bends towards ``P`` with a radius
of at least ``2 |d|``, so it stays outside the sphere of radius ``|d|`` around ``P``
(the ball tangent at ``F``; the same bound as half the smallest radius of curvature
of the whole face, the projector's global test, but taken locally). Curvature is
sampled at the grid samples, as for the global test. Feet on the border of the work
area are never certified here. Points that are not certified get the projector's
point-by-point search for other minima.
"""

import numpy as np

from .kdtree import cKDTree
from .projection_newton import dot

#: radii R, R/2, ... R/2^(LEVELS-1) at which the tile curvature is recorded
LEVELS = 5
#: tiles are about this fraction of the largest radius R across
TILE_FRACTION = 1.0
#: at most this many tiles (coarser tiles on very finely sampled faces)
MAX_TILES = 40_000


def principal_curvatures(D):
    """Signed principal curvatures (k1 >= k2, 1/mm, positive bending towards
    ``Su x Sv``) at SoA derivative samples ``D = (S, Su, Sv, Suu, Suv, Svv)``; NaN
    where the normal is undefined."""
    S, Su, Sv, Suu, Suv, Svv = D
    n = np.cross(Su.T, Sv.T).T
    with np.errstate(divide="ignore", invalid="ignore"):
        n = n / np.sqrt(dot(n, n))
        E, F, G = dot(Su, Su), dot(Su, Sv), dot(Sv, Sv)
        L, M, N = dot(n, Suu), dot(n, Suv), dot(n, Svv)
        den = E * G - F * F
        K = (L * N - M * M) / den
        H = (E * N - 2.0 * F * M + G * L) / (2.0 * den)
        root = np.sqrt(np.maximum(H * H - K, 0.0))
    return H + root, H - root


def _block_reduce(A, b, ufunc):
    """``ufunc`` over the blocks of rows ``[k b0, k b0 + b0]`` and columns
    ``[k b1, k b1 + b1]`` (inclusive: tiles share their border samples) of a 2-D (or
    3-D, reduced over the first two axes) array; the last block ends at the last
    sample."""
    for axis in (0, 1):
        n, b_ = A.shape[axis], b[axis]
        starts = np.arange(0, n - 1, b_)
        ends = np.minimum(starts + b_, n - 1)
        head = A[:n - 1] if axis == 0 else A[:, :n - 1]
        A = ufunc(ufunc.reduceat(head, starts, axis=axis), np.take(A, ends, axis=axis))
    return A


class _Groups:
    """Pairs grouped by their target tile (sorted once), for many maxima over subsets."""

    def __init__(self, target):
        self.order = np.argsort(target, kind="stable")
        t = target[self.order]
        self.starts = np.flatnonzero(np.r_[True, t[1:] != t[:-1]]) if t.size else t
        self.first = t[self.starts] if t.size else t

    def max(self, values, initial, mask=None):
        """``out[t] = max(initial[t], values[target == t & mask])``."""
        out = initial.copy()
        if self.first.size:
            v = values[self.order]
            if mask is not None:
                v = np.where(mask[self.order], v, -np.inf)
            out[self.first] = np.maximum(out[self.first], np.maximum.reduceat(v, self.starts))
        return out


class Regions:
    """Tile tables of one face for feet up to ``reach / 2`` from it (see the module
    docstring).

    Parameters
    ----------
    us, vs : ndarray, shape (nu,), (nv,)
        Sample parameters of the projector's grid.
    samples : list of 6 ndarray, shape (3, nu * nv)
        S, Su, Sv, Suu, Suv, Svv at the samples (grid order ``i * nv + j``).
    curvatures : (ndarray, ndarray), shape (nu * nv,) each
        :func:`principal_curvatures` of the samples.
    regular : ndarray of bool, shape (nu * nv,)
        Samples with a defined normal (the others block certification nearby).
    eps : float
        Covering radius of the samples (mm): every point of a grid cell is within
        ``eps`` of one of its corners.
    reach : float
        The largest radius R (mm): feet up to ``R / 2`` from the face can be
        certified.
    """

    def __init__(self, us, vs, samples, curvatures, regular, eps, reach):
        nu, nv = us.size, vs.size
        self.us, self.vs, self.reach = us, vs, float(reach)
        grid = samples[0].T.reshape(nu, nv, 3)
        # tiles of bu x bv cells, about TILE_FRACTION * reach across in both directions
        steps = []
        for axis in (0, 1):
            e = np.linalg.norm(np.diff(grid, axis=axis), axis=2)
            steps.append(float(np.median(e[e > 0])) if np.any(e > 0) else self.reach)
        target = TILE_FRACTION * self.reach
        bu, bv = (max(1, int(round(target / h))) for h in steps)
        grow = np.sqrt((nu - 1) * (nv - 1) / (bu * bv * MAX_TILES))
        if grow > 1:
            bu, bv = int(np.ceil(bu * grow)), int(np.ceil(bv * grow))
        self.b = b = (bu, bv)
        k1, k2 = curvatures
        bad = ~regular | ~np.isfinite(k1) | ~np.isfinite(k2)
        kplus = np.where(bad, np.inf, np.maximum(k1, 0.0)).reshape(nu, nv)
        kminus = np.where(bad, np.inf, np.maximum(-k2, 0.0)).reshape(nu, nv)
        lo = _block_reduce(grid, b, np.minimum)
        hi = _block_reduce(grid, b, np.maximum)
        self.shape = lo.shape[:2]
        centre = (0.5 * (lo + hi)).reshape(-1, 3)
        kp = _block_reduce(kplus, b, np.maximum).ravel()
        km = _block_reduce(kminus, b, np.maximum).ravel()
        # the face between the samples bulges out of their box by at most the sagitta
        # kappa delta^2 / 8 of a cell (delta its diagonal), and never more than eps
        diag = np.zeros((nu, nv))
        diag[:-1, :-1] = np.maximum(np.linalg.norm(grid[1:, 1:] - grid[:-1, :-1], axis=2),
                                    np.linalg.norm(grid[1:, :-1] - grid[:-1, 1:], axis=2))
        delta = _block_reduce(diag, b, np.maximum).ravel()
        kk = np.maximum(kp, km)
        sag = np.where(np.isfinite(kk), np.minimum(0.125 * kk * delta ** 2, eps), eps)
        radius = 0.5 * np.linalg.norm(hi - lo, axis=2).ravel() + sag + 1e-9 * self.reach
        # first fundamental form and parameter centre of every tile (at its middle sample)
        ti, tj = np.indices(self.shape)
        mi = np.minimum(ti * bu + bu // 2, nu - 1).ravel()
        mj = np.minimum(tj * bv + bv // 2, nv - 1).ravel()
        Su, Sv = samples[1][:, mi * nv + mj], samples[2][:, mi * nv + mj]
        form = np.stack([dot(Su, Su), dot(Su, Sv), dot(Sv, Sv)], axis=1)
        pu, pv = us[mi], vs[mj]
        # tile pairs that may be within the reach of each other
        tree = cKDTree(centre)
        pairs = tree.query_pairs(self.reach + 2.0 * float(radius.max()), output_type="ndarray")
        a, c = pairs[:, 0], pairs[:, 1]
        gap = np.linalg.norm(centre[a] - centre[c], axis=1)
        bound = gap - radius[a] - radius[c]
        keep = bound < self.reach
        a, c, gap, bound = a[keep], c[keep], gap[keep], bound[keep]
        du, dv = pu[c] - pu[a], pv[c] - pv[a]
        E, F, G = (0.5 * (form[a, k] + form[c, k]) for k in range(3))
        path = np.sqrt(np.maximum(E * du * du + 2.0 * F * du * dv + G * dv * dv, 0.0))
        far = path > 3.0 * gap + 2.0 * (radius[a] + radius[c])
        n_tiles = centre.shape[0]
        # every pair in both directions, grouped by the tile it informs
        dst, src = np.r_[a, c], np.r_[c, a]
        lb, far2 = np.r_[bound, bound], np.r_[far, far]
        groups = _Groups(dst)
        self.clearance = -groups.max(-lb, np.full(n_tiles, -np.inf), far2)
        # curvature per side and radius: the tile's own and that of the same-sheet tiles
        # whose distance bound is below the radius
        self.radii = self.reach / 2.0 ** np.arange(LEVELS)
        self.kplus = np.empty((n_tiles, LEVELS))
        self.kminus = np.empty((n_tiles, LEVELS))
        kp_src, km_src = kp[src], km[src]
        for m, R in enumerate(self.radii):
            sel = ~far2 & (lb < R)
            self.kplus[:, m] = groups.max(kp_src, kp, sel)
            self.kminus[:, m] = groups.max(km_src, km, sel)

    def tile(self, u, v):
        """Tile numbers of feet at face parameters (u, v)."""
        i = np.clip(np.searchsorted(self.us, u, side="right") - 1, 0, self.us.size - 2)
        j = np.clip(np.searchsorted(self.vs, v, side="right") - 1, 0, self.vs.size - 2)
        ti = np.minimum(i // self.b[0], self.shape[0] - 1)
        tj = np.minimum(j // self.b[1], self.shape[1] - 1)
        return ti * self.shape[1] + tj

    def certified(self, u, v, d):
        """True where the interior foot (u, v) at signed distance ``d`` (along
        ``Su x Sv``) is certainly the closest point of the face."""
        t = self.tile(u, v)
        r = 2.0 * np.abs(d)
        # the smallest recorded radius reach / 2^m that still covers r
        ratio = np.log2(self.reach / np.maximum(r, self.reach / 2.0 ** LEVELS))
        m = np.clip(np.floor(ratio).astype(np.intp), 0, LEVELS - 1)
        k = np.where(d >= 0, self.kplus[t, m], self.kminus[t, m])
        return (r <= self.reach) & (np.abs(d) * k < 0.5) & (r < self.clearance[t])
