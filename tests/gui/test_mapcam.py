# SPDX-License-Identifier: LGPL-2.1-or-later
"""The colour map in the real FreeCAD GUI (under Xvfb), part 3: in a CAM document (the shop
document FreeCAD 0.20 saved: a Job with a stock box, its model copy) a real click on the map
selects the map alone, the map shows in front of the model copy and the nominal after
Replace and after Restore (pixels at the nodes have the map's colours), the point markers
are whole; a face with a hole is not painted in the hole and its points inside the hole are
listed in the legend panel; a disc-trimmed face smaller than the measured area is refused in
words a GUI user can act on; built faces are numbered by round and build; documents from
disk without a stored unit show um, a stored mm is kept; the Filter task panel and the
legend panel do not overlap."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("mapcam", tmp_path_factory.mktemp("gui_mapcam"), timeout=400)


def _median(img, xy, half=1):
    h = img.shape[0]
    col, row = xy[0], h - 1 - xy[1]
    block = img[row - half:row + half + 1, col - half:col + half + 1]
    return np.median(block.reshape(-1, 3), axis=0)


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []


def test_stock_around_the_map_is_not_drawn_but_stays_visible(session):
    hidden, visibility, child = session["stock_hidden"]
    assert hidden == ["Stock"] and visibility is True and child == -1
    hidden, child = session["stock_after_map_hidden"]
    assert hidden == [] and child != -1            # the map hidden: the stock drawn again
    assert session["stock_after_map_shown"] == ["Stock"]


def test_a_click_on_the_map_selects_the_map_alone(session):
    assert session["click_selection"] == [["Round2", []]]
    assert len(session["click_flags"]) == 1
    assert session["click_elsewhere"] == ["BallEnd"]       # the next click is the user's


def _matches(state, atol=0.1):
    img = read_image(state["shot"])
    got = np.array([_median(img, xy) for xy in state["pixels"]])
    want = np.array(state["want"])
    return np.all(np.abs(got - want) <= atol, axis=1)


@pytest.mark.parametrize("state", ["after_replace", "with_nominal", "after_restore"])
def test_map_in_front_of_model_copy_and_nominal(session, state):
    # 40 interior nodes seen at an angle (where coincident faces z-fight): the map's colour
    ok = _matches(session[state])
    assert ok.mean() >= 0.95, "%d of %d nodes show the map's colour" % (ok.sum(), ok.size)


def test_restore_geometry_was_reached(session):
    assert session["clone_base"] == ["Round2"]            # the shop document is replaced
    assert session["clone_after_restore"] == ["Block"]


def test_point_markers_are_whole(session):
    m = session["markers"]
    img = read_image(m["shot"])
    assert m["size"] == 7
    h = img.shape[0]
    # the middle 5 x 5 of each 7 px square (projected to the pixel, +-1 px): all black
    whole = [bool((img[h - 1 - y - 2:h - y + 2, x - 2:x + 3].sum(axis=2) < 0.15).all())
             for x, y in m["pixels"]]
    assert sum(whole) >= 0.9 * len(whole), whole


def test_hole_is_not_painted_and_the_face_is(session):
    h = session["hole"]
    img = read_image(h["shot"])
    for xy in h["hole"]:
        assert_allclose(_median(img, xy), [1, 1, 1], atol=0.02, err_msg=str(xy))
    painted = [np.abs(_median(img, xy) - 1.0).max() > 0.2 for xy in h["face"]]
    assert all(painted)
    assert any("outside its trimmed boundary" in w for w in h["warnings"])


def test_points_in_the_hole_are_listed_in_the_legend_panel(session):
    leg = session["hole_legend"]
    assert leg is not None
    warning = [w for w in session["hole"]["warnings"] if "outside its trimmed" in w][0]
    count = int(warning.split(": ", 1)[1].split(" of ")[0])
    assert len(leg["outside"]) == count > 10
    text = [t for t in leg["texts"] if "outside the trimmed face" in t][0]
    assert text.startswith("%d point(s) outside the trimmed face" % count)
    assert leg["outside"][0] in text


def test_disc_face_refused_in_gui_words(session):
    # the import preview refuses the file on the disc face: nothing added
    text, added = session["disc_preview"]
    assert "beyond the border of the face" in text and "--" not in text
    assert added == 0
    (title, message), = session["disc_errors"]
    assert "beyond the border of the face" in message
    assert "--" not in message                           # no command-line option
    assert not [n for n in session["disc_objects"] if n.startswith("Compensation")]


def test_built_faces_number_round_and_build(session):
    assert session["built_labels"] == ["Holed filtered round 1 build 1",
                                       "Holed filtered round 1 build 2"]


def test_units_default_um_from_disk_and_stored_mm_kept(session):
    assert session["units_from_disk"] == ["um", "um"]
    assert session["unit_stored_mm"] == "mm"


def test_filter_task_panel_does_not_cover_the_legend_panel(session):
    t = session["task_and_legend"]
    assert t["tasks"], "the Filter task panel did not open"
    for lx, ly, lw, lh in (t["legend"], t["entry"]):
        for tx, ty, tw, th in t["tasks"]:
            assert lx >= tx + tw or lx + lw <= tx or ly >= ty + th or ly + lh <= ty
    # shown, docked, not a tab behind another dock, the map's entry visible in it
    assert t["legend_shown"] == [True, True, True, ["Compensation"]]
    ex, ey, ew, eh = t["entry"]
    lx, ly, lw, lh = t["legend"]
    assert lx <= ex and ex + ew <= lx + lw and ly <= ey < ly + lh


def test_no_traceback_of_surfcomp_in_the_report_view(session):
    # (up to the disc's refusal, which FreeCAD reports with the recompute's traceback; the
    # shop document's CAM objects that fail to restore, without OpenCamLib or with 0.20's
    # module names on 1.0, are reported by FreeCAD and are another matter)
    text = session["report_view_end"]
    assert "surfcomp" not in text
