# SPDX-License-Identifier: LGPL-2.1-or-later
"""The mirror method's stock against the measured mean (issue 24, item 4): a part measured
after semi-finishing with stock s has deviations d = s + e (surfcomp's sign convention,
Huang et al. 2019 Sec. 2.4), so its mean lies near s; a stock that does not fit is refused
unless confirmed, and the predicted residual says what it assumes."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.cli.option_flags import flag
from surfcomp.core.compensation import plausibility as pl
from surfcomp.core.compensation.pipeline import Options, compensate, prepare
from surfcomp.core.measurement_set import MeasurementSet
from surfcomp.core.surface import bspline
from surfcomp.errors import InputError
from tests.pure.surfaces import wavy_patch

#: mirror paper Tab. 3, mirror compensation "before" (semi-finished parts, stock 0.2 mm,
#: Sec. 2.6): mean and standard deviation of the error beyond the stock (um), 280, 196
#: and 272 errors
PAPER_SEMI_FINISHED = ((15.1, 6.2, 280), (17.2, 3.8, 196), (16.8, 3.1, 272))


def _errors(mean_um, std_um, n, seed=0):
    """n seeded errors with exactly the given mean and sample standard deviation (mm)."""
    e = np.random.default_rng(seed).normal(size=n)
    e = (e - e.mean()) / e.std(ddof=1)
    return 1e-3 * (mean_um + std_um * e)


@pytest.mark.parametrize("mean_um, std_um, n", PAPER_SEMI_FINISHED)
def test_the_papers_semi_finished_parts_fit_their_stock(mean_um, std_um, n):
    d = 0.2 + _errors(mean_um, std_um, n)
    c = pl.stock_check(d, 0.2)
    assert c.consistent
    assert_allclose([c.mean, c.spread], [0.2 + 1e-3 * mean_um, 1e-3 * std_um], atol=1e-12)
    assert_allclose(c.tolerance, 0.1, atol=1e-15)   # stock/2 beats 3 x 6.2 um
    # the rule read as |mean - s/2| <= 3 spreads would refuse every one of them: the mean of
    # a right stock is s/2 + mean(e) away from the mirror surface
    assert abs(c.mean - 0.1) > 3 * c.spread


def test_the_issues_finished_part_does_not_fit_the_default_stock():
    """The example's measurement (a finished part): mean 15.7 um, spread 19.1 um. With the
    default stock 0.1 mm the face would move out by up to 0.13 mm."""
    d = _errors(15.67, 19.08, 2025)
    c = pl.stock_check(d, 0.1)
    assert not c.consistent
    assert_allclose(c.tolerance, 3 * 0.01908, atol=1e-12)      # 3 spreads beat stock/2
    text = c.describe()
    assert "measured mean deviation 15.7 um (spread 19.1 um)" in text
    assert "a mean of 0.1 mm +- 57.2 um" in text
    # |mean - s/2| = 34 um < 3 x 19.1 um: the issue's literal rule would have accepted it
    assert abs(c.mean - 0.05) < 3 * c.spread
    # the same part with no stock (mirror = raw) or a stock within its scatter is fine
    assert pl.stock_check(d, 0.0).consistent and pl.stock_check(d, 0.05).consistent


def test_a_stock_smaller_than_the_part_carries_is_refused_too():
    d = 0.3 + _errors(5.0, 4.0, 100)         # semi-finished with 0.3 mm, stated 0.1 mm
    assert not pl.stock_check(d, 0.1).consistent
    assert pl.stock_check(d, 0.3).consistent
    assert pl.stock_check(d, 0.25).consistent       # within stock/2 = 0.125 mm


def test_the_border_of_the_rule():
    # constant deviations: spread 0, the tolerance is stock/2 exactly
    assert pl.stock_check(np.full(9, 0.05), 0.1).consistent          # |0.05 - 0.1| = 0.05
    assert not pl.stock_check(np.full(9, 0.0499), 0.1).consistent
    assert not pl.stock_check(np.full(9, 0.1501), 0.1).consistent
    # NaN (unmeasured nodes) are left out; nothing measured: nothing to refuse
    c = pl.stock_check([0.1, np.nan, 0.1], 0.1)
    assert c.consistent and c.mean == 0.1 and c.spread == 0.0
    assert pl.stock_check([np.nan], 0.1).consistent


def test_the_residual_says_what_it_assumes():
    text = pl.residual_assumption("mirror", 0.1)
    assert "carries the stock 0.1 mm" in text and "d = stock + e" in text
    assert "-(the random part) whatever the stock" in text
    assert pl.residual_assumption("filtered", 0.1) == ""


def _prepared(d, n):
    surf = wavy_patch()
    us = np.linspace(0.02, 0.98, n)
    S, Su, Sv = bspline.evaluate_grid(surf, us, us, order=1)
    nrm = np.cross(Su, Sv)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    rows, cols = np.indices((n, n))
    ms = MeasurementSet(nominal=S.reshape(-1, 3), normal=nrm.reshape(-1, 3),
                        deviation=d.ravel(), row=rows.ravel(), col=cols.ravel())
    return surf, prepare(surf, 1, ms, Options(method="mirror", stock=0.1))


def test_compensate_refuses_naming_the_option_and_the_mean():
    n = 9
    d = _errors(15.7, 5.0, n * n).reshape(n, n)       # a finished part
    surf, prep = _prepared(d, n)
    with pytest.raises(InputError) as err:
        compensate(surf, 1, prep, Options(method="mirror", stock=0.1), build=False)
    msg = str(err.value)
    assert "the stock 0.1 mm (Stock in the document)" in msg
    assert "measured mean deviation 15.7 um" in msg
    assert "use this one anyway with accept_stock (StockOk = true in the document)" in msg
    # the command line names the option by its flag
    assert "with --accept-stock (StockOk" in err.value.shown(flag)
    # confirmed: used as given, delta = d - s (mirror paper eq. 1-2)
    comp = compensate(surf, 1, prep, Options(method="mirror", stock=0.1, accept_stock=True),
                      build=False)
    assert_allclose(comp.correction.delta, d - 0.1, atol=1e-15)
    # other methods never look at the stock
    compensate(surf, 1, prep, Options(method="filtered", stock=0.1), build=False)


def test_accept_stock_is_a_boolean():
    with pytest.raises(InputError, match=r"accept_stock 'yes': expected true or false "
                                         r"\(StockOk in the document\)"):
        Options(method="mirror", stock=0.1, accept_stock="yes").validate()
