# SPDX-License-Identifier: LGPL-2.1-or-later
"""The second-order term of a region face's displacement where it slides the face along
itself (issue 30; numpy only).

Near a sharp edge the displacement ``D = -delta n + T`` (:mod:`region_build`) keeps the
correction along the normal and slides the face along itself by ``T``, which is how the
intersection of two offset faces moves. ``T`` lies in the tangent plane: on a face that
curves, ``S + D`` leaves the offset surface by ``II_O(T, T) / 2`` (the offset's second
fundamental form; a blade side curling with a 0.08 mm radius next to its trailing edge,
slid by 5 to 21 um, missed the correction by up to 1.8 um), and the correction itself
varies along the slide (the realised correction is read at the foot the point slid to).
:func:`normal_term` gives the scalar ``q`` that puts ``S + D + q n`` on the offset surface
``S - delta(S) n`` to second order.

On the edge both faces must move by one vector. There each face's ``q`` is known from its
own curvature (``q_A``, ``q_B``): the edge adds ``Q`` with ``Q . n_A = q_A`` and
``Q . n_B = q_B`` (:func:`edge_vector`, as the miter combines the two normals), and a face
adds ``q n`` plus, within the band, the part of ``Q`` along itself, so that on the edge
both faces add ``Q``.
"""

import numpy as np

#: the offset's metric at least this share of the face's (else the offset is near a cusp
#: and the term is left out)
CUSP = 0.25
#: slides (mm) shorter than this get no term
SLIDE = 1e-12
#: the term at most this share of the slide (beyond it the expansion fails)
SHORT = 0.5
#: regularisation of the edge's two-normal solve (where the normals nearly agree, both
#: terms vanish with the slide)
EDGE_REG = 1e-3


def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def normal_term(S, Su, Sv, Suu, Suv, Svv, n, D, field, here=None, slope=None):
    """``q`` (M,) at points ``S`` (M, 3) of a face with derivatives ``Su``... (M, 3) and
    outward unit normals ``n`` moved by ``D`` (M, 3): ``S + D + q n`` lies on the offset
    surface to second order in ``D``'s part along the face (module docstring). ``field``:
    ``field(x)`` -> corrections (mm) at points (K, 3); ``here``: ``field(S)``, when known;
    ``slope``: the correction's derivatives in u and v (M,) each, when known (a dense grid's
    differences: the field is then not evaluated where the points land)."""
    D = np.asarray(D, dtype=float)
    q = np.zeros(len(D))
    dn = _dot(D, n)
    T = D - dn[:, None] * n
    slid = np.linalg.norm(T, axis=1) > SLIDE     # (rounding leaves 1e-20 off the bands)
    if not np.any(slid):
        return q
    S, Su, Sv, Suu, Suv, Svv, n, T = (a[slid] for a in (S, Su, Sv, Suu, Suv, Svv, n, T))
    slide = np.linalg.norm(T, axis=1)
    delta = -dn[slid]
    N = np.cross(Su, Sv)
    size = np.maximum(np.linalg.norm(N, axis=1), 1e-300)
    own = np.sign(_dot(N, n))[:, None]      # the outward normal is +-N / |N|
    nu = np.cross(Suu, Sv) + np.cross(Su, Suv)
    nv = np.cross(Suv, Sv) + np.cross(Su, Svv)
    n_u = own * (nu - _dot(nu, n)[:, None] * n) / size[:, None]
    n_v = own * (nv - _dot(nv, n)[:, None] * n) / size[:, None]
    # the offset S - delta n: its tangents and its second fundamental form
    Ou, Ov = Su - delta[:, None] * n_u, Sv - delta[:, None] * n_v
    L = _dot(Suu, n) + delta * _dot(n_u, n_u)
    M = _dot(Suv, n) + delta * _dot(n_u, n_v)
    Nn = _dot(Svv, n) + delta * _dot(n_v, n_v)
    g11, g12, g22 = _dot(Ou, Ou), _dot(Ou, Ov), _dot(Ov, Ov)
    r1, r2 = _dot(Ou, T), _dot(Ov, T)
    det = g11 * g22 - g12 * g12
    # where the offset is near its cusp (the correction near a radius of curvature of
    # the face: the fold of a blade's pressure side over its tip cap) the expansion
    # fails: no term there (those points lie where the design shortens the correction)
    e11, e12, e22 = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)
    ok = det > CUSP * (e11 * e22 - e12 * e12)
    det = np.where(ok, det, 1.0)
    du = np.where(ok, (g22 * r1 - g12 * r2) / det, 0.0)
    dv = np.where(ok, (g11 * r2 - g12 * r1) / det, 0.0)
    curve = 0.5 * (L * du * du + 2.0 * M * du * dv + Nn * dv * dv)
    # the correction read at the foot the point slid to, in the share the normal keeps
    here = field(S) if here is None else np.asarray(here, dtype=float)[slid]
    if slope is None:
        there = field(S + du[:, None] * Su + dv[:, None] * Sv)
    else:
        there = here + slope[0][slid] * du + slope[1][slid] * dv
    share = np.where(np.abs(here) > 1e-15, delta / np.where(here == 0, 1.0, here), 0.0)
    q[slid] = np.where(ok, np.clip(curve - share * (there - here), -SHORT * slide,
                                   SHORT * slide), 0.0)
    return q


def edge_vector(n_a, n_b, q_a, q_b):
    """``Q`` (K, 3) with ``Q . n_a = q_a`` and ``Q . n_b = q_b`` (least norm, regularised
    where the normals nearly agree or are nearly opposite)."""
    c = _dot(n_a, n_b)
    g = np.stack([np.stack([np.ones_like(c), c], -1), np.stack([c, np.ones_like(c)], -1)], -2)
    g = g + EDGE_REG * np.eye(2)
    x = np.linalg.solve(g, np.stack([q_a, q_b], -1)[..., None])[..., 0]
    return x[:, :1] * n_a + x[:, 1:] * n_b
