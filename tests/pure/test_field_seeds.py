# SPDX-License-Identifier: LGPL-2.1-or-later
"""The seeds of a small grid's map are made once for its nodes' (u, v): the grid check's
field and the construction's field (other values, same nodes) share them, and locate the
same; other nodes, or a map with more seeds than are kept, make their own."""

import numpy as np
from numpy.testing import assert_array_equal

from surfcomp.core.compensation import field
from surfcomp.core.compensation.field import GridField


def _nodes(n, turn=20.0):
    t = np.linspace(0.01, 0.99, n)
    U, V = np.meshgrid(t, t, indexing="ij")
    a, c = np.radians(turn), 0.5
    return (c + 0.68 * ((U - c) * np.cos(a) - (V - c) * np.sin(a)),
            c + 0.68 * ((U - c) * np.sin(a) + (V - c) * np.cos(a)))


def test_the_same_nodes_share_the_seeds():
    U, V = _nodes(45)
    check = GridField(U, V, np.zeros(U.shape))
    seeds = check._kd()
    built = GridField(U.copy(), V.copy(), np.random.default_rng(1).normal(size=U.shape))
    assert built._kd() is seeds
    us = vs = np.linspace(0.1, 0.9, 33)
    shared = built.locate_grid(us, vs)
    field._LAST_SEEDS.clear()          # the same field with seeds of its own
    own = GridField(U, V, built._F[..., 2]).locate_grid(us, vs)
    assert_array_equal(shared[0], own[0])
    assert_array_equal(shared[1], own[1])


def test_other_nodes_make_their_own():
    U, V = _nodes(45)
    a = GridField(U, V, np.zeros(U.shape))._kd()
    U2, V2 = _nodes(45, turn=21.0)
    b = GridField(U2, V2, np.zeros(U.shape))._kd()
    assert b is not a and not np.array_equal(a[1].data, b[1].data)


def test_a_large_map_is_not_kept():
    U, V = _nodes(120)                 # 4 seeds a cell side: 477^2 > 100 000 seeds
    f = GridField(U, V, np.zeros(U.shape))
    seeds = f._kd()
    assert seeds[0].shape[0] > field._SEEDS_KEPT
    assert field._LAST_SEEDS == []
