# SPDX-License-Identifier: LGPL-2.1-or-later
"""Where a corrected surface folds over itself (no FreeCAD).

Moving a face along its normal by more than its radius of curvature, towards the centre of
that curvature, turns the face inside out there: an inward correction of 30 um on a
trailing edge curled at a 12 um radius gives a surface that loops over itself. Its normal
then points against the nominal's (the offset's normal is the nominal's times
``1 - delta * kappa``, which changes sign), while everywhere else the correction's slopes
(about 1e-3) tilt it by fractions of a degree. A cutter cannot follow such a loop, CAM's
mesher spends its time on it, and OpenCASCADE still calls the solid valid: so the loop is
looked for here, on the two surfaces' common parameters, and reported.

The samples: every knot span of either surface, :data:`PER_SPAN` parameters across it in
each direction (a loop lies within the few spans where the curl is tight), evaluated in
blocks of about a million points.
"""

from dataclasses import dataclass

import numpy as np

from ..limits import FOLD_ANGLE_DEG as FOLD_ANGLE
from ..surface import bspline

#: samples across each knot span, in each direction
PER_SPAN = 2


@dataclass
class Fold:
    """What :func:`find_fold` found: the largest angle (degrees) between the corrected
    and the nominal normal at the same parameters, where it is (``u``, ``v`` and the nominal
    point ``xyz``, mm), the share of the samples past :data:`FOLD_ANGLE` and the count of
    the samples that had a normal (and were kept)."""

    angle: float
    u: float
    v: float
    xyz: tuple
    folded_share: float
    samples: int

    @property
    def folds(self):
        return self.angle > FOLD_ANGLE

    def as_dict(self):
        return {"largest_normal_turn_deg": self.angle, "folds": self.folds,
                "at_mm": list(self.xyz), "at_uv": [self.u, self.v],
                "folded_share": self.folded_share, "samples": self.samples}


def span_parameters(knots, lo, hi, per_span=PER_SPAN):
    """Parameters across every span of ``knots`` within ``[lo, hi]``: ``per_span`` in each
    span, its ends included (sorted, unique)."""
    k = np.unique(np.clip(np.asarray(knots, dtype=float), lo, hi))
    k = np.union1d(k, [lo, hi])
    t = np.linspace(0.0, 1.0, per_span + 1)
    return np.unique((k[:-1, None] + np.diff(k)[:, None] * t[None, :]).ravel())


def _unit_normals(surf, us, vs, outward):
    S, Su, Sv = bspline.evaluate_grid(surf, us, vs, order=1)
    return S, bspline.grid_unit_normals(Su, Sv, outward)


def find_fold(nominal, corrected, outward=1, per_span=PER_SPAN, keep=None):
    """The largest turn of the corrected surface's normal from the nominal's at the same
    (u, v) (:class:`Fold`), over the knot spans of both surfaces (the corrected surface
    spans the nominal's parameter domain, as every builder here makes it). Degenerate
    normals (a pole) are left out, and so are the samples where ``keep(U, V)`` (a bool
    array of the grid block's shape, e.g. inside a trimmed face's boundary) is false."""
    (u0, u1), (v0, v1) = nominal.u_range, nominal.v_range
    us = np.union1d(span_parameters(nominal.knots_u, u0, u1, per_span),
                    span_parameters(corrected.knots_u, u0, u1, per_span))
    vs = np.union1d(span_parameters(nominal.knots_v, v0, v1, per_span),
                    span_parameters(corrected.knots_v, v0, v1, per_span))
    best, where, folded, count = -1.0, (u0, v0, (np.nan,) * 3), 0, 0
    step = max(1, int(1e6 // vs.size))
    for start in range(0, us.size, step):
        ub = us[start:start + step]
        S, n = _unit_normals(nominal, ub, vs, outward)
        _C, nc = _unit_normals(corrected, ub, vs, outward)
        cos = np.clip(np.einsum("ijk,ijk->ij", n, nc), -1.0, 1.0)
        angle = np.degrees(np.arccos(cos))
        if keep is not None:
            angle[~keep(*np.meshgrid(ub, vs, indexing="ij"))] = np.nan
        count += int(np.count_nonzero(np.isfinite(angle)))
        if not np.isfinite(angle).any():
            continue
        folded += int(np.count_nonzero(angle > FOLD_ANGLE))
        i, j = np.unravel_index(np.nanargmax(angle), angle.shape)
        if angle[i, j] > best:
            best = float(angle[i, j])
            where = (float(ub[i]), float(vs[j]), tuple(float(x) for x in S[i, j]))
    return Fold(angle=max(best, 0.0), u=where[0], v=where[1], xyz=where[2],
                folded_share=folded / float(max(count, 1)), samples=count)


def fold_warning(name, fold):
    """The warning for a face that folds (None when it does not): where, and why."""
    if not fold.folds:
        return None
    x, y, z = fold.xyz
    return ("%s: the corrected face folds over itself near (%.3f, %.3f, %.3f) mm: its normal "
            "turns by up to %.0f deg from the nominal's (%.2g %% of the face's samples past "
            "%g deg), where the correction towards the face's centre of curvature is larger "
            "than the radius of curvature (a sharp edge's curl): no cutter can follow the "
            "loop there, so check or reduce the correction near that point"
            % (name, x, y, z, fold.angle, 100.0 * fold.folded_share, FOLD_ANGLE))


__all__ = ["Fold", "find_fold", "fold_warning", "span_parameters", "PER_SPAN", "FOLD_ANGLE"]
