# SPDX-License-Identifier: LGPL-2.1-or-later
"""Every line of the workbench's longest messages shows where the user reads it, in the real
FreeCAD GUI (under Xvfb), driven by key and mouse events: the import preview's error of three
lines (its file, line and position) above the file's text, not pushing it under the buttons;
the filter panel's error after a shorter one; the alignment's and the plan's errors in their
panels' result boxes; the refused stock and the report's note in their dialogs."""

import pytest

from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gui_messages")
    res = run_session("messages", tmp)
    res["tmp"] = tmp
    return res


def shows(place):
    """The widget is as high as its text needs, and its text lies inside what the user
    sees (a text box's lines, which may end above the box's bottom)."""
    return (place["top"] >= 0 and place["top"] + place["need"] <= place["room"]
            and place["height"] >= place["need"])


def whole(box):
    """A result box shows its whole text: every line without scrolling, or a scroll bar."""
    return box["scroll"] == 0 or box["bar"]


def red_pixels(path):
    img = read_image(path)
    return int(((img[..., 0] > 0.6) & (img[..., 1] < 0.35) & (img[..., 2] < 0.35)).sum())


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert "Traceback" not in session["report_view"]


def test_import_error_above_the_text_not_under_the_buttons(session):
    s = session["preview"]
    assert s["ok"]["text"] == "2025 points, no errors" and s["ok"]["scroll"] == 0
    assert s["units"] == "in"
    # the first error, with its file and line, is the status line's whole text
    first = s["errors"][0]
    assert s["bad"]["text"] == "Cannot import: " + first
    assert "measurements.csv:" in first and " mm from the face (expected at most" in first
    # the box has room for its three lines: no scrolling
    assert s["bad"]["scroll"] == 0
    status, text, buttons = s["places"]
    # the dialog keeps its size; the status, the file's text and the buttons do not overlap
    assert s["size_after"] == s["size"]
    # (the file's text scrolls: it is longer than its box)
    assert shows(status) and shows(buttons) and text["need"] > text["height"]
    assert status["bottom"] <= text["top"] and text["bottom"] <= buttons["top"]
    assert red_pixels(s["png"]) > 200


def test_filter_error_grows_in_the_panel(session):
    s = session["filter"]
    assert s["short"] == "mask weights row 1 '1 2 x' is not a list of numbers " \
        "(expected rows like '1 2 1; 2 4 2; 1 2 1')"
    assert s["long"] == "mask weights '1 2 1; 2 4 2 4 2 4; 1 2 1 0 0 0 0; 3 3 3 3 3 3 3 3 " \
        "3; 7 7' are not square: 5 rows of lengths [3, 6, 7, 9, 2] (expected n rows of n " \
        "numbers, n odd)"
    figures, status = s["places"]
    assert shows(figures) and shows(status), s["places"]
    assert status["need"] > figures["need"] / 2
    assert red_pixels(s["png"]) > 100


def test_alignment_error_in_the_result_box(session):
    s = session["align"]
    assert s["method"] == "rps"
    text = s["box"]["text"]
    assert text.startswith("measurements.csv: ") and text.endswith(
        "(expected a point file of measured points only)")
    assert whole(s["box"]) and shows(s["place"]), s
    assert red_pixels(s["png"]) > 200


def test_plan_error_in_the_result_box(session):
    s = session["plan"]
    text = s["box"]["text"]
    assert text.startswith("Tip radius 60 mm is larger than the face's smallest concave "
                           "radius 55.83 mm (at ") and text.endswith(
        "(expected a tip radius of at most 55.83 mm)")
    assert whole(s["box"]) and s["box"]["scroll"] == 0 and shows(s["place"]), s
    assert red_pixels(s["png"]) > 200


def test_refused_stock_shows_whole(session):
    s = session["stock"]
    assert s["visible"] is True
    assert s["text"].startswith("Refused: the stock does not fit the measured deviations. "
                                "Measured mean deviation 15.7 µm") and s["text"].endswith(
        "(the larger of stock/2 and 3 x the spread).")
    label, buttons = s["places"]
    assert shows(label) and shows(buttons) and label["bottom"] <= buttons["top"]


def test_report_note_shows_whole(session):
    s = session["report"]
    assert s["text"].startswith("Predicted residual: the mirror method's predicted residual")
    table, note = s["places"]
    assert shows(table) and shows(note) and table["bottom"] <= note["top"]


def test_stock_drawing_labels_apart(session):
    s = session["stock"]
    width, height, spacing = s["drawing"]
    labels = s["labels"]
    assert sorted(t for t, _x, _y in labels) == ["corrected face", "measured (d)", "nominal",
                                                 "nominal + stock"]
    ys = sorted(y for _t, _x, y in labels)
    # a line apart (measured and corrected end closer than a line on the curves), inside
    # the drawing
    assert min(b - a for a, b in zip(ys[:-1], ys[1:])) >= spacing - 1e-9
    assert spacing <= ys[0] and ys[-1] <= height
    assert all(0 < x < width - 60 for _t, x, _y in labels)
