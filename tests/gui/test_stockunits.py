# SPDX-License-Identifier: LGPL-2.1-or-later
"""Issue 24, items 4 and 5, in the real FreeCAD GUI (under Xvfb) with real key and mouse
events on the dialogs: the import preview chooses the coordinates' and the deviation's
units apart and shows points that fall off the nominal face before OK; the Mirror command's
stock dialog refuses the default stock on the finished example (mean 15.7 um), showing the
measured mean, until the stock is confirmed or one that fits is typed."""

import pytest

from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("stockunits", tmp_path_factory.mktemp("gui_stockunits"))


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["errors_at_end"] == []
    assert "Traceback" not in session["report_view_end"]


def test_example_preview_is_checked_against_the_face(session):
    text = session["example_preview"]
    assert "Checked against the nominal face: nominal.Face1" in text
    assert "Problems found: none" in text and "ERRORS" not in text


def test_preview_unit_selectors_are_separate(session):
    s = session["preview_units"]
    text, status, ok = s["mm"]
    assert ok is False and status.startswith("Cannot import:") and "are the deviations in um?" \
        in status
    # deviation in um: coordinates stay in mm (the issue: x_nom became 0.88..44.12 um)
    text, status, ok, coords, dev = s["dev_um"]
    assert (coords, dev, ok) == ("mm", "um", True) and status == "2025 points, no errors"
    assert "coordinates mm, deviation µm" in text
    lines = text.splitlines()
    x_range = next(x for x in lines if x.strip().startswith("nominal x"))
    assert x_range.split()[2:6] == ["0.8822", "..", "44.12", "mm"], x_range
    dev_range = next(x for x in lines if x.strip().startswith("deviation"))
    assert dev_range.split()[1:5] == ["-28.9", "..", "47.1", "µm"], dev_range
    assert "Problems found: none" in text


def test_points_off_the_face_are_shown_in_the_preview(session):
    s = session["preview_units"]
    text, status, ok, coords, dev = s["both_um"]
    assert (coords, dev, ok) == ("um", "um", False)
    assert status.startswith("Cannot import:") and "multiplied by 1000 they lie on" in status
    assert "ERRORS (1)" in text and "deviations_in_um.csv: the 2025 points span 0.06177 mm " \
        "where the face spans 64.27 mm, and multiplied by 1000 they lie on it: the file's " \
        "coordinates are in mm, not um" in text
    assert "nominal x         0.8822 .. 44.12        µm" in text
    assert s["after_ok_click"] == [True, 0]          # the click on OK did nothing
    assert s["back"] == ["2025 points, no errors", True, "mm", "um"]
    img = read_image(s["png"])
    assert img.shape[0] > 300 and img.shape[1] > 700
    # the status line in red above the text: a red pixel row exists
    red = (img[..., 0] > 0.6) & (img[..., 1] < 0.35) & (img[..., 2] < 0.35)
    assert red.sum() > 100


def test_the_accepted_file_keeps_mm_coordinates_and_maps_cleanly(session):
    added, name, units, largest, x_max = session["um_object"]
    assert added == 1 and name.startswith("Measurement")
    assert units == "mm, deviation um" and largest < 0.05 and abs(x_max - 44.1178) < 1e-3
    state, errors, vs_example = session["um_map"]
    assert "Invalid" not in state and errors == []
    assert vs_example <= 5e-5 + 1e-12    # the mm file's deviations, rounded to 0.1 um


def test_a_map_of_points_off_the_face_has_no_traceback(session):
    errors, unchanged, report = session["bad_map"]
    (title, message), = errors
    assert title == "SurfComp: Deviation map" and unchanged is True
    assert message.startswith("Measurement") and "deviations_in_um.csv: the 2025 points " \
        "span 0.06177 mm where the face spans 64.27 mm, and multiplied by 1000 they lie on it: " \
        "the file's coordinates are in mm, not um" in message
    # nothing recomputed: no traceback, no "Recompute failed" (the dialog recorder stands in
    # for the message box and its Report view line)
    assert "Traceback" not in report and "Recompute failed" not in report


def test_mirror_refuses_the_default_stock_with_the_measured_mean(session):
    s = session["stock"]
    value, text, confirm = s["initial"]
    assert value == 0.1 and confirm is False
    assert text.startswith("The stock does not fit the measured deviations. Measured mean "
                           "deviation 15.7 µm (spread 19.1 µm)")
    visible, text, confirm, label = s["refused"]
    assert visible is True and confirm is True and label == "Use this stock anyway"
    assert text.startswith("Refused:") and "15.7 µm" in text and "0.1 mm ± 57.2 µm" in text
    img = read_image(s["png"])
    red = (img[..., 0] > 0.6) & (img[..., 1] < 0.35) & (img[..., 2] < 0.35)
    assert red.sum() > 100
    method, stock, accept, state, errors, delta = s["confirmed"]
    assert (method, stock, accept, errors) == ("mirror", 0.1, True, [])
    assert "Invalid" not in state and delta < 1e-12
    assert "carries the stock 0.1 mm" in s["report_assumes"]


def test_mirror_stock_that_fits_needs_no_confirmation(session):
    s = session["stock"]
    value, text, confirm = s["typed"]
    assert abs(value - 0.02) < 1e-12 and confirm is False
    assert text.startswith("The stock fits the measured deviations")
    method, stock, accept, state, errors, delta = s["fitting"]
    assert (method, accept, errors) == ("mirror", False, []) and abs(stock - 0.02) < 1e-12
    assert "Invalid" not in state and delta < 1e-12


def test_mirror_refused_stock_cancelled_leaves_the_object(session):
    s = session["stock"]
    visible, value, text = s["refused_03"]
    assert visible is True and abs(value - 0.3) < 1e-12 and text.startswith("Refused:")
    assert s["retyped"] == [False]
    method, stock, accept, state, errors, delta = s["cancelled"]
    assert (method, accept, errors) == ("mirror", False, []) and abs(stock - 0.02) < 1e-12
