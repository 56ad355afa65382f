# SPDX-License-Identifier: LGPL-2.1-or-later
"""Build corrected face and Replace in document / Restore nominal in the real FreeCAD GUI
(under Xvfb), part 4: the built face hidden (it z-fought with the map) and named by method
and round; Replace refused when nothing uses the nominal, its summary (links, objects, Path
jobs), the job's model clone renamed and named back, Esc undoing the step."""

import pytest
from numpy.testing import assert_allclose

from surfcomp.core import colormap
from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("replace", tmp_path_factory.mktemp("gui_replace"))


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []
    assert session["errors_at_end"] == []


def test_built_face_is_hidden_and_named_by_method_and_round(session):
    n, area, comp_area, label, visible, map_visible = session["corrected_face"]
    assert n == 1 and area > 2000
    assert_allclose(area, comp_area, rtol=1e-9)
    assert label == "nominal filtered round 1 build 1"
    assert visible is False and map_visible is True
    # no grey face over the map: the largest deviation keeps the top colour
    img = read_image(session["shot_after_build"])
    x, y = session["extreme_pixel"]
    px = img[img.shape[0] - 1 - y + 2, x - 2]
    assert_allclose(px, colormap.map_colors([1.0], -1.0, 1.0)[0], atol=0.12)


def test_replace_refused_when_nothing_uses_the_nominal(session):
    errors, infos, record = session["replace_without_users"]
    (title, message), = errors
    assert title.endswith("Replace in document")
    assert "nothing in the document uses nominal" in message
    assert infos == [] and record == ""


def test_replace_summary_and_the_model_clone_renamed(session):
    name, label = session["clone_before"]
    assert "nominal" in label
    source, can_replace, can_restore, infos, clone_label, clone_objects = \
        session["after_replace"]
    assert source.startswith("Compensation") and (can_replace, can_restore) == (False, True)
    (title, text), = infos
    assert "Rebound 2 link(s) of 2 object(s)" in text
    # the job has no operations: nothing claims a regenerated tool path
    assert "Path job Job: no operations" in text and "regenerated" not in text
    assert "Renamed %s -> %s" % (label, clone_label) in text
    assert clone_label == label.replace("nominal", "Compensation")
    source, label_back, infos = session["after_restore"]
    assert source == "Nominal" and label_back == label
    assert "Restored 2 link(s)" in infos[0][1]


def test_escape_while_the_users_recompute_undoes_the_step(session):
    infos, _obj, source, record, clone_label = session["after_esc"]
    assert [m for _t, m in infos] == ["Cancelled: the document is as before."]
    assert source == "Nominal" and record == "" and "nominal" in clone_label
    assert session["replace_active"] == [True, False]
