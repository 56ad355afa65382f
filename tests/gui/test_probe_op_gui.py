# SPDX-License-Identifier: LGPL-2.1-or-later
"""Add probe plan to Job in the real FreeCAD GUI (under Xvfb): on the shop document a 5 x 4
plan made with the Plan measurement panel becomes, by a click on the toolbar button, an
operation under the Job's Operations with 20 probe moves; the Job's post writes them; one
undo step removes it."""

import pytest

from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gui_probeop")
    res = run_session("probeop", tmp)
    res["tmp"] = tmp
    return res


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["errors_at_end"] == []


def test_command_needs_a_plan(session):
    assert session["active_without_plan"] is False and session["active_with_plan"] is True
    text, accepted, kept = session["plan"]
    assert accepted is True and kept == 20 and text.startswith("20 of 20 points kept")


def test_the_button_adds_the_operation_to_the_job(session):
    assert session["buttons"] >= 1 and session["button_enabled"] is True
    assert session["command_errors"] == []
    count, probes, g38, state, added, tool = session["op"]
    assert (count, probes, g38, tool) == (1, 20, 20, 99)
    assert "Invalid" not in state and "Touched" not in state
    # the operation, its tool controller and bit (on 1.1 with the bit's shape objects)
    assert added >= 3
    assert session["bit_hidden"] == [False]
    (mine,), (first,), folder = session["tree"]
    assert mine == first and mine[0] == folder == "Operations"
    assert session["posted_probes"] == 20
    assert "ProbePlan: 20 probe moves added to Job" in session["status"]


def test_probe_moves_drawn(session):
    assert session["op_view"] == ["ViewProviderProbeOperation", "Waypoints"]
    shown = read_image(session["tmp"] / "probeop.png")
    hidden = read_image(session["tmp"] / "probeop_hidden.png")
    # the moves' lines (their colours differ between versions): the pixels that change when
    # the operation is hidden; all 20 probe moves drawn: 2207 (0.20), 2208 (1.0), 3159 to
    # 3163 (1.1) pixels; pictures taken while FreeCAD 1.1 still animated the camera showed
    # only parts of the moves, 683 to 1207 pixels
    changed = int((abs(shown - hidden).sum(axis=2) > 0.3).sum())
    assert changed > 1800, changed


def test_a_headless_operation_is_drawn_when_opened(session):
    assert session["headless_made"][0] == 0, session["headless_made"]
    assert session["headless_view"] == ["ViewProviderProbeOperation", "Waypoints", 9]


def test_one_undo_step(session):
    assert session["after_undo"] == [0, []]
