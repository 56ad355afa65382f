# SPDX-License-Identifier: LGPL-2.1-or-later
"""One deviation field over a region of several faces (issue 30; numpy/scipy only).

The points of a region are not split face by face before the numerics. Each point is
assigned to its nearest face (:func:`assign`) only to report the count per face and to
take its deviation along that face's normal; the filter and the correction field are then
functions of the 3D position:

* **Mask filter over the set** (:func:`mask_filter_3d`): Werner 2022's mask filter (eq. 3-5)
  with the square mask of ``N x N`` grid steps replaced by a ball of radius ``N/2`` steps
  in space, the step being the points' median nearest-neighbour distance. The box mask
  weighs every neighbour in the ball alike, the Gaussian mask by ``exp(-r^2 / 2 sigma^2)``;
  the sum is divided by the weights present (the ``renormalize`` edge handling).
* **Correction field** (:class:`RegionField`): a kernel average of the corrections in
  space, ``delta(x) = sum_j phi(|x - x_j| / R) c_j / sum_j phi(|x - x_j| / R)``, with the
  compactly supported Wendland kernel ``phi(s) = (1 - s)^4 (4 s + 1)`` (C2). The points are
  first gathered in cells of ``R / 3`` (their weighted centroid and mean), so a 200 000
  point region costs a few thousand kernel centres.

**How the neighbourhood crosses an edge.** Both the filter's ball and the field's kernel
are balls in space, so at a shared edge they take the points of both faces as they take
the points of one face: the field is one function of ``x``, the same value whichever face
evaluates it, and continuous (C2) across every edge. Where the part is thinner than the
ball (a blade's trailing edge), both sides share their readings. Far from every point the
field falls back smoothly on wider kernels (4 R, 16 R) and, beyond them, on the mean
correction.
"""

import numpy as np

from ...errors import InputError, MeasurementFileError
from ..surface.kdtree import cKDTree
from .filters import WERNER_MASK_SIZE

#: the wider kernels the field falls back on where no point lies within R: (factor, weight)
FALLBACK = ((4.0, 1e-3), (16.0, 1e-6))
#: weight of the mean correction beyond every kernel
MEAN_WEIGHT = 1e-12
#: cell size of the field's kernel centres, as a share of R
CELL = 1.0 / 3.0
#: block size of the field's kernel sums, as a share of the kernel's radius
BLOCK = 0.5
#: kernel values of one dense block of the field's sums at most (memory: 8 bytes each)
BLOCK_VALUES = 1 << 20


def wendland(s):
    """Wendland's C2 kernel ``(1 - s)^4 (4 s + 1)`` for ``s < 1``, else 0."""
    s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
    return (1.0 - s) ** 4 * (4.0 * s + 1.0)


def wendland_unclipped(s):
    """:func:`wendland` of ``s`` already in ``[0, 1]`` (no copy, fewer passes)."""
    t = 1.0 - s
    t *= t
    t *= t
    return t * (4.0 * s + 1.0)


def spacing(points):
    """Median distance (mm) of each point to its nearest neighbour."""
    points = np.asarray(points, dtype=float)
    if len(points) < 2:
        raise InputError("a region needs at least two measured points")
    d, _ = cKDTree(points).query(points, k=2, workers=-1)
    return float(np.median(d[:, 1]))


def assign(distances, max_offset):
    """Nearest face of each point.

    Parameters
    ----------
    distances : ndarray, shape (F, N)
        Absolute distance of each point from each face; NaN or inf where the point's foot
        is not on the face (beyond its border or trim).
    max_offset : float
        A point farther than this (mm) from every face is on no face.

    Returns
    -------
    ndarray of int, shape (N,)
        The face index, -1 for a point on no face.
    """
    d = np.where(np.isfinite(distances), distances, np.inf)
    face = np.argmin(d, axis=0)
    best = d[face, np.arange(d.shape[1])]
    return np.where(best <= max_offset, face, -1)


def mask_filter_3d(points, d, mask_size=WERNER_MASK_SIZE, kind="box", sigma=None, step=None):
    """Werner's mask filter over scattered points in space (see the module docstring).

    Parameters
    ----------
    points : ndarray, shape (N, 3)
        Nominal points (mm).
    d : ndarray, shape (N,)
        Deviations (mm).
    mask_size : int
        Odd mask size in grid steps; 1 leaves the deviations as they are.
    kind : {'box', 'gaussian'}
    sigma : float, optional
        Gaussian sigma in grid steps (default ``mask_size / 4``).
    step : float, optional
        Grid step (mm); default :func:`spacing`.

    Returns
    -------
    ndarray, shape (N,)
        Filtered deviations (mm).
    """
    points = np.asarray(points, dtype=float)
    d = np.asarray(d, dtype=float)
    if mask_size <= 1:
        return d.copy()
    step = spacing(points) if step is None else float(step)
    radius = 0.5 * mask_size * step
    tree = cKDTree(points)
    pairs = tree.query_pairs(radius, output_type="ndarray")
    i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(len(d))])
    j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(len(d))])
    if kind == "gaussian":
        s = (mask_size / 4.0 if sigma is None else float(sigma)) * step
        r2 = np.sum((points[i] - points[j]) ** 2, axis=1)
        w = np.exp(-0.5 * r2 / (s * s))
    else:
        w = np.ones(len(i))
    num = np.bincount(i, weights=w * d[j], minlength=len(d))
    den = np.bincount(i, weights=w, minlength=len(d))
    return num / den


def _cells(key):
    """``np.unique(key, axis=0, return_inverse=True, return_counts=True)[1:]`` for integer
    rows (M, 3): the cells in the same (lexicographic) order, from one integer per row
    (several times faster than sorting the rows)."""
    if not len(key):
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    k = key - key.min(axis=0)
    ext = k.max(axis=0) + 1
    if float(ext[0]) * float(ext[1]) * float(ext[2]) >= 2.0 ** 62:
        _, inv, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        return inv.ravel(), count
    _, inv, count = np.unique((k[:, 0] * ext[1] + k[:, 1]) * ext[2] + k[:, 2],
                              return_inverse=True, return_counts=True)
    return inv, count


class RegionField:
    """The correction field ``delta(x)`` of a region (mm, positive: into the material).

    Parameters
    ----------
    points : ndarray, shape (N, 3)
        Nominal points (mm).
    values : ndarray, shape (N,)
        Corrections at the points (mm).
    radius : float
        Kernel radius R (mm).
    """

    def __init__(self, points, values, radius):
        points = np.asarray(points, dtype=float)
        values = np.asarray(values, dtype=float)
        self.radius = float(radius)
        cell = CELL * self.radius
        inv, count = _cells(np.floor(points / cell).astype(np.int64))
        self.centres = np.stack([np.bincount(inv, weights=points[:, k]) / count
                                 for k in range(3)], axis=1)
        self.values = np.bincount(inv, weights=values) / count
        self.weights = count.astype(float)
        self.mean = float(np.mean(values))
        self._tree = cKDTree(self.centres)

    def _sums(self, x, radius):
        """``sum_j phi_j w_j c_j`` and ``sum_j phi_j w_j`` at the points ``x`` (M, 3).

        The points are taken in blocks of :data:`BLOCK` x ``radius`` (sorted by block);
        each block's candidate centres are those within ``radius`` plus the block's half
        diagonal of its middle (one ball query for all blocks), and the block's kernel
        values are one dense matrix against them, summed by a matrix product (candidates
        beyond ``radius`` get ``phi = 0``). About twice as fast as the pairs of a sparse
        distance matrix, and the same sums up to rounding."""
        out = np.zeros((len(x), 2))
        if not len(x):
            return out[:, 0], out[:, 1]
        key = np.floor(x / (BLOCK * radius)).astype(np.int64)
        order = np.lexsort(key.T[::-1])
        xs, key = x[order], key[order]
        starts = np.r_[0, np.flatnonzero(np.any(np.diff(key, axis=0) != 0, axis=1)) + 1]
        ends = np.r_[starts[1:], len(x)]
        lo, hi = np.minimum.reduceat(xs, starts), np.maximum.reduceat(xs, starts)
        mid = 0.5 * (lo + hi)
        half = 0.5 * np.linalg.norm(hi - lo, axis=1)
        candidates = self._tree.query_ball_point(mid, radius + half)
        wv = np.stack([self.weights * self.values, self.weights], axis=1)
        sums = np.zeros((len(x), 2))
        for a, b, c, m in zip(starts, ends, candidates, mid):
            if not c:
                continue
            c = np.asarray(c)
            q = self.centres[c] - m         # about the block's middle: no cancellation
            qq = np.einsum("ij,ij->i", q, q)
            rows = max(1, BLOCK_VALUES // len(c))
            for s in range(a, b, rows):
                p = xs[s:min(s + rows, b)] - m
                d2 = np.einsum("ij,ij->i", p, p)[:, None] + qq[None, :] - 2.0 * (p @ q.T)
                t = np.sqrt(np.maximum(d2, 0.0)) / radius
                sums[s:s + len(p)] = wendland_unclipped(np.minimum(t, 1.0)) @ wv[c]
        out[order] = sums
        return out[:, 0], out[:, 1]

    def __call__(self, x):
        """``delta`` at points ``x`` (shape (M, 3)), mm."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        num, den = self._sums(x, self.radius)
        for factor, weight in FALLBACK:
            far = den < 1e3 * weight
            if np.any(far):
                n2, d2 = self._sums(x[far], factor * self.radius)
                num[far] += weight * n2
                den[far] += weight * d2
        return (num + MEAN_WEIGHT * self.mean) / (den + MEAN_WEIGHT)


def coverage(samples, points, radius, area=None):
    """Share of a face's area samples with a measured point within ``radius``.

    Parameters
    ----------
    samples : ndarray, shape (M, 3)
        Points on the face (inside its trim).
    points : ndarray, shape (N, 3)
        The measured points assigned to the face.
    radius : float
    area : ndarray, shape (M,), optional
        The area each sample stands for (default: equal areas).
    """
    if len(points) == 0 or len(samples) == 0:
        return 0.0
    d, _ = cKDTree(points).query(samples, k=1, distance_upper_bound=radius)
    return float(np.average(np.isfinite(d), weights=area))


def check_straddle(points, d, face, edges, radius, max_offset, lines, source, names):
    """Refuse readings that jump across a shared edge.

    For each shared edge (``edges``: ``(a, b, samples)`` with the faces' indices and points
    along the edge), the points of face ``a`` and face ``b`` within ``radius`` of the edge
    and of each other are compared: deviations more than ``max_offset`` apart (mm) are a
    step no surface can follow (a registration error, two parts mixed up), so the run is
    refused naming the two faces and a pair of lines.
    """
    for a, b, samples in edges:
        near = cKDTree(samples).query(points, k=1, distance_upper_bound=radius)[0]
        ia = np.flatnonzero((face == a) & np.isfinite(near))
        ib = np.flatnonzero((face == b) & np.isfinite(near))
        if not len(ia) or not len(ib):
            continue
        pairs = cKDTree(points[ia]).query_ball_tree(cKDTree(points[ib]), radius)
        worst = (0.0, None, None)
        for k, js in enumerate(pairs):
            if not js:
                continue
            jump = np.abs(d[ib[js]] - d[ia[k]])
            m = int(np.argmax(jump))
            if jump[m] > worst[0]:
                worst = (float(jump[m]), ia[k], ib[js[m]])
        if worst[0] > max_offset:
            raise MeasurementFileError(
                "the readings straddling the edge between %s and %s differ by %.4f mm "
                "(line %d on %s against line %d on %s), more than max_offset %.4g mm "
                "(expected one surface across the edge)"
                % (names[a], names[b], worst[0], lines[worst[1]], names[a], lines[worst[2]],
                   names[b], max_offset), file=source, options=("max_offset",))
