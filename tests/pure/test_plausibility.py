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
