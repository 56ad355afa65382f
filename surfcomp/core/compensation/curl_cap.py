# SPDX-License-Identifier: LGPL-2.1-or-later
"""A region's correction held short of turning a curl inside out (issue 30; no FreeCAD).

A face moved along its normal by ``delta`` towards its centre of curvature has the normal
of the nominal times ``1 - delta * kappa``: past ``delta = 1 / kappa`` (a trailing edge
curled at a 12 um radius, corrected 30 um inwards) it folds over itself
(:mod:`surfcomp.core.compensation.folds`). So the field is capped, before the edges, the
build, the fidelity and the volume integral take it, by a limit that is ONE function of
the position in space (on a shared edge both faces must still move by the same vector):

* **Curvature samples** (:func:`curvature_samples`): every knot span of every region
  face, :data:`PER_SPAN` parameters across it and at most :data:`SAMPLE_STEP` knot steps
  apart, the principal curvatures from the first and second derivatives; the *convex*
  curvature (centre of curvature on the inward side) limits an inward correction
  (``delta > 0``, into the material), the *concave* one an outward correction. They are
  thinned to the tightest of each cell of the sample step.
* **Limit in space**: ``L(x) = 1 / kappa(x)``, ``kappa(x) = (sum_j (phi_j / (SHARE R_j +
  SLOPE |x - x_j|))^P)^(1/P)``, a smooth maximum (at least its largest term, at most
  ``n^(1/P)`` times it for ``n`` samples) over the samples within the reach, ``R_j`` the
  radius at the sample, ``phi_j`` 1 within :data:`FLAT` of the reach and Wendland's C2
  kernel down to 0 at it. The limit grows by at most :data:`SLOPE` away from a tight curl,
  a slope the build's knot step follows; the reach is where it no longer matters.
* **Soft cap**: with ``t = |delta| / L``, the field is left as it is for ``t <= KNEE`` and
  becomes ``sign(delta) L g(t)``, ``g(t) = KNEE + (1 - KNEE)(1 - exp(-(t - KNEE) /
  (1 - KNEE)))`` beyond (C1, below ``L`` always). Samples whose curvature cannot bring
  ``t`` past the knee anywhere (``kappa_j max|delta| <= KNEE SHARE``) are dropped before the
  limit is built: where every radius is well above the correction, the cap is the field
  itself, to the bit.
* **Evaluation**: ``kappa(x)`` is a sum over every sample within the reach (the terms fall
  as slowly as ``1 / (SLOPE d)``: none can be left out at the 1e-16 level), so it is taken
  only where the cap can act. An upper bound of ``kappa`` per box of 1/32 of the reach
  (every sample's term at the box's nearest point) sorts out the points where ``|delta|
  kappa`` stays below the knee for certain (on the 200 000-point blade bench, 90 % of the
  1.08 million points the field is taken at); they keep the field as it is. The others
  take ``kappa`` sample by sample, the terms added in the samples' order, which is the
  order the neighbour queries of the first version added them in: the capped field is
  the same to the bit as theirs.
"""

import threading

import numpy as np

from ..surface import bspline
from ..surface.kdtree import cKDTree
from .folds import span_parameters
from .region_build import face_lengths
from .region_field import wendland

#: the cap: at most this share of the local radius of curvature
SHARE = 0.5
#: the field is unchanged up to this share of the cap
KNEE = 0.5
#: exponent of the smooth maximum of the samples' curvatures
P = 16.0
#: samples across each knot span, in each direction
PER_SPAN = 3
#: largest distance between two curvature samples (and their cell), in knot steps
SAMPLE_STEP = 0.5
#: points of one block of the limit's evaluation
BLOCK = 4096
#: boxes of one block of the limit's bound
BOX_BLOCK = 1024
#: box-sample pairs the bound takes at once (its arrays' size)
PAIRS = 1 << 20
#: boxes of the limit's bound to the reach (the bound takes a sample nearer by at most the
#: box's diagonal, 5.4 % of the reach)
BOXES_PER_REACH = 32
#: share of the reach over which a sample's term counts in full
FLAT = 0.8
#: the limit grows by at most this (mm per mm) away from a tight curl
SLOPE = 0.005


def principal_curvatures(Su, Sv, Suu, Suv, Svv, n):
    """The principal curvatures ``(k1, k2)`` (``k1 <= k2``, 1/mm) for the unit normal ``n``:
    negative where the surface bends away from ``n`` (convex for an outward ``n``)."""
    E, F, G = (np.einsum("...k,...k", a, b) for a, b in ((Su, Su), (Su, Sv), (Sv, Sv)))
    L, M, N = (np.einsum("...k,...k", a, n) for a in (Suu, Suv, Svv))
    det = np.maximum(E * G - F * F, 1e-300)
    H = (E * N - 2.0 * F * M + G * L) / (2.0 * det)
    K = (L * N - M * M) / det
    root = np.sqrt(np.maximum(H * H - K, 0.0))
    return H - root, H + root


def curvature_samples(surf, outward=1, keep=None, step=None, per_span=PER_SPAN):
    """Points of ``surf`` across every knot span, and at most ``step`` (mm) apart in each
    direction, and their convex and concave curvature (1/mm, >= 0) for the outward normal
    (the surface's normal times ``outward``); samples where ``keep(U, V)`` is false or the
    normal is degenerate are left out. Returns ``(points (M, 3), convex (M,), concave
    (M,))``."""
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    us = span_parameters(surf.knots_u, u0, u1, per_span)
    vs = span_parameters(surf.knots_v, v0, v1, per_span)
    if step is not None:
        lu, lv = face_lengths(surf)
        us = np.union1d(us, np.linspace(u0, u1, int(np.ceil(lu * (u1 - u0) / step)) + 1))
        vs = np.union1d(vs, np.linspace(v0, v1, int(np.ceil(lv * (v1 - v0) / step)) + 1))
    S, Su, Sv, Suu, Suv, Svv = bspline.evaluate_grid(surf, us, vs, order=2)
    n = bspline.grid_unit_normals(Su, Sv, outward)
    ok = np.isfinite(n[..., 0])
    if keep is not None:
        U, V = np.meshgrid(us, vs, indexing="ij")
        ok &= np.asarray(keep(U, V), dtype=bool)
    k1, k2 = principal_curvatures(Su[ok], Sv[ok], Suu[ok], Suv[ok], Svv[ok], n[ok])
    return S[ok], np.maximum(-k1, 0.0), np.maximum(k2, 0.0)


class _Limit:
    """``kappa(x)`` of the samples (see the module docstring); 0 where none matters. The
    samples that can matter (for a field at most ``largest``, mm) are thinned to the
    tightest of each ``cell`` (mm), so a query meets a bounded count of them.

    :meth:`cap` evaluates ``kappa`` only at the points where the cap can act: an upper
    bound of ``kappa`` over a box of :data:`BOXES_PER_REACH` boxes to the reach (each
    sample's term taken at the box's nearest point, see :meth:`bound`) sorts out the points
    where ``|delta| kappa`` stays below :data:`KNEE` for certain; those keep their field to
    the bit, the others take ``kappa`` sample by sample in the same order as before."""

    def __init__(self, points, kappa, cell, largest):
        self.reach = largest / (KNEE * SLOPE * FLAT)
        keep = kappa * largest > KNEE * SHARE
        points, kappa = points[keep], kappa[keep]
        if len(points):
            key = np.floor(points / cell).astype(np.int64)
            order = np.lexsort((-kappa, *key.T[::-1]))
            key = key[order]
            first = np.r_[True, np.any(np.diff(key, axis=0) != 0, axis=1)]
            points, kappa = points[order][first], kappa[order][first]
        self.points, self.kappa = points, kappa
        self.radius = SHARE / kappa           # SHARE R_j, the term's floor (mm)
        self.empty = not len(points)
        # the bound's boxes: over the samples' reach, at most a million to a side
        if not self.empty:
            self.origin = points.min(axis=0) - self.reach
            extent = points.max(axis=0) + self.reach - self.origin
            self.box = max(self.reach / BOXES_PER_REACH, float(np.max(extent)) * 1e-6)
            self.shape = tuple(int(n) for n in np.ceil(extent / self.box) + 1)
            # a point rounded into the next box lies within this of its own (a millionth of
            # the box, and a million times the rounding of the coordinates)
            self.slack = 1e-6 * self.box + 1e-12 * float(np.max(np.abs(self.origin))
                                                         + np.max(extent))
        self.tree = cKDTree(points) if not self.empty else None
        self.known, self.values = np.zeros(0, dtype=np.int64), np.zeros(0)
        self.lock = threading.Lock()

    def __call__(self, x):
        """``kappa`` at points ``x`` (M, 3), 1/mm."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        out = np.zeros(len(x))
        if self.empty:
            return out
        for a in range(0, len(x), BLOCK):
            out[a:a + BLOCK] = self._exact(x[a:a + BLOCK])
        return out

    def _near(self, lo, hi):
        """The samples within the reach of the box ``[lo, hi]`` (and some beyond it), in
        their order."""
        centre, half = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))
        return np.sort(np.asarray(self.tree.query_ball_point(centre, half + self.reach),
                                  dtype=np.intp))

    def _exact(self, xs):
        """``kappa`` at ``xs`` (at most a few thousand points): the samples within the
        reach of their bounding box, each term to the power P added in the samples' order
        (a term beyond the reach is 0 and adds nothing)."""
        acc = np.zeros(len(xs))
        for j in self._near(xs.min(axis=0), xs.max(axis=0)):
            d = np.linalg.norm(self.points[j] - xs, axis=1)
            term = flat_top(d / self.reach) / (self.radius[j] + SLOPE * d)
            acc += term ** P
        return acc ** (1.0 / P)

    def _boxes(self, boxes):
        """:meth:`bound` of the boxes ``boxes`` (flat indices, ascending)."""
        out = np.empty(len(boxes))
        for a in range(0, len(boxes), BOX_BLOCK):
            lo = self.origin + np.stack(np.unravel_index(boxes[a:a + BOX_BLOCK], self.shape),
                                        axis=1) * self.box
            near = self._near(lo.min(axis=0), lo.max(axis=0) + self.box)
            pts, floor = self.points[near], self.radius[near]
            step = max(1, PAIRS // max(len(near), 1))
            for c in range(0, len(lo), step):
                low = lo[c:c + step, None, :]
                gap = np.maximum(np.maximum(low - pts, pts - (low + self.box)), 0.0)
                # less the slack: a point rounded into the box next to its own is inside it
                d = np.maximum(np.linalg.norm(gap, axis=2) - self.slack, 0.0)
                term = np.where(d < self.reach, 1.0 / (floor + SLOPE * d), 0.0)
                out[a + c:a + c + len(low)] = np.sum(term ** P, axis=1) ** (1.0 / P)
        return out

    def bound(self, x, keys=False):
        """An upper bound of ``kappa`` at points ``x`` (M, 3): per box of side
        :attr:`box` holding a point, every sample within the reach of the box taken at
        the box's nearest point (a term is at most ``1 / (SHARE R_j + SLOPE d)`` and falls
        with ``d``); 0 beyond the reach of every sample. The boxes' bounds are kept for
        the next call. With ``keys``, also each point's box (-1 beyond the boxes)."""
        key = np.floor((x - self.origin) / self.box).astype(np.int64)
        inside = np.all((key >= 0) & (key < self.shape), axis=1)
        out, flat_all = np.zeros(len(x)), np.full(len(x), -1, dtype=np.int64)
        if inside.any():
            flat = np.ravel_multi_index(tuple(key[inside].T), self.shape)
            flat_all[inside] = flat
            boxes, which = np.unique(flat, return_inverse=True)
            with self.lock:
                known, values = self.known, self.values
            if len(known):
                pos = np.minimum(np.searchsorted(known, boxes), len(known) - 1)
                found = known[pos] == boxes
                value = np.where(found, values[pos], 0.0)
            else:
                found, value = np.zeros(len(boxes), dtype=bool), np.zeros(len(boxes))
            new = np.flatnonzero(~found)
            if len(new):
                value[new] = self._boxes(boxes[new])
                with self.lock:
                    keys_ = np.concatenate([self.known, boxes[new]])
                    order = np.argsort(keys_, kind="stable")
                    keys_ = keys_[order]
                    vals = np.concatenate([self.values, value[new]])[order]
                    first = np.r_[True, keys_[1:] != keys_[:-1]]
                    self.known, self.values = keys_[first], vals[first]
            out[inside] = value[which.reshape(-1)]
        return (out, flat_all) if keys else out

    def cap(self, delta, x):
        """``delta`` at points ``x`` soft-capped by ``1 / kappa(x)`` (:func:`soft_cap`),
        ``kappa`` taken only where :meth:`bound` lets ``|delta| kappa`` pass the knee (in
        the order of their boxes, so that a block of them lies together)."""
        out = np.array(delta, dtype=float)
        if self.empty or not len(out):
            return out
        bound, box = self.bound(x, keys=True)
        # a margin of a millionth covers the rounding of the bound and of kappa
        k = np.flatnonzero(np.abs(out) * bound > KNEE * (1.0 - 1e-6))
        if len(k):
            k = k[np.argsort(box[k], kind="stable")]
            out[k] = soft_cap(out[k], self(x[k]))
        return out


def flat_top(s):
    """1 for ``s <= FLAT``, then Wendland's C2 kernel down to 0 at ``s = 1``."""
    return wendland((np.asarray(s, dtype=float) - FLAT) / (1.0 - FLAT))


def soft_cap(delta, kappa):
    """``delta`` (mm) capped by ``SHARE / kappa`` (1/mm) as the module docstring says."""
    delta = np.asarray(delta, dtype=float)
    t = np.abs(delta) * np.asarray(kappa, dtype=float)
    over = t > KNEE
    factor = np.ones_like(t)
    s = t[over]
    factor[over] = (KNEE + (1.0 - KNEE) * (1.0 - np.exp(-(s - KNEE) / (1.0 - KNEE)))) / s
    return delta * factor


class CappedField:
    """``field`` capped by the region's curvature (the module docstring), a function of
    the position; :meth:`capped` says where the cap is active and by how much it falls
    short.

    Parameters
    ----------
    field : callable
        ``delta(x)`` (mm) at points ``x`` (M, 3).
    samples : list of (points, convex, concave)
        :func:`curvature_samples` of every region face.
    cell : float
        Cell (mm) the samples are thinned to (their spacing).
    largest : float
        The largest ``|delta|`` the field takes (mm), which sets which samples can matter.
    """

    def __init__(self, field, samples, cell, largest):
        self.field = field
        largest = max(float(largest), 1e-12)
        pts = np.concatenate([s[0] for s in samples]) if samples else np.zeros((0, 3))
        convex = np.concatenate([s[1] for s in samples]) if samples else np.zeros(0)
        concave = np.concatenate([s[2] for s in samples]) if samples else np.zeros(0)
        self.inward = _Limit(pts, convex, cell, largest)
        self.outward = _Limit(pts, concave, cell, largest)

    @property
    def active(self):
        """True where some sample is tight enough for the cap to act somewhere."""
        return not (self.inward.empty and self.outward.empty)

    def both(self, x):
        """``(field, capped field)`` at points ``x`` (M, 3), mm."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        raw = self.field(x)
        if not self.active:
            return raw, raw
        out = raw.copy()
        for lim, side in ((self.inward, raw > 0), (self.outward, raw < 0)):
            k = np.flatnonzero(side)
            if not lim.empty and len(k):
                out[k] = lim.cap(raw[k], x[k])
        return raw, out

    def __call__(self, x):
        return self.both(x)[1]

    def capped(self, x):
        """Where the cap is active at ``x`` (bool) and the shortfall ``|field - capped|``
        (mm) there."""
        raw, out = self.both(x)
        short = np.abs(raw - out)
        return short > 0.0, short


def field_largest(field, points):
    """The largest ``|field|`` at ``points`` (mm), with a margin of 2 for what the field
    takes between them (the cap's sample floor)."""
    return 2.0 * float(np.max(np.abs(field(points)))) if len(points) else 0.0
