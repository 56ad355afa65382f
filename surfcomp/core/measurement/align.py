# SPDX-License-Identifier: LGPL-2.1-or-later
"""Rigid alignment of measured points to the nominal before deviations (no FreeCAD).

A best fit moves the measured points by a rigid transform ``q = R p + t`` that minimises a
robust sum of their squared exact distances to the nominal's reference faces
(Gauss-Newton on the point-to-surface distance: at every iteration the projection engine,
:mod:`surfcomp.core.surface.projection`, gives each point its exact foot on the B-spline face and
the distance's gradient there, the face normal; the linearised problem is the
point-to-plane step of Chen & Medioni 1992 with the exact foot instead of a mesh's; the
weights are Tukey's biweight of the residuals over their median absolute size, iteratively
reweighted, Huber 1981 ch. 7 / Holland & Welsch 1977). The transform may be constrained to
any of the six degrees of freedom (``x y z rx ry rz``); a direction the reference cannot
fix (a plane fixes only its normal translation and two rotations) is refused, named, unless
it is left out. Rotations are about the nominal frame's axes through the origin when the
fit is constrained, about the points' centroid otherwise (the same set of motions then).

A far start is first pre-aligned: the points' principal axes are put on the reference's
(four sign choices, rotations about an axis whose two principal lengths are close), each
start is fitted briefly on a subsample, and the best one is fitted fully.
The 3-2-1 (RPS) alignment is in :mod:`surfcomp.core.measurement.align_rps`, the reporting in
:mod:`surfcomp.core.measurement.align_report`.
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ...errors import InputError
from ..progress import report
from ..surface import bspline
from ..surface.projection import Projector
from ..surface.projection_warm import Tracker

#: the six degrees of freedom, in the order of the parameter vector
DOF_NAMES = ("x", "y", "z", "rx", "ry", "rz")
#: iteration limit of a fit
MAX_ITER = 100
#: a fit has converged when its last step moved no point more than this (mm)
STEP_TOL = 1e-9
#: a robust fit keeps its scale once a step moved no point farther than this (mm)
FREEZE_STEP = 1e-3
#: Tukey biweight constant (95 % efficiency at the normal distribution)
TUKEY_C = 4.685
#: smallest robust scale of the residuals (mm): exact data keeps its weights at 1
SCALE_FLOOR = 1e-4
#: a direction is not fixed by the data when its singular value in the scaled Jacobian
#: is below this share of the largest
RANK_TOL = 1e-5
#: largest rotation of one Gauss-Newton step (rad); longer steps are shortened
MAX_STEP_ROT = 0.3
#: points a fit iterates on before it takes all points (a subsample spread over the file)
FIT_SAMPLE = 50000
#: points of the coarse starts' short fits, and their iterations
COARSE_SAMPLE = 500
COARSE_ITER = 10
#: a start whose brief fit converged with a trimmed RMS below this (mm) needs no other
#: starts (a wrong local minimum of a part is millimetres off, machining errors are not)
GOOD_RMS = 0.05
#: two principal lengths closer than this ratio make the axes ambiguous
AMBIGUOUS = 0.15
#: a rigid transform's rotation must be orthonormal with determinant 1 within this
RIGID_TOL = 1e-9


def parse_dof(text, option="align_dof"):
    """The degrees of freedom of ``text``: ``all``, or names of :data:`DOF_NAMES` written
    together or separated by commas or blanks (``xyz``, ``z``, ``rz``, ``xy,rz``).

    Returns
    -------
    tuple of str, in the order of :data:`DOF_NAMES`
    """
    if text is None or str(text).strip().lower() in ("", "all"):
        return DOF_NAMES
    s = str(text).lower().replace(",", " ").replace("+", " ")
    got, k = set(), 0
    while k < len(s):
        if s[k] == " ":
            k += 1
        elif s[k] in "xyz":
            got.add(s[k])
            k += 1
        elif s[k] == "r" and k + 1 < len(s) and s[k + 1] in "xyz":
            got.add(s[k:k + 2])
            k += 2
        else:
            raise InputError("%s %r: expected 'all' or degrees of freedom among %s (e.g. xyz, "
                             "z, rz, xy,rz)" % (option, text, " ".join(DOF_NAMES)),
                             options=(option,))
    return tuple(n for n in DOF_NAMES if n in got)


def rigid(R, t):
    """The 4 x 4 matrix of ``q = R p + t``."""
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = R, t
    return M


def apply(M, P):
    """Points (N, 3) moved by the 4 x 4 rigid matrix ``M``."""
    P = np.asarray(P, dtype=float)
    return P @ M[:3, :3].T + M[:3, 3]


def check_rigid(M, source=None, tol=RIGID_TOL):
    """``M`` as a float 4 x 4 array when it is a rigid transform: rotation block orthonormal
    within ``tol`` (``|R^T R - I|``), determinant 1 within ``tol``, last row ``0 0 0 1``.

    Raises
    ------
    InputError
        What is wrong with it (``source``: the file in the message).
    """
    M = np.asarray(M, dtype=float)
    if M.shape != (4, 4) or not np.isfinite(M).all():
        raise InputError("a transform must be a finite 4 x 4 matrix, got shape %s"
                         % (M.shape,), file=source)
    R = M[:3, :3]
    off = np.abs(R.T @ R - np.eye(3)).max()
    det = np.linalg.det(R)
    if np.abs(M[3] - [0, 0, 0, 1]).max() > 0:
        raise InputError("the transform's last row is %s (expected 0 0 0 1: a rigid transform)"
                         % " ".join("%g" % x for x in M[3]), file=source)
    if off > tol or abs(det - 1.0) > tol:
        raise InputError("the transform is not rigid: its rotation has determinant %.12g and "
                         "departs from orthonormal by %.3g (expected determinant 1 and "
                         "orthonormal within %g; a scale, shear or mirror cannot align "
                         "measured points)" % (det, off, tol), file=source)
    return M


def work_offset(translation, rz_deg=0.0):
    """The matrix of a machine work offset: rotation about Z by ``rz_deg`` degrees, then the
    translation (mm)."""
    R = Rotation.from_euler("z", float(rz_deg), degrees=True).as_matrix()
    return rigid(R, np.asarray(translation, dtype=float))


def describe(M):
    """Translation (mm), rotation angles about the fixed X, Y, Z axes applied in that order
    (degrees) and the total rotation angle (degrees) of a rigid matrix."""
    rot = Rotation.from_matrix(M[:3, :3])
    return {"translation_mm": [float(x) for x in M[:3, 3]],
            "rotation_deg": [float(x) for x in rot.as_euler("xyz", degrees=True)],
            "angle_deg": float(np.degrees(np.linalg.norm(rot.as_rotvec())))}


@dataclass
class Reference:
    """A reference face of the fit: its name in messages, its surface, and the sign that
    turns ``Su x Sv`` into its outward normal."""

    name: str
    surface: object
    outward: int = 1


class Distances:
    """Signed exact distances of points to the reference faces, with their gradients.

    One :class:`surfcomp.core.surface.projection.Projector` per reference, built once. A point
    goes to the face given for it (``assign``), else to its nearest face.
    """

    def __init__(self, references, points=0, workers=None, warm=True):
        if not references:
            raise InputError("the alignment needs at least one reference face")
        self.refs = list(references)
        self.proj = [Projector(r.surface, workers=workers, min_samples=min(points, 10 ** 6) // 16)
                     for r in self.refs]
        self.warm = warm

    def tracking(self):
        """Per reference a :class:`~surfcomp.core.surface.projection_warm.Tracker` for one point set
        moved call after call (``None`` when not ``warm``: every call projects afresh)."""
        return [Tracker(p) for p in self.proj] if self.warm else None

    def __call__(self, Q, assign=None, track=None):
        """``(r, g, face)``: outward distances (N,), their gradients (N, 3) (unit vectors;
        the face normal inside the face, towards the boundary foot beyond it) and the
        reference of every point (N,); NaN where a point could not be projected.
        ``track``: :meth:`tracking` of these points (the same ``assign`` at every call)."""
        N = Q.shape[0]
        r, g = np.full(N, np.nan), np.full((N, 3), np.nan)
        face = np.zeros(N, dtype=int) if assign is None else np.asarray(assign)
        for k, ref in enumerate(self.refs):
            idx = None if assign is None else np.flatnonzero(face == k)
            if idx is not None and not idx.size:
                continue
            Qk = Q if idx is None else Q[idx]
            p = (track[k] if track else self.proj[k]).project(Qk)
            d = p.distance * ref.outward
            gk = p.normal * ref.outward
            # beyond the face the foot is on its boundary: the gradient points from it
            edge = np.flatnonzero(p.outside)
            diff = Qk[edge] - p.foot[edge]
            ln = np.sqrt(np.einsum("ij,ij->i", diff, diff))
            far = ln > 1e-9
            gk[edge[far]] = diff[far] / ln[far, None] * np.sign(d[edge[far]])[:, None]
            if idx is not None:
                r[idx], g[idx] = d, gk
            elif k == 0:
                r, g = d, gk
            else:
                better = ~(np.abs(d) >= np.abs(r))      # NaN old values lose
                r[better], g[better], face[better] = d[better], gk[better], k
        return r, g, face


def robust_scale(r):
    """``1.4826 median |r|`` of the finite residuals, at least :data:`SCALE_FLOOR`."""
    ok = np.isfinite(r)
    return max(1.4826 * float(np.median(np.abs(r[ok]))) if ok.any() else 0.0, SCALE_FLOOR)


def tukey_weights(r, robust=True, scale=None):
    """``(w, h)``: Tukey's biweight ``w = psi(r) / r`` of residuals ``r`` and the second
    derivative ``h = rho''(r)`` of its loss, over ``scale`` (default :func:`robust_scale`);
    all ones when not ``robust``; zero for NaN."""
    ok = np.isfinite(r)
    if not robust:
        return ok.astype(float), ok.astype(float)
    scale = robust_scale(r) if scale is None else scale
    x2 = (np.where(ok, r, np.inf) / (TUKEY_C * scale)) ** 2
    inside = x2 < 1.0
    return (np.where(inside, (1.0 - x2) ** 2, 0.0),
            np.where(inside, (1.0 - x2) * (1.0 - 5.0 * x2), 0.0))


def free_directions(J, w, cols, lever):
    """The degrees of freedom the weighted Jacobian ``J`` (N, 6) cannot fix among ``cols``
    (indices into :data:`DOF_NAMES`): names of the parameters that take part in the null
    space of the problem scaled to mm (rotations times ``lever``). Empty when all are fixed."""
    D = np.array([1.0, 1.0, 1.0, lever, lever, lever])[cols]
    A = J[:, cols] / D * np.sqrt(w)[:, None]
    s, V = np.linalg.svd(A.T @ A)[1:]
    sv = np.sqrt(np.maximum(s, 0.0))
    null = V[sv < RANK_TOL * max(sv[0], 1e-300)]
    if not null.size:
        return ()
    share = (null ** 2).sum(axis=0)
    return tuple(DOF_NAMES[c] for c, f in zip(cols, share) if f > 0.1)


def refuse_free(free, cols, faces):
    fixed = [DOF_NAMES[c] for c in cols if DOF_NAMES[c] not in free]
    raise InputError("the alignment cannot fix %s: the reference (%s) leaves %s free (a plane "
                     "alone fixes only its normal translation and two rotations); exclude "
                     "them with align_dof%s, or add reference faces with align_faces"
                     % (", ".join(free), ", ".join(faces), "it" if len(free) == 1 else "them",
                        " " + ",".join(fixed) if fixed else ""),
                     options=("align_dof", "align_faces"))


@dataclass
class Fit:
    """One fit's result: ``matrix`` (4 x 4, points -> nominal), ``iterations``,
    ``converged``, and per point the final residual (mm; NaN on passive faces), weight,
    reference and the distance's gradient (N, 3)."""

    matrix: np.ndarray
    iterations: int
    converged: bool
    residual: np.ndarray
    weight: np.ndarray
    face: np.ndarray
    gradient: np.ndarray = None


class Solver:
    """Gauss-Newton iterations of the robust rigid fit (see the module docstring)."""

    def __init__(self, distances, dof=DOF_NAMES, robust=True, offset=0.0, pivot=None,
                 tol=STEP_TOL, names=(), passive=()):
        self.dist = distances
        self.passive = tuple(passive)
        self.cols = [DOF_NAMES.index(n) for n in dof]
        self.robust = robust
        self.offset = float(offset)
        self.pivot = pivot
        self.tol = tol
        self.names = names

    def residuals(self, P, M, assign=None, track=None):
        Q = apply(M, P)
        r, g, face = self.dist(Q, assign, track)
        if self.passive:        # points nearest to a passive face take no part (NaN)
            r = np.where(np.isin(face, self.passive), np.nan, r)
        return Q, r - self.offset, g, face

    def run(self, P, M, max_iter, assign=None, weights=None, check=True):
        """Iterate from ``M``; ``weights`` fixed, else Tukey's loss over the robust scale
        of each iteration's residuals until a step moves no point more than
        :data:`FREEZE_STEP`, then over that scale (Newton steps on the loss converge
        quadratically, reweighting alone only linearly). ``check``: refuse directions the
        data cannot fix (at the solution: a far start may see fewer faces)."""
        if len(self.cols) > P.shape[0]:
            raise InputError("%d point(s) cannot fix %d degrees of freedom (%s): expected at "
                             "least as many points as degrees of freedom"
                             % (P.shape[0], len(self.cols), " ".join(DOF_NAMES[c]
                                                                      for c in self.cols)))
        M, moved, scale = M.copy(), np.inf, None
        track = self.dist.tracking()
        for it in range(1, max_iter + 1):
            Q, r, g, face = self.residuals(P, M, assign, track)
            if weights is None:
                settled = moved <= FREEZE_STEP
                if not settled:
                    scale = robust_scale(r)
                w, h = tukey_weights(r, self.robust, scale)
                h = h if settled else w         # Newton only near the solution
            else:
                w = h = weights
            c = Q.mean(axis=0) if self.pivot is None else self.pivot
            J, arm = jacobian(Q, c, g)
            ok = w > 0
            rk, wk, hk = r, w, h
            if not ok.all():
                J, rk, wk, hk, arm = J[ok], r[ok], w[ok], h[ok], arm[ok]
            step, moved = self._step(J, rk, wk, hk, arm)
            M = step_matrix(step, c) @ M
            if moved <= self.tol:
                if check:
                    self._check(J, wk, arm)
                Q, r, g, face = self.residuals(P, M, assign, track)
                return Fit(M, it, True, r, w, face, g)
        Q, r, g, face = self.residuals(P, M, assign, track)
        return Fit(M, max_iter, False, r, w, face, g)

    def _check(self, J, w, arm):
        lever = max(float(np.sqrt((arm ** 2).sum(axis=1).mean())) if arm.size else 1.0, 1.0)
        free = free_directions(J, w, self.cols, lever)
        if free:
            refuse_free(free, self.cols, self.names)

    def _step(self, J, r, w, h, arm):
        """Newton step of the robust loss (Hessian ``J^T diag(h) J``, gradient
        ``J^T diag(w) r``), the reweighted least-squares step where that Hessian is not
        positive definite."""
        A = J if len(self.cols) == 6 else J[:, self.cols]
        grad = A.T @ (w * r)
        x = None
        for hw in (h, w):
            H = A.T @ (A * hw[:, None])
            try:
                L = np.linalg.cholesky(H)
            except np.linalg.LinAlgError:
                continue
            x = -np.linalg.solve(L.T, np.linalg.solve(L, grad))
            break
        if x is None:
            sw = np.sqrt(w)
            x = np.linalg.lstsq(A * sw[:, None], -r * sw, rcond=None)[0]
        step = np.zeros(6)
        step[self.cols] = x
        rot = np.linalg.norm(step[3:])
        if rot > MAX_STEP_ROT:
            step *= MAX_STEP_ROT / rot
        reach = float(np.sqrt(np.einsum("ij,ij->i", arm, arm).max())) if arm.size else 0.0
        return step, float(np.linalg.norm(step[:3]) + np.linalg.norm(step[3:]) * reach)


def jacobian(Q, c, g):
    """``(J, arm)``: the residuals' derivatives (N, 6) along a translation and a rotation
    vector about ``c``, ``[g, (Q - c) x g]``, and the lever arms ``Q - c`` (N, 3)."""
    arm = Q - c
    J = np.empty((Q.shape[0], 6))
    J[:, :3] = g
    a, b = arm.T, g.T
    J[:, 3] = a[1] * b[2] - a[2] * b[1]
    J[:, 4] = a[2] * b[0] - a[0] * b[2]
    J[:, 5] = a[0] * b[1] - a[1] * b[0]
    return J, arm


def step_matrix(step, centre):
    """The rigid matrix of a parameter step (translation, rotation vector about ``centre``)."""
    R = Rotation.from_rotvec(step[3:]).as_matrix()
    return rigid(R, centre + step[:3] - R @ centre)


# --------------------------------------------------------------------------- coarse starts

def face_samples(references, per_side=40):
    """Points spread over the reference faces by area: ``(points (K, 3), weights (K,))``."""
    pts, wts = [], []
    for ref in references:
        s = ref.surface
        us = np.linspace(*s.u_range, per_side)
        vs = np.linspace(*s.v_range, per_side)
        S, Su, Sv = bspline.evaluate_grid(s, us, vs, order=1)
        pts.append(S.reshape(-1, 3))
        wts.append(np.linalg.norm(np.cross(Su, Sv), axis=-1).ravel())
    w = np.concatenate(wts)
    return np.concatenate(pts), w / w.sum()


def principal_axes(P, w=None):
    """Centroid, principal lengths (descending) and axes (columns, right-handed)."""
    w = np.full(P.shape[0], 1.0 / P.shape[0]) if w is None else w
    c = w @ P
    X = P - c
    lam, E = np.linalg.eigh((X * w[:, None]).T @ X)
    lam, E = lam[::-1], E[:, ::-1]
    if np.linalg.det(E) < 0:
        E[:, 2] = -E[:, 2]
    return c, np.sqrt(np.maximum(lam, 0.0)), E


def coarse_starts(P, references):
    """Start matrices putting the points' principal axes on the faces': the four sign
    choices, or where two principal lengths of the faces are within :data:`AMBIGUOUS` of
    each other, rotations in 30 degree steps about the third axis, each also turned over."""
    cm, lm, Em = principal_axes(P)
    cn, ln_, En = principal_axes(*face_samples(references))
    turns = [np.diag(s) for s in ((1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1))]
    for a in range(3):
        b, c = [k for k in range(3) if k != a]
        if abs(ln_[b] - ln_[c]) <= AMBIGUOUS * max(ln_[b], 1e-12):
            axis, over = np.zeros(3), -np.ones(3)
            axis[a], over[b] = 1.0, 1.0
            spins = [Rotation.from_rotvec(axis * np.radians(k * 30.0)).as_matrix()
                     for k in range(12)]
            turns = [S @ F for S in spins for F in (np.eye(3), np.diag(over))]
            break
    starts = []
    for T in turns:
        R = En @ T @ Em.T
        starts.append(rigid(R, cn - R @ cm))
    return starts


def spread(n, k):
    """About ``k`` indices spread evenly over ``range(n)`` (all when ``n <= k``)."""
    if n <= k:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, k).round().astype(int))


def trimmed_rms(r, keep=0.8):
    """RMS of the smallest ``keep`` share of ``|r|`` (NaN counts as infinite)."""
    a = np.sort(np.where(np.isfinite(r), np.abs(r), np.inf))[:max(1, int(keep * r.size))]
    return float(np.sqrt(np.mean(a * a)))


def _cost(solver, P, M):
    """Trimmed RMS distance of the points moved by ``M`` to their nearest faces, passive
    ones included (a start must not win by handing points to them)."""
    return trimmed_rms(solver.dist(apply(M, P))[0] - solver.offset)


def pre_align(P, solver, M0, progress=None):
    """The best start among ``M0`` and the principal-axes starts (:func:`coarse_starts`):
    each fitted briefly on a subsample (all for 3 iterations, the best three on), another
    start wins only when its trimmed RMS is below half of ``M0``'s.
    Returns ``(matrix, label)``."""
    sub = P[spread(P.shape[0], COARSE_SAMPLE)]
    quick = Solver(solver.dist, robust=solver.robust, offset=solver.offset, tol=1e-6,
                   passive=solver.passive)
    first = quick.run(sub, M0, COARSE_ITER, check=False)
    best, best_cost, label = first.matrix, _cost(solver, sub, first.matrix), "as given"
    if first.converged and best_cost < GOOD_RMS:
        return best, label
    starts = coarse_starts(apply(M0, P), solver.dist.refs)
    tries = []
    for k, S in enumerate(starts):
        report(progress, 0.1 * (k + 1) / len(starts), "pre-aligning (principal axes)")
        fit = quick.run(sub[::3], S @ M0, 3, check=False)
        tries.append((_cost(solver, sub[::3], fit.matrix), k, fit.matrix))
    for _c, _k, M in sorted(tries, key=lambda x: x[:2])[:3]:
        fit = quick.run(sub, M, COARSE_ITER, check=False)
        cost = _cost(solver, sub, fit.matrix)
        if cost < (0.5 if label == "as given" else 1.0) * best_cost:
            best, best_cost, label = fit.matrix, cost, "principal axes"
    return best, label


def best_fit(points, references, assign=None, dof=DOF_NAMES, start=None, coarse=True,
             robust=True, offset=0.0, max_iter=MAX_ITER, tol=STEP_TOL, workers=None,
             progress=None, passive=(), distances=None, warm=True):
    """Robust rigid least-squares fit of measured points to reference faces.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Measured points (mm).
    references : list of Reference
    assign : array_like of int, shape (N,), optional
        The reference of every point (index into ``references``); default its nearest.
    dof : tuple of str
        Degrees of freedom the fit may move (:data:`DOF_NAMES`).
    start : ndarray (4, 4), optional
        Starting transform (default identity); a known transform goes here.
    coarse : bool
        Pre-align on principal axes (:func:`pre_align`, six degrees of freedom only).
    robust : bool
        Tukey-weighted (default) or plain least squares.
    offset : float
        Distance (mm) the points keep outside the faces (a stylus tip radius).
    max_iter, tol
        Iteration limit of each stage (subsample, all points) and the convergence step
        (mm, largest motion of a point).
    passive : tuple of int
        References that only claim their nearest points, which then take no part in the
        fit (the compensated face beside datum faces); their residuals are NaN.
    distances : Distances, optional
        The references' projection engines when the caller has them.
    warm : bool
        Iterations after the first answer each point from its last foot
        (:class:`~surfcomp.core.surface.projection_warm.Tracker`, the same distances to ~1e-12
        mm); False projects afresh at every iteration.

    Returns
    -------
    (Fit, str)
        The fit (matrix maps measured points to the nominal) and how it started
        (``'as given'`` or ``'principal axes'``).

    Raises
    ------
    InputError
        Fewer points than degrees of freedom, directions the references cannot fix (named),
        no convergence within ``max_iter``.
    """
    P = np.asarray(points, dtype=float)
    M0 = np.eye(4) if start is None else np.asarray(start, dtype=float)
    dist = distances or Distances(references, P.shape[0], workers)
    dist.warm = warm
    pivot = None if {"x", "y", "z"} <= set(dof) else np.zeros(3)
    names = [r.name for k, r in enumerate(references) if k not in passive]
    solver = Solver(dist, dof, robust, offset, pivot, tol, names, passive)
    label = "as given"
    if coarse and len(dof) == 6 and P.shape[0] >= 6:
        M0, label = pre_align(P, solver, M0, progress)
    iterations = 0
    if P.shape[0] > FIT_SAMPLE:
        s = spread(P.shape[0], FIT_SAMPLE)
        report(progress, 0.2, "fitting on %d of %d points" % (s.size, P.shape[0]))
        sub = Solver(dist, dof, robust, offset, pivot, 1e-6, names, passive)
        fit = sub.run(P[s], M0, max_iter, None if assign is None else np.asarray(assign)[s])
        if not fit.converged:
            _not_converged(max_iter)
        M0, iterations = fit.matrix, fit.iterations
    report(progress, 0.6, "fitting on all %d points" % P.shape[0])
    fit = solver.run(P, M0, max_iter, assign)
    if not fit.converged:
        _not_converged(max_iter)
    fit.iterations += iterations
    report(progress, 1.0, "aligned")
    return fit, label


def _not_converged(max_iter):
    raise InputError("the alignment did not converge in %d iterations (expected the measured "
                     "points to match the reference faces; are they the right faces, or is "
                     "the start too far off? a transform may bring the points closer)"
                     % max_iter, options=("transform",))
