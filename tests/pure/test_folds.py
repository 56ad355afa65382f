# SPDX-License-Identifier: LGPL-2.1-or-later
"""A corrected surface that folds over itself is found (core/compensation/folds.py): a
quarter cylinder of 25 mm radius moved inwards by more than its radius turns inside out."""

import numpy as np
import pytest

from surfcomp.core.compensation import folds
from surfcomp.core.surface.bspline import Surface
from tests.pure.surfaces import quarter_cylinder

R, H = 25.0, 40.0


def moved_inwards(nominal, d0, d1):
    """The cylinder moved inwards by ``d0`` at z = 0 and ``d1`` at z = H (exactly: the
    circle's rational poles scaled about the axis)."""
    poles = nominal.poles.copy()
    poles[:, 0, :2] *= (R - d0) / R
    poles[:, 1, :2] *= (R - d1) / R
    return Surface(poles, nominal.knots_u, nominal.knots_v, nominal.degree_u,
                   nominal.degree_v, nominal.weights)


def test_a_correction_below_the_radius_does_not_fold():
    nominal = quarter_cylinder(R, H)
    fold = folds.find_fold(nominal, moved_inwards(nominal, 0.03, 10.0))
    # the correction's slope (10 mm over 40 mm) tilts the normal by atan(0.25) = 14.04 deg
    assert fold.angle == pytest.approx(np.degrees(np.arctan(9.97 / H)), abs=0.01)
    assert not fold.folds and fold.folded_share == 0.0
    assert folds.fold_warning("Face1", fold) is None


def test_a_correction_beyond_the_radius_turns_the_face_inside_out():
    nominal = quarter_cylinder(R, H)
    fold = folds.find_fold(nominal, moved_inwards(nominal, 30.0, 30.0))
    assert fold.angle == pytest.approx(180.0, abs=1e-6)
    assert fold.folds and fold.folded_share == pytest.approx(1.0)
    text = folds.fold_warning("Face1", fold)
    assert text.startswith("Face1: the corrected face folds over itself near (")
    assert "turns by up to 180 deg" in text


def test_a_partial_fold_is_located_where_the_correction_exceeds_the_radius():
    nominal = quarter_cylinder(R, H)
    # inwards 10 mm at z = 0 growing to 40 mm at z = H: past the 25 mm radius above z = 20
    fold = folds.find_fold(nominal, moved_inwards(nominal, 10.0, 40.0), per_span=4)
    assert fold.folds
    assert fold.xyz[2] > 20.0
    # one span each way, 4 samples across: the rows at z = 30 and 40 mm fold, the row at
    # z = 20 mm has shrunk to the axis (no normal, not counted), z = 0 and 10 mm do not
    assert fold.samples == 5 * 4
    assert fold.folded_share == pytest.approx(2 / 4)


def test_the_samples_cover_every_knot_span_of_both_surfaces():
    t = folds.span_parameters([0, 0, 0, 0.1, 0.5, 1, 1, 1], 0.0, 1.0, per_span=4)
    assert t.size == 3 * 4 + 1
    assert np.allclose(t[:5], [0, 0.025, 0.05, 0.075, 0.1])
    assert t[0] == 0.0 and t[-1] == 1.0


def test_samples_outside_the_kept_part_are_left_out():
    nominal = quarter_cylinder(R, H)
    moved = moved_inwards(nominal, 10.0, 40.0)
    # the cylinder's v runs along z from 0 to 1: keeping v <= 0.45 (z <= 18 mm) leaves the
    # fold out, as a trim that ends before it would
    fold = folds.find_fold(nominal, moved, per_span=4, keep=lambda U, V: V <= 0.45)
    assert not fold.folds and fold.folded_share == 0.0
    assert fold.samples == 5 * 2        # the rows at z = 0 and 10 mm
    assert fold.xyz[2] <= 10.0 + 1e-9
