"""Arrange measured points on their n x m measurement grid (no FreeCAD).

A grid is an index array ``index[i, j]`` -> point number, oriented so that the
map from grid indices to the face's (u, v) parameters preserves orientation
(checked on every cell, so the correction field built on it is well defined).
"""

from dataclasses import dataclass

import numpy as np

from ..errors import GridError


@dataclass(frozen=True)
class Grid:
    """``index`` (n, m) int: point number at each node; ``rows_from`` tells how it was found."""

    index: np.ndarray
    rows_from: str

    @property
    def shape(self):
        return self.index.shape

    def take(self, values):
        """Arrange per-point ``values`` (N, ...) on the grid -> (n, m, ...)."""
        return np.asarray(values)[self.index]


class Scattered(Grid):
    """A layout that is not a complete grid: ``index`` (N,) is the points in file order.

    The :class:`Grid` interface (``index``, ``shape`` (N,), ``take``) keeps per-point and
    per-node arrays converting alike; ``rows_from`` says why the points are scattered.
    """


def _where(source, lines, k):
    return dict(file=source, line=int(lines[k]) if lines is not None else None)


def grid_from_indices(row, col, u, v, lines=None, source=None):
    """Grid from explicit ``row``/``col`` columns of the measurement file.

    Row and column labels may be any integers (0- or 1-based, gaps in numbering
    allowed); every (row, col) pair must occur exactly once and the grid must be
    complete.
    """
    row = np.asarray(row)
    col = np.asarray(col)
    ru, ri = np.unique(row, return_inverse=True)
    cu, ci = np.unique(col, return_inverse=True)
    n, m = ru.size, cu.size
    index = np.full((n, m), -1, dtype=np.int64)
    flat = ri * m + ci
    order = np.argsort(flat, kind="stable")
    dup = np.nonzero(np.diff(flat[order]) == 0)[0]
    if dup.size:
        a, b = order[dup[0]], order[dup[0] + 1]
        raise GridError("grid node (row %s, col %s) given twice (also on line %s) (expected each "
                        "row/col pair once)"
                        % (row[b], col[b], lines[a] if lines is not None else "?"),
                        **_where(source, lines, b))
    index.ravel()[flat] = np.arange(row.size)
    if np.any(index < 0):
        miss = np.argwhere(index < 0)
        names = ", ".join("(row %s, col %s)" % (ru[i], cu[j]) for i, j in miss[:10])
        more = "" if len(miss) <= 10 else " and %d more" % (len(miss) - 10)
        raise GridError("the row/col indices do not form a complete %d x %d grid: missing %s%s "
                        "(expected every row/col pair; without row/col columns the points can be "
                        "used as a scattered layout)"
                        % (n, m, names, more), file=source)
    return _oriented(Grid(index, "row/col columns"), u, v, source)


def _clusters(x, count, order=None):
    """Split sorted values into ``count`` groups at the largest gaps; return (order, labels, ratio).

    ``order`` (``argsort(x)``) may be given when the same values are split several times.
    """
    if order is None:
        order = np.argsort(x, kind="stable")
    if count <= 1:
        return order, np.zeros(x.size, dtype=int), 0.0
    xs = x[order]
    gaps = np.diff(xs)
    cut = np.sort(np.argpartition(gaps, -(count - 1))[-(count - 1):])
    labels_sorted = np.zeros(x.size, dtype=int)
    labels_sorted[cut + 1] = 1
    labels_sorted = np.cumsum(labels_sorted)
    inside = np.delete(gaps, cut)
    big = gaps[cut].min()
    small = inside.max() if inside.size else 0.0
    ratio = big / max(small, 1e-15 * max(1.0, np.abs(xs).max()))
    labels = np.empty(x.size, dtype=int)
    labels[order] = labels_sorted
    return order, labels, ratio


def _try_rows(a, b, name_a, name_b):
    """Points in rows of nearly constant ``a``; within a row ordered by ``b``."""
    n_pts = a.size
    best = None
    order = np.argsort(a, kind="stable")
    for rows in range(2, n_pts // 2 + 1):
        if n_pts % rows:
            continue
        _, labels, ratio = _clusters(a, rows, order)
        if ratio <= 3.0 or (best is not None and ratio <= best[0]):
            continue
        sizes = np.bincount(labels, minlength=rows)
        if np.all(sizes == n_pts // rows):
            best = (ratio, rows, labels)
    if best is None:
        return None
    _, rows, labels = best
    cols = n_pts // rows
    # labels grow with a, so rows are consecutive runs of the points sorted by a
    members = order.reshape(rows, cols)
    within = np.argsort(b[members], axis=1, kind="stable")
    return np.take_along_axis(members, within, axis=1)


def _describe_incomplete(a, b, name_a, name_b):
    """A message that says which row is short when points almost form a grid."""
    order = np.argsort(a)
    gaps = np.diff(a[order])
    if gaps.size == 0:
        return "only one point"
    thresh = 0.3 * np.sort(gaps)[-max(1, int(np.sqrt(a.size)) // 2):].mean()
    labels = np.concatenate([[0], np.cumsum(gaps > thresh)])
    sizes = np.bincount(labels)
    if sizes.size < 2:
        return "the points do not fall into rows of constant %s or %s" % (name_a, name_b)
    common = np.bincount(sizes).argmax()
    odd = [k for k in range(sizes.size) if sizes[k] != common]
    if not odd:
        return "found %d rows of %d points" % (sizes.size, common)
    full = order[labels == next(k for k in range(sizes.size) if sizes[k] == common)]
    ref = np.sort(b[full])
    half = 0.5 * np.min(np.diff(ref)) if ref.size > 1 else np.inf
    parts = []
    for k in odd[:5]:
        mem = order[labels == k]
        text = "the row at %s=%.6g has %d points" % (name_a, a[mem].mean(), sizes[k])
        if sizes[k] < common:
            gaps = [x for x in ref if np.min(np.abs(b[mem] - x)) > half]
            if gaps:
                text += " (missing near %s=%s)" % (name_b, ", ".join("%.6g" % x for x in gaps[:5]))
        parts.append(text)
    return ("found %d rows of constant %s, most with %d points, but %s"
            % (sizes.size, name_a, common, "; ".join(parts)))


def grid_from_uv(u, v, lines=None, source=None):
    """Find the n x m grid from the points' (u, v) on the face.

    Rows may come in any order and any direction (serpentine scans). The points
    must fall into rows of nearly constant v (or of nearly constant u), each with
    the same number of points.
    """
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    if u.size < 4:
        raise GridError("%d measured points cannot form a grid (expected at least 2 x 2)" % u.size,
                        file=source)
    for a, b, na, nb, how in ((v, u, "v", "u", "rows of constant v"),
                              (u, v, "u", "v", "rows of constant u")):
        index = _try_rows(a, b, na, nb)
        if index is not None:
            if how.endswith("v"):
                index = index.T  # (rows of v, points along u) -> first axis along u
            return _oriented(Grid(np.ascontiguousarray(index), how + " on the face"), u, v, source)
    index = _rows_in_file_order(u, v)
    if index is not None:
        try:
            return _oriented(Grid(index, "scan lines in file order (across the parameter lines)"),
                             u, v, source)
        except GridError:
            pass  # not a proper grid after all: report why the other ways failed
    raise GridError("the %d measured points do not form a complete n x m grid on the face: %s "
                    "(expected rows of equal length; add row/col columns, or --layout "
                    "scattered)" % (u.size, _describe_incomplete(v, u, "v", "u")),
                    file=source)


#: cosine of the direction change (45 degrees) that ends a scan line in file order
_ROW_TURN = np.cos(np.radians(45.0))


def _rows_in_file_order(u, v, turn=_ROW_TURN):
    """Rows of a raster or serpentine scan written line by line, whatever their angle to
    the parameter lines: a row ends where the scan direction turns by more than 45
    degrees on both sides of one step (the step to the next line). Returns the index
    (n, m) with every row running the first row's way, or None when the points are not
    n equal lines of m >= 3 evenly spaced points (within 25 %; n >= 2)."""
    x = np.stack([u / (np.ptp(u) or 1.0), v / (np.ptp(v) or 1.0)], axis=1)
    d = np.diff(x, axis=0)
    length = np.linalg.norm(d, axis=1)
    if d.shape[0] < 3 or np.any(length == 0):
        return None
    e = d / length[:, None]
    cos = np.einsum("ij,ij->i", e[:-1], e[1:])     # turn between step k and step k + 1
    turned = cos < turn
    # step k (1..N-3) links two lines when the direction turns before and after it
    links = np.nonzero(turned[:-1] & turned[1:])[0] + 1
    starts = np.concatenate([[0], links + 1])
    sizes = np.diff(np.concatenate([starts, [u.size]]))
    if sizes.size < 2 or sizes[0] < 3 or np.any(sizes != sizes[0]):
        return None
    index = np.arange(u.size).reshape(sizes.size, sizes[0])
    # a scan grid steps evenly along its lines; points placed adaptively along curves
    # (the mirror paper's layouts) are a scattered layout, not a grid
    along = np.linalg.norm(np.diff(x[index], axis=1), axis=2)
    if np.any(np.abs(along / np.median(along) - 1.0) > 0.25):
        return None
    first = x[index[0, -1]] - x[index[0, 0]]
    back = np.einsum("ij,j->i", x[index[:, -1]] - x[index[:, 0]], first) < 0
    index[back] = index[back, ::-1]
    # the lines must follow each other across the face (no line out of place)
    gaps = np.linalg.norm(x[index[1:, 0]] - x[index[:-1, 0]], axis=1)
    if np.max(gaps) > 3.0 * np.median(gaps):
        return None
    return np.ascontiguousarray(index)


def _oriented(grid, u, v, source):
    """Flip the second axis if needed so every cell maps to (u, v) with positive orientation."""
    index = grid.index
    n, m = index.shape
    if n < 2 or m < 2:
        raise GridError("a %d x %d grid has no cells (expected at least 2 x 2 points)" % (n, m),
                        file=source)
    U, V = np.asarray(u)[index], np.asarray(v)[index]
    du_s, dv_s = U[1:, :-1] - U[:-1, :-1], V[1:, :-1] - V[:-1, :-1]
    du_t, dv_t = U[:-1, 1:] - U[:-1, :-1], V[:-1, 1:] - V[:-1, :-1]
    det = du_s * dv_t - dv_s * du_t
    if np.median(det) < 0:
        index = index[:, ::-1]
        det = -det[:, ::-1]
    if np.any(det <= 0):
        i, j = np.argwhere(det <= 0)[0]
        raise GridError("the measurement grid folds over itself on the face near grid cell "
                        "(%d, %d) (expected a grid whose cells do not overlap in (u, v))" % (i, j),
                        file=source)
    return Grid(np.ascontiguousarray(index), grid.rows_from)
