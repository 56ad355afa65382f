# SPDX-License-Identifier: LGPL-2.1-or-later
"""The statistics' words: ``max_negative`` is the largest deviation below the nominal (0.0
when none is below), ``max_positive`` the largest above (0.0 when none is above), ``min``
and ``max`` the extremes whatever their signs; the JSON keys only ever grow."""

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.compensation.deviations import Statistics, statistics

#: the JSON report's statistics keys before ``min`` and ``max`` were added: a contract
KEYS_BEFORE = ("count", "max_negative", "max_positive", "mean", "std", "rms", "profile")


def test_an_all_positive_set_has_no_negative_deviation():
    """The issue's case: every point above the nominal. max_negative printed the smallest
    value (3.2 um) as if it were a negative deviation."""
    st = statistics([0.0032, 0.0100, 0.0471])
    assert st.max_negative == 0.0
    assert st.max_positive == pytest.approx(0.0471, abs=1e-15)
    assert (st.min, st.max) == (pytest.approx(0.0032, abs=1e-15), pytest.approx(0.0471, abs=1e-15))
    assert st.profile == pytest.approx(2 * 0.0471, abs=1e-15)


def test_an_all_negative_set_has_no_positive_deviation():
    st = statistics([-0.03, -0.02, -0.005])
    assert st.max_positive == 0.0
    assert st.max_negative == pytest.approx(-0.03, abs=1e-15)
    assert (st.min, st.max) == (pytest.approx(-0.03, abs=1e-15), pytest.approx(-0.005, abs=1e-15))


def test_a_mixed_set_keeps_the_extremes_and_nan_is_ignored():
    st = statistics([[-0.03, np.nan], [0.045, 0.01]])
    assert st.count == 3
    assert (st.max_negative, st.min) == (pytest.approx(-0.03, abs=1e-15),) * 2
    assert (st.max_positive, st.max) == (pytest.approx(0.045, abs=1e-15),) * 2
    assert st.mean == pytest.approx(0.025 / 3, abs=1e-15)


def test_the_json_keys_only_grow_and_round_trip():
    st = statistics([0.0032, 0.0100, 0.0471])
    d = json.loads(json.dumps(st.as_dict()))
    assert tuple(d)[:len(KEYS_BEFORE)] == KEYS_BEFORE
    assert set(d) == set(KEYS_BEFORE) | {"min", "max"}
    assert Statistics.from_dict(d) == st


def test_a_dict_from_before_min_and_max_reads_with_the_meaning_of_today():
    """A document's or report's statistics written before: max_negative was min()."""
    old = {"count": 3, "max_negative": 0.0032, "max_positive": 0.0471, "mean": 0.0201,
           "std": 0.023, "rms": 0.028, "profile": 0.0942}
    st = Statistics.from_dict(old)
    assert (st.min, st.max) == (0.0032, 0.0471)
    assert (st.max_negative, st.max_positive) == (0.0, 0.0471)
    assert_allclose([st.mean, st.std, st.rms, st.profile], [0.0201, 0.023, 0.028, 0.0942],
                    rtol=0, atol=0)


def test_a_side_without_deviations_is_shown_as_none_not_as_zero():
    """The tables showed "Max. negative 0.00" for an all-positive set, as if a point lay
    on the nominal; the smallest deviation was +171.1 um. The table, the HTML report and the
    GUI panel now say "none" (the JSON keeps 0.0 and gives ``min``)."""
    from surfcomp.core.compensation.deviations import format_table
    from surfcomp.io.html_report import _stat_table

    up, down = statistics([0.1711, 0.2, 0.25]), statistics([-0.03, -0.005])
    assert [r[1] for r in up.rows("um")[1:3]] == [None, pytest.approx(250.0)]
    assert [r[1] for r in down.rows("um")[1:3]] == [pytest.approx(-30.0), None]
    table = format_table([("up", up), ("down", down)]).splitlines()
    assert table[2].split() == ["Max.", "negative", "none", "-30.00"]
    assert table[3].split() == ["Max.", "positive", "250.00", "none"]
    html = _stat_table([("up", up.as_dict()), ("down", down.as_dict())])
    assert ('<tr><th>Max. negative</th><td class="num">none</td><td class="num">-30.00</td>'
            in html)
    assert ('<tr><th>Max. positive</th><td class="num">250.00</td><td class="num">none</td>'
            in html)
    mixed = statistics([-0.001, 0.002])
    assert [r[1] for r in mixed.rows("mm")[1:3]] == [pytest.approx(-0.001), pytest.approx(0.002)]
