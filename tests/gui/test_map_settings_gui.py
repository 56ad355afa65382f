# SPDX-License-Identifier: LGPL-2.1-or-later
"""Colour-map settings that cannot be drawn as set, in the real FreeCAD GUI (under Xvfb):
a manual range whose RangeMin is not below RangeMax, a WarnBand typed as a percentage (80
for 0.8), a tolerance band whose TolLow lies above TolHigh. The map is drawn without the
setting and the legend (in red, wrapped to the panel) and the Report view say which one
and why; set right again, the map takes it and the message goes. Before, the range and the
warning band were dropped without a word and the inverted band was a traceback in the
Report view with the legend still showing the previous band."""

import pytest

from tests.gui.harness import read_image, run_session

AUTO = [-0.047134, 0.047134]


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("map_settings", tmp_path_factory.mktemp("gui_map_settings"))


def problems(step):
    return [t for t in step["texts"] if " is drawn" in t]


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["errors_at_end"] == []
    assert "Traceback" not in session["report_view"]


def test_inverted_range_is_said_in_the_legend(session):
    s = session["range_inverted"]
    message = "RangeMin +30.0 µm is not below RangeMax -20.0 µm: the automatic range is drawn"
    assert s["range"] == pytest.approx(AUTO)
    assert problems(s) == [message]
    assert ("Compensation: " + message) in s["report"]
    e = session["range_equal"]
    assert problems(e) == ["RangeMin +20.0 µm is not below RangeMax +20.0 µm: the "
                           "automatic range is drawn"]
    r = session["range_right"]
    assert r["range"] == pytest.approx([-0.02, 0.03]) and problems(r) == []
    assert "< " in " ".join(r["texts"])     # the out-of-range arrows' percentages
    assert problems(session["auto"]) == [] and session["auto"]["report"].strip() == ""


def test_problem_drawn_in_red_inside_the_entry(session):
    path, ratio, blocks, (width, height) = session["shot"]
    (block,) = [b for b in blocks if b[0].startswith("RangeMin")]
    _text, x, y, w, h = block
    assert 0 <= x and x + w <= width and 0 <= y and y + h <= height
    img = read_image(path)
    rows = img[int(y * ratio):int((y + h) * ratio), int(x * ratio):int((x + w) * ratio)]
    red = (rows[..., 0] > 0.4) & (rows[..., 1] < 0.2) & (rows[..., 2] < 0.2)
    assert red.sum() > 50


def test_warn_band_as_percentage_is_said(session):
    assert session["band"]["warning"] == 0.8 and problems(session["band"]) == []
    s = session["warn_percent"]
    message = ("WarnBand 80 is not a fraction between 0 and 1 (0.8: the outer 20 % of the "
               "tolerance warn): no warning band is drawn")
    assert s["warning"] is None and problems(s) == [message]
    assert ("Compensation: " + message) in s["report"]
    assert not any(t.startswith("warn ") for t in s["texts"])
    r = session["warn_right"]
    assert r["warning"] == 0.8 and problems(r) == []
    assert any(t.startswith("warn ") for t in r["texts"])


def test_inverted_band_is_said_not_a_traceback(session):
    s = session["band_inverted"]
    message = "TolLow +20.0 µm is above TolHigh +10.0 µm: no tolerance band is drawn"
    assert s["tolerance"] is None and problems(s) == [message]
    assert ("Compensation: " + message) in s["report"]
    # the legend is the map's as drawn: no band, its title without the band
    assert "Deviation [µm]" in s["texts"]
    assert not any(t.startswith(("below ", "in ", "above ")) for t in s["texts"])
    r = session["band_right"]
    assert r["tolerance"] == pytest.approx((-0.01, 0.01)) and problems(r) == []
    assert "Deviation [µm] - tolerance band" in r["texts"]
