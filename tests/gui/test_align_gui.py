# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Align measurements command in the real FreeCAD GUI (under Xvfb), on a document opened
from disk whose points were measured after re-clamping (0.3 deg, 50 um): a transform file
gives the deviations of the unmoved points back, a best fit with chosen degrees of freedom
reports what it absorbed, a collinear 3-2-1 set stays in the panel, OK is one undo step,
Cancel leaves nothing."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.measurement import align
from tests.gui.harness import read_image, run_session

SETUP = align.work_offset([0.04, -0.03, 0.05], 0.3)


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gui_align")
    res = run_session("align", tmp)
    res["tmp"] = tmp
    return res


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["errors_at_end"] == []
    assert "Traceback" not in session["report_view_end"]


def test_command_needs_one_compensation(session):
    assert session["active_two_compensations"] is False and session["active_selected"] is True
    state, matrix, off = session["before"]
    assert "Invalid" not in state and matrix == [] and off > 0.01   # the setup error

    opened, method, transform, text, rps_on, dof_on = session["opened"]
    assert opened and method == "none" and transform == "none"
    assert text.startswith("No alignment") and rps_on is False and dof_on is False


def test_transform_file_gives_the_unmoved_deviations(session):
    assert session["transform_text"].startswith("translation ")
    text, stored, matrix, off = session["transform"]
    assert_allclose(stored, np.linalg.inv(SETUP).ravel(), atol=1e-12)
    assert_allclose(matrix, np.linalg.inv(SETUP).ravel(), atol=1e-12)
    assert off < 1e-4
    assert text.startswith("Alignment:    none (with the known transform)")


def test_best_fit_with_chosen_freedoms_shows_what_it_absorbed(session):
    method, text, stored, dof, alignment, warnings = session["bestfit"]
    assert (method, stored, dof) == ("bestfit", "bestfit", "z,rx,ry")
    assert "degrees of freedom z rx ry" in text and "converged" in text
    assert "absorbed on the compensated face: mean offset" in text
    assert text.splitlines()[0] == alignment[0]
    assert any("absorbed a mean offset" in w for w in warnings)


def test_map_and_panel_on_screen(session):
    img = read_image(session["view_shot"])
    # the compensation's map is drawn in the 3D view: saturated colours
    sat = img.max(axis=2) - img.min(axis=2)
    assert (sat > 0.5).sum() > 5000
    h, w, _ = read_image(session["shot"]).shape
    assert w > 800 and h > 600
    form, viewport, scrollbar = session["fits"]
    assert form <= viewport and scrollbar is False


def test_collinear_rps_stays_in_the_panel(session):
    method, text, stored, rps, accepted, still_open, state = session["bad"]
    assert method == "rps" and "collinear" in text
    assert stored == "bestfit" and rps == "" and accepted is False and still_open is True
    assert "Invalid" not in state
    assert session["rps_file"] == "1,40,2000;5,30;1000"
    assert session["faces"] == "Face1"


def test_ok_is_one_undo_step_and_cancel_leaves_nothing(session):
    method, accepted, closed, stored, faces, dof, matrix, state = session["ok"]
    assert (method, accepted, closed, stored, faces, dof) == (
        "bestfit", True, True, "bestfit", "Face1", "z,rx,ry")
    assert matrix == 16 and "Invalid" not in state
    assert session["after_undo"] == ["none", [], "all", []]
    assert session["cancel"] == ["bestfit", 16, True, True, "none", []]
