# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Plan measurement command in the real FreeCAD GUI (under Xvfb): active on a selected
face, its task panel planning the example face (grid, the points a small max tilt drops
named by the field's label, then adaptive chosen with the keys),
the points drawn in the 3D view, a tip too large for the face refused in the panel, OK as one
undo step, Cancel leaving nothing."""

import os
import subprocess
import sys

import pytest

from tests.conftest import ROOT
from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gui_plan")
    res = run_session("plan", tmp)
    res["tmp"] = tmp
    return res


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["errors_at_end"] == []
    assert "Traceback" not in session["report_view_end"]


def test_command_needs_a_face(session):
    assert session["active_no_face"] is False and session["active_face"] is True


def test_panel_plans_the_default_grid(session):
    text, layout, kept, placed, vertices, points_enabled = session["default"]
    assert (layout, kept, placed, vertices) == ("grid", 100, 100, 100)
    assert text.startswith("100 of 100 points kept; travel ") and points_enabled is False


def test_safe_z_as_the_command_line_says(session, tmp_path):
    """The panel's safe Z is the command line's for the same face and fields: the drawn
    face's display mesh once widened the part's top to 9.99 mm (safe Z 15.993 mm, against
    15.034 mm from ``plan``)."""
    out = subprocess.run([sys.executable, "-m", "surfcomp", "plan",
                          os.path.join(ROOT, "examples", "nominal.step"), "-o",
                          str(tmp_path / "plan.csv")], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout
    (line,) = [t for t in out.splitlines() if t.startswith("Safe Z:")]
    cli = float(line.split()[2])
    assert session["safe_z"] == pytest.approx(cli, abs=5e-5)
    assert session["default"][0].endswith("safe Z %.3f mm" % cli)


def test_adaptive_chosen_with_the_keys(session):
    combo, text, layout, kept, placed, points_on, count_on, first = session["adaptive"]
    assert (combo, layout, kept, placed) == ("adaptive", "adaptive", 60, 60)
    assert points_on is True and count_on is False
    assert text.startswith("60 of 60 points kept")
    # the points lie on the example face (45 x 45 mm, z from 0 to 10 mm)
    assert all(0 < p[0] < 45 and 0 < p[1] < 45 and 0 <= p[2] <= 10 for p in first)


def test_points_drawn_in_the_view(session):
    img = read_image(session["shot"])
    red = (img[..., 0] > 0.6) & (img[..., 1] < 0.3) & (img[..., 2] < 0.3)
    # 60 red points of 6 pixels: at least a few hundred red pixels
    assert red.sum() > 200


def test_dropped_points_name_the_field_in_the_panel(session):
    text, prop, kept, placed, tilt = session["tilt"]
    # the example face's default 10 x 10 grid: 79 points lean more than 15 degrees
    assert (placed, tilt, kept) == (100, 15.0, 21)
    (reason,) = [r for r in prop if "normal leans more than" in r]
    n = int(reason.split(" ")[0])
    assert n == placed - kept                      # only the tilt drops points here
    # the property names the property; the panel the field, as its row is labelled
    assert reason == "%d normal leans more than MaxTilt from +Z" % n
    assert text.endswith("\nDropped: %d normal leans more than Max tilt from +Z" % n)
    assert "MaxTilt" not in text and "max_tilt" not in text
    assert session["bad_labels"][3] == "Max tilt (deg)"
    # the whole message shows in the panel, without scrolling, and not in red (no error)
    assert session["tilt_scroll"] == 0
    img = read_image(session["tilt_png"])
    red = ((abs(img[..., :3] - [197 / 255, 48 / 255, 48 / 255]).sum(axis=2)) < 0.15).sum()
    assert red == 0
    assert session["tilt_back"] == [100, 60.0]


def test_tip_too_large_stays_in_the_panel(session):
    text, accepted, still_open = session["bad"]
    # the option named as the panel's field (the command line says --tip-radius)
    assert "Tip radius 60 mm is larger than the face's smallest concave radius" in text
    assert "tip_radius" not in text
    # the field it names carries that label, and the message shows in red in the panel
    assert session["bad_labels"] == ["Layout", "Points", "Tip radius (mm)", "Max tilt (deg)"]
    img = read_image(session["bad_png"])
    red = ((abs(img[..., :3] - [197 / 255, 48 / 255, 48 / 255]).sum(axis=2)) < 0.15).sum()
    assert red > 50
    assert accepted is False and still_open is True


def test_ok_is_one_undo_step_and_cancel_leaves_nothing(session):
    accepted, closed, kept, tip, added, state = session["ok"]
    assert accepted is True and closed is True and kept == 60 and tip == 1.5
    assert added == 1 and "Invalid" not in state and "Error" not in state
    assert session["after_undo"] == 0
    assert session["cancel"] == [True, True, 0]


def test_a_scripted_plan_shows_its_points(session):
    assert session["scripted"] == [25, "Points", 6.0]
