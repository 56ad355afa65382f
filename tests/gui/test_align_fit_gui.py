# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Align measurements panel fits FreeCAD's task view: in a 1600x1200 and a 1280x800 main
window its result box (the alignment report) and its Apply button lie in the visible part of
the task view as it opens, without scrolling (on FreeCAD 1.1 the panel was taller than the
task view and the result box needed scrolling to)."""

import pytest

from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("align_fit", tmp_path_factory.mktemp("gui_align_fit"))


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["errors_at_end"] == []
    assert session["enabled"] is True and session["closed"] is True
    method, text = session["applied"]
    assert method == "bestfit" and "converged" in text


@pytest.mark.parametrize("size", ["1600x1200", "1280x800"])
def test_result_box_is_visible_without_scrolling(session, size):
    s = session["sizes"][size]
    assert s["window"] == [int(v) for v in size.split("x")]
    assert s["scrolled"] == [0, 0]
    for name in ("result", "apply"):
        x, y, w, h, view_w, view_h = s[name]
        assert 0 <= x and x + w <= view_w, (name, s)
        assert 0 <= y and y + h <= view_h, (name, s)
    # the panel has the height its layout needs (nothing drawn over anything else), and the
    # task view has nothing to scroll to
    assert s["form"][1] >= s["form_least"], s
    assert s["view_scroll"] == 0, s
    # the options are all shown when there is room (at 1600x1200 everywhere; at 1280x800 on
    # FreeCAD 1.0, whose task view is 626 px there), else they scroll in their own area,
    # which takes the room there is (0.20: 405 px beside the report view; 1.1: 385 px)
    shown, needed = s["options"]
    assert 100 <= shown <= needed
    if size == "1600x1200":
        assert shown == needed
    if shown < needed:
        x, y, w, h, view_w, view_h = s["result"]
        assert y + h >= view_h - 40, s
    # the result box shows several lines of the report (not squeezed to nothing)
    assert s["result"][3] >= 100
    # the screenshot is the window (in device pixels: FreeCAD may scale the interface)
    h, w, _ = read_image(s["shot"]).shape
    assert abs(w - s["window"][0] * s["ratio"]) <= 1 and abs(h - s["window"][1] * s["ratio"]) <= 1
