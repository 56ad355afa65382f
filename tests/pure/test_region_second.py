# SPDX-License-Identifier: LGPL-2.1-or-later
"""The second-order term of a region face's slide along itself (issue 30): on a curved face
and in a varying field the slid point lands on the offset surface."""

import numpy as np

from surfcomp.core.compensation.region_second import edge_vector, normal_term


def _cylinder(u, r):
    c, s = np.cos(u), np.sin(u)
    z = np.zeros_like(u)
    S = np.stack([r * c, r * s, z], -1)
    Su = np.stack([-r * s, r * c, z], -1)
    Sv = np.stack([z, z, z + 1.0], -1)
    Suu = np.stack([-r * c, -r * s, z], -1)
    n = np.stack([c, s, z], -1)
    t = np.stack([-s, c, z], -1)
    return S, Su, Sv, Suu, 0 * Su, 0 * Su, n, t


def test_a_slide_on_a_curved_face_stays_on_the_offset():
    # a face curling with a 0.1 mm radius, corrected by 30 um inwards and slid by 20 um
    r, delta, tau = 0.1, 0.03, 0.02
    u = np.linspace(0.0, 2.0, 5)
    S, Su, Sv, Suu, Suv, Svv, n, t = _cylinder(u, r)
    D = -delta * n + tau * t
    q = normal_term(S, Su, Sv, Suu, Suv, Svv, n, D, lambda x: np.full(len(x), delta))
    before = np.linalg.norm((S + D)[:, :2], axis=1) - (r - delta)
    after = np.linalg.norm((S + D + q[:, None] * n)[:, :2], axis=1) - (r - delta)
    assert np.all(before > 2.5e-3)              # tau^2 / 2 (r - delta): 2.9 um off
    assert np.max(np.abs(after)) < 1e-4         # third order: 0.06 um
    # no slide, no term
    q0 = normal_term(S, Su, Sv, Suu, Suv, Svv, n, -delta * n, lambda x: np.full(len(x), delta))
    assert np.all(q0 == 0.0)


def test_a_slide_in_a_varying_field_reads_the_field_where_it_lands():
    # a plane, the correction rising 1 um per mm along x, the face slid 0.5 mm along x
    u = np.linspace(0.0, 1.0, 4)
    z = np.zeros_like(u)
    S = np.stack([u, z, z], -1)
    Su, Sv = np.tile([1.0, 0, 0], (4, 1)), np.tile([0, 1.0, 0], (4, 1))
    n = np.tile([0, 0, 1.0], (4, 1))

    def field(x):
        return 0.02 + 1e-3 * x[:, 0]

    D = -field(S)[:, None] * n + 0.5 * Su
    q = normal_term(S, Su, Sv, 0 * Su, 0 * Su, 0 * Su, n, D, field)
    landed = S + D + q[:, None] * n
    np.testing.assert_allclose(landed[:, 2], -field(landed), atol=1e-12)


def test_the_edge_vector_gives_both_faces_their_terms():
    a = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    b = np.array([[1.0, 0.0, 0.0], [-np.sqrt(0.75), 0.0, -0.5]])     # 90 and 120 degrees
    qa, qb = np.array([-2e-3, 1e-3]), np.array([5e-4, -3e-3])
    Q = edge_vector(a, b, qa, qb)
    np.testing.assert_allclose(np.einsum("ij,ij->i", Q, a), qa, rtol=3e-3)
    np.testing.assert_allclose(np.einsum("ij,ij->i", Q, b), qb, rtol=3e-3)
