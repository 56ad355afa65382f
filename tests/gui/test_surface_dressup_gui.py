# SPDX-License-Identifier: LGPL-2.1-or-later
"""Add surface correction to operation in the real FreeCAD GUI (under Xvfb): on a Job with
a finishing operation on the example face (6 mm ball end mill) and a filtered compensation,
a wrong selection and a Job that already machines the compensation are refused with what to
do and nothing added; with the operation and the compensation selected, a click on the
toolbar button puts the "Surface correction" dressup in the operation's place, moving its
480 moves by up to the correction's largest value; one undo step removes it."""

import pytest

from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gui_surfdressup")
    res = run_session("surfdressup", tmp, timeout=600)
    res["tmp"] = tmp
    return res


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["made"][0] == 0, session["made"]


def test_a_wrong_selection_is_refused(session):
    assert session["active"] is True
    for key in ("nothing_selected", "job_selected", "model_selected"):
        (message,), added = session[key]
        assert added == 0
        assert "select the finishing operation of a CAM Job" in message, (key, message)


def test_a_job_machining_the_compensation_is_refused(session):
    assert session["replaced_model"] and session["replaced_model"][0].startswith("Compensation")
    (message,), added = session["after_replace"]
    assert added == 0
    assert "is already the compensation" in message and "Restore nominal" in message
    assert session["restored_model"] == ["Nominal"]


def test_the_button_adds_the_dressup(session):
    assert session["buttons"] >= 1 and session["button_enabled"] is True
    assert session["command_errors"] == []
    d = session["dressup"]
    assert d is not None
    assert d["added"] == 1 and "Invalid" not in d["state"] and "Touched" not in d["state"]
    assert d["base"] == "Finish" and d["compensation"].startswith("Compensation")
    assert d["radius"] == pytest.approx(3.0, abs=1e-9)
    # every feed move rides the face: all 480 are moved and touch it; the largest move is
    # the correction's largest on the face (44.71 um on the example, filtered) or below
    assert d["moved"] == 480 and d["contact"] == 480
    assert 0.030 < d["max_move"] <= 0.04472
    assert d["commands"] >= session["op_commands"]
    assert session["ops_before"] == ["Finish"]
    assert d["ops"] == ["DressupSurfaceCorrection"] and d["base_hidden"] is True
    assert d["op_kept"] is True
    assert "480 moves of Finish moved by up to" in session["status"]
    assert "post the Job to write the program" in session["report_tail"]


def test_the_moved_path_is_drawn(session):
    shown = read_image(session["tmp"] / "surfdressup.png")
    hidden = read_image(session["tmp"] / "surfdressup_hidden.png")
    # the path's lines: the pixels that change when the dressup is hidden
    changed = int((abs(shown - hidden).sum(axis=2) > 0.3).sum())
    assert changed > 2000, changed


def test_one_undo_step(session):
    assert session["after_undo"] == [0, ["Finish"]]
    assert session["errors_at_end"] == []
