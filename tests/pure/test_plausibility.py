# SPDX-License-Identifier: LGPL-2.1-or-later
"""Plausibility of deviations: max offset per line, ISO 2768-1 fine size tolerance."""

import numpy as np
import pytest

from surfcomp.core.compensation import plausibility as pl


@pytest.mark.parametrize("size, tol", [(2.0, 0.05), (6.0, 0.05), (6.1, 0.1), (30.0, 0.1),
                                       (100.0, 0.15), (120.0, 0.15), (300.0, 0.2),
                                       (1000.0, 0.3), (1500.0, 0.5), (5000.0, 0.5)])
def test_size_tolerance_is_iso_2768_fine(size, tol):
    # ISO 2768-1:1989 table 1, class f
    assert pl.size_tolerance(size) == tol


def test_every_line_beyond_max_offset_is_named_with_a_units_hint():
    d = np.array([0.01, 28.9, -0.02, 47.1, np.nan])
    msgs = pl.offset_errors(d, lines=[4, 5, 6, 7, 8], max_offset=1.0, source="f.csv")
    assert [m.split(":")[1] for m in msgs] == ["5", "7", "8"]
    assert "+28.9000 mm" in msgs[0] and "in um" in msgs[0] and "3 of 5 points" in msgs[0]
    assert pl.offset_errors(d[[0, 2]], max_offset=1.0) == []


def test_long_lists_are_cut_with_a_count():
    msgs = pl.offset_errors(np.full(30, 2.0), max_offset=1.0, limit=20)
    assert len(msgs) == 21 and msgs[-1].startswith("... and 10 more")


def test_units_warning_only_when_every_deviation_is_far_beyond_the_tolerance():
    # a 100 mm face: +-0.15 mm, 100 x = 15 mm
    assert pl.units_warning([16.0, -20.0, 30.0], 100.0) is not None
    assert pl.units_warning([16.0, -0.1, 30.0], 100.0) is None
    assert pl.units_warning([0.03, -0.02], 100.0) is None
    assert "+-0.15 mm" in pl.units_warning([16.0], 100.0)
    # the other way: deviations in mm read as um (all below 0.5 um)
    tiny = pl.units_warning([4.7e-5, -2.9e-5, 1e-6], 100.0)
    assert tiny.startswith("every deviation is below 0.5 um (largest 0.047 um)")
    assert "deviations in mm read as um?" in tiny
    assert pl.units_warning([4.7e-5, -6e-4, 1e-6], 100.0) is None


def test_largest_dimension_and_ranges_ignore_nan():
    p = np.array([[0, 0, 0], [100, 20, 5], [np.nan, 1e9, 0]], dtype=float)
    assert pl.largest_dimension(p) == 100.0
    assert pl.value_ranges({"a": [1.0, np.nan, -2.0], "b": None}) == {"a": (-2.0, 1.0)}


def test_prepare_warns_when_every_deviation_is_far_beyond_the_size_tolerance():
    """The command line's report carries the warning (prepare's warnings)."""
    from surfcomp.core.compensation.pipeline import Options, prepare
    from surfcomp.core.surface.bspline import Surface
    from surfcomp.io.measurements import MeasurementSet

    # a flat 100 x 100 mm face: size tolerance +-0.15 mm, flagged beyond 15 mm
    P = np.array([[[0, 0, 0], [0, 100, 0]], [[100, 0, 0], [100, 100, 0]]], dtype=float)
    surf = Surface(P, np.r_[0, 0, 1, 1.], np.r_[0, 0, 1, 1.], 1, 1)
    g = np.linspace(10, 90, 5)
    X, Y = np.meshgrid(g, g, indexing="ij")
    nom = np.stack([X.ravel(), Y.ravel(), np.zeros(25)], axis=1)
    nrm = np.tile([0.0, 0.0, 1.0], (25, 1))
    opts = Options(method="raw", max_offset=50.0)

    def warnings(dev):
        ms = MeasurementSet(nominal=nom, normal=nrm, deviation=np.full(25, dev),
                            lines=np.arange(25) + 2, source="f.csv")
        return [w for w in prepare(surf, 1, ms, opts).warnings if "size tolerance" in w]

    assert len(warnings(20.0)) == 1 and "f.csv: every deviation" in warnings(20.0)[0]
    assert warnings(0.02) == []


def _flat_face_and_points(scale, corner=(10.0, 10.0), size=80.0, n=9):
    """A flat 100 x 100 mm face (z = 1 mm), and an n x n grid of points on it over ``size``
    mm from ``corner``, divided by ``scale`` (a file in another unit read as mm)."""
    from surfcomp.core.surface.bspline import Surface

    P = np.array([[[0, 0, 1], [0, 100, 1]], [[100, 0, 1], [100, 100, 1]]], dtype=float)
    surf = Surface(P, np.r_[0, 0, 1, 1.], np.r_[0, 0, 1, 1.], 1, 1)
    g0, g1 = np.linspace(corner[0], corner[0] + size, n), np.linspace(corner[1],
                                                                       corner[1] + size, n)
    X, Y = np.meshgrid(g0, g1, indexing="ij")
    pts = np.stack([X.ravel(), Y.ravel(), np.full(n * n, 1.002)], axis=1) / scale
    return surf, pts


@pytest.mark.parametrize("scale, unit", [(25.4, "in"), (10.0, "cm"), (1000.0, "m")])
def test_points_in_another_length_unit_are_refused_naming_it(scale, unit):
    """Points in inches, cm or m read as mm land in a corner of a face near the origin, and
    still within max offset of it: multiplied back they lie on the face."""
    from surfcomp.core.compensation.pipeline import Options, prepare
    from surfcomp.errors import InputError
    from surfcomp.io.measurements import MeasurementSet

    surf, pts = _flat_face_and_points(scale)
    ms = MeasurementSet(measured=pts, lines=np.arange(len(pts)) + 2, source="f.csv")
    with pytest.raises(InputError, match=r"f.csv: the 81 points span .* mm where the face "
                                         r"spans 141.4 mm, and multiplied by %g they lie on "
                                         r"it: .*'x \[%s\]'" % (scale, unit)):
        prepare(surf, 1, ms, Options(method="raw"))
    # read in their unit, they are taken
    ms = MeasurementSet(measured=pts * scale, lines=np.arange(len(pts)) + 2, source="f.csv")
    assert prepare(surf, 1, ms, Options(method="raw")).deviation.size == 81


def test_a_table_in_another_unit_is_pointed_to_its_nominal_column():
    """A table's nominal points in metres: the hint named 'x [m]', which a table refuses (x
    alone: nominal or measured?); it names 'x_nom [m]'."""
    from surfcomp.core.compensation.pipeline import Options, prepare
    from surfcomp.errors import InputError
    from surfcomp.io.measurements import MeasurementSet

    surf, pts = _flat_face_and_points(1000.0)
    ms = MeasurementSet(nominal=pts, normal=np.tile([0.0, 0.0, 1.0], (len(pts), 1)),
                        deviation=np.zeros(len(pts)), lines=np.arange(len(pts)) + 2,
                        source="f.csv")
    with pytest.raises(InputError, match=r"not mm \(give the unit: a column name like "
                                         r"'x_nom \[m\]'\)$"):
        prepare(surf, 1, ms, Options(method="raw"))


@pytest.mark.parametrize("corner, size", [((0.0, 0.0), 5.0), ((60.0, 30.0), 5.0),
                                          ((0.2, 0.2), 0.5)])
def test_a_small_patch_measured_in_mm_is_no_unit_mistake(corner, size):
    """A patch under a tenth of the face: scaled by 25.4, 10 or 1000 it would leave the face
    or still cover a corner, so it is no unit mistake."""
    from surfcomp.core.compensation.pipeline import project
    from surfcomp.core.surface.bspline import Surface  # noqa: F401

    surf, pts = _flat_face_and_points(1.0, corner, size, n=5)
    assert pl.unit_mistake(surf, pts, 1.0, project) is None


@pytest.mark.parametrize("mask, warned", [(5, False), (7, True)])
def test_a_mask_larger_than_the_grid_is_warned_about(mask, warned):
    """A 7 x 7 mask over a 5 x 5 grid leaves the determined part nearly the grid's mean."""
    from surfcomp.core.compensation.pipeline import Options, compensate, prepare
    from surfcomp.io.measurements import MeasurementSet

    surf, pts = _flat_face_and_points(1.0, n=5)
    nrm = np.tile([0.0, 0.0, 1.0], (25, 1))
    pts[:, 2] = 1.0
    dev = 0.01 * np.sin(pts[:, 0] / 20.0)
    ms = MeasurementSet(nominal=pts, normal=nrm, deviation=dev, lines=np.arange(25) + 2,
                        source="f.csv")
    opts = Options(mask_size=mask)
    prepared = prepare(surf, 1, ms, opts)
    compensate(surf, 1, prepared, opts, build=False)
    found = [w for w in prepared.warnings if "mask is larger" in str(w)]
    assert found == (["f.csv: the 7 x 7 mask is larger than the 5 x 5 grid, the determined "
                      "part is nearly the mean: a smaller mask_size keeps its shape"]
                     if warned else [])


def test_points_in_a_tiny_patch_are_refused_before_a_huge_face_is_sampled():
    """60 points within 0.05 mm on a 100 mm face would need a corrected face of 38137 x
    38137 poles: refused with what it needs (before: a 43 GiB allocation, an internal
    error)."""
    from surfcomp.core.compensation.pipeline import Options, compensate, prepare
    from surfcomp.errors import InputError
    from surfcomp.io.measurements import MeasurementSet

    surf, _pts = _flat_face_and_points(1.0)
    xy = 40 + np.random.default_rng(1).uniform(0, 0.05, (60, 2))
    ms = MeasurementSet(nominal=np.column_stack([xy, np.ones(60)]),
                        normal=np.tile([0, 0, 1.0], (60, 1)), deviation=0.01 * np.sin(xy[:, 0]),
                        lines=np.arange(60) + 2, source="f.csv")
    prepared = prepare(surf, 1, ms, Options())
    with pytest.raises(InputError, match=r"needs a corrected face of 38137 x 38137 poles \(at "
                                         r"most 9000000 in all\): the points cover a tiny part"):
        compensate(surf, 1, prepared, Options())
