# SPDX-License-Identifier: LGPL-2.1-or-later
"""Iterations of a region compensation: the corrections of the rounds added up (numpy/scipy).

A region's correction field (:class:`surfcomp.core.compensation.region_field.RegionField`)
is a function of the position. A next round measures the part machined from the previous
round's corrected faces; its deviations are against the nominal (Werner 2022: "deviations
are always determined in relation to the initial, nominal model"), its own field (the
increment) comes from them, and the corrections accumulate:
``delta(x) = delta_1(x) + ... + delta_k(x)`` (:class:`StackedField`), the same sum at every
face, so shared edges stay closed as in one round.

A round keeps its own field as arrays (:func:`field_arrays`: the kernel centres, their
values and weights, the mean and the radius), so the next round rebuilds it
(:func:`field_from_arrays`) without recomputing the earlier rounds.
"""

import numpy as np
from scipy.spatial import cKDTree

from ...errors import InputError
from .region_field import RegionField


class StackedField:
    """The sum of the fields of several rounds (callables ``x (M, 3) -> delta (M,)``, mm);
    ``own`` is the last round's field (its increment)."""

    def __init__(self, earlier, own):
        self.earlier = list(earlier)
        self.own = own
        self.radius = own.radius

    def __call__(self, x):
        total = self.own(x)
        for f in self.earlier:
            total = total + f(x)
        return total


def field_arrays(field):
    """The arrays that rebuild a :class:`RegionField`: ``{"centres": (K, 3), "values": (K,),
    "weights": (K,), "mean": float, "radius": float}``."""
    return {"centres": np.asarray(field.centres, dtype=float),
            "values": np.asarray(field.values, dtype=float),
            "weights": np.asarray(field.weights, dtype=float),
            "mean": float(field.mean), "radius": float(field.radius)}


def field_from_arrays(centres, values, weights, mean, radius, source="the previous round"):
    """The :class:`RegionField` of :func:`field_arrays` (the same values everywhere).

    Raises
    ------
    InputError
        Arrays of different lengths, none, or a radius that is not positive (naming
        ``source``).
    """
    centres = np.asarray(centres, dtype=float).reshape(-1, 3)
    values = np.asarray(values, dtype=float).ravel()
    weights = np.asarray(weights, dtype=float).ravel()
    if not len(centres) or len(values) != len(centres) or len(weights) != len(centres) \
            or not radius > 0 or not np.all(np.isfinite(values)):
        raise InputError("%s holds no usable correction field (%d centres, %d values, %d "
                         "weights, radius %g mm): recompute it first"
                         % (source, len(centres), len(values), len(weights), radius))
    field = RegionField.__new__(RegionField)
    field.radius = float(radius)
    field.centres, field.values, field.weights = centres, values, weights
    field.mean = float(mean)
    field._tree = cKDTree(centres)
    return field


__all__ = ["StackedField", "field_arrays", "field_from_arrays"]
