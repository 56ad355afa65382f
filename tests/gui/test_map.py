# SPDX-License-Identifier: LGPL-2.1-or-later
"""The colour map in the real FreeCAD GUI (under Xvfb), part 2: screenshots checked pixel by
pixel (legend, manual range with out-of-range colours, steps, tolerance and warning bands
with percentages), the other maps, a shared range, the histogram panel, the point readout in
the status bar and flags (also over a tool path), stacked legends clear of the navigation
cube, save and reopen."""

import os
import subprocess
import sys

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core import colormap
from tests.conftest import ROOT
from tests.gui.harness import read_image, run_session


def make_headless_document(path):
    """A document with a compensation made without the GUI (as the batch route saves
    them): its objects carry no view providers."""
    script = ("import sys; sys.path.insert(0, %r)\n"
              "from surfcomp.app import fcenv; FreeCAD = fcenv.import_freecad()\n"
              "import Part\n"
              "from surfcomp.app import features\n"
              "doc = FreeCAD.newDocument('headless')\n"
              "nom = doc.addObject('Part::Feature', 'Nominal')\n"
              "nom.Shape = Part.read(%r)\n"
              "m = features.make_measurement(doc, %r)\n"
              "c = features.make_compensation(doc, nom, 'Face1', m)\n"
              "c.Refine = 1\n"
              "doc.recompute()\n"
              "assert c.Shape.isValid()\n"
              "doc.saveAs(%r)\n" % (ROOT, os.path.join(ROOT, "examples", "nominal.step"),
                                     os.path.join(ROOT, "examples", "measurements.csv"), path))
    subprocess.run([sys.executable, "-c", script], check=True, timeout=300)


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gui_map")
    make_headless_document(str(tmp / "headless.FCStd"))
    return run_session("map", tmp)


def _pixel(img, xy, dx=-2, dy=2):
    """Median colour of the 3 x 3 block next to a projected point (view y is up; the
    offset keeps off the label text, which starts at the point and runs right/up)."""
    h = img.shape[0]
    col, row = xy[0] + dx, h - 1 - xy[1] + dy
    return np.median(img[row - 1:row + 2, col - 1:col + 2].reshape(-1, 3), axis=0)


def _legend_pixel(img, layout, fraction, dx=0.5):
    h, w = img.shape[:2]
    x = layout["bar_x"][0] + dx * (layout["bar_x"][1] - layout["bar_x"][0])
    y0, y1 = layout["bar_y"]
    y = y0 + fraction * (y1 - y0)
    return img[int(round((1 - (y + 1) / 2) * h)), int(round((x + 1) / 2 * w))]


def _row(layout, y, h):
    return int(round((1 - (y + 1) / 2) * h))


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []
    assert session["errors_after_map"] == []


def test_deviation_map_is_one_undo_step_with_symmetric_range(session):
    assert "Up-to-date" in session["comp_state"]
    assert session["display_mode"] == "Map"
    assert session["hidden_by_map"] == [False, False]   # nominal and points do not cover it
    assert session["undo_names"][:3] == ["Deviation map", "Import measurements", "Load nominal"]
    lo, hi = session["dev_minmax"]
    a = max(-lo, hi)
    assert_allclose(session["range_auto"], [-a, a], atol=1e-12)
    assert_allclose(session["view_range_props"], [-a, a], atol=1e-9)
    assert session["markers"] == 2025
    assert session["mesh_vertices"] == 90 * 90          # 2 x the 45 x 45 grid
    assert session["labels"] == ["  max %s" % colormap.format_value(hi),
                                 "  min %s" % colormap.format_value(lo)]


def test_screenshot_largest_deviation_has_the_legend_end_colour(session):
    img = read_image(session["shot_deviation"])
    assert list(img.shape[1::-1]) == session["image_size"]
    lay = session["layout_one"]
    lo, hi = session["dev_minmax"]
    assert_allclose(_legend_pixel(img, lay, 0.99), [1, 0, 0], atol=0.08)
    assert_allclose(_legend_pixel(img, lay, 0.01), [0, 0, 1], atol=0.08)
    assert_allclose(_legend_pixel(img, lay, 0.5), [0, 1, 0], atol=0.08)
    assert_allclose(_pixel(img, session["extreme_pixels"][0]), _legend_pixel(img, lay, 0.99),
                    atol=0.08)
    want = colormap.map_colors([lo], -hi, hi)[0]
    assert_allclose(_pixel(img, session["extreme_pixels"][1]), want, atol=0.08)


def test_screenshot_legend_has_labels_title_and_sign_note(session):
    img = read_image(session["shot_deviation"])
    h, w = img.shape[:2]
    lay = session["layout_one"]
    dark = img.sum(axis=2) < 0.6
    x_text = int((lay["label_x"] + 1) / 2 * w)
    labels = dark[:, x_text:]
    rows_with_text = np.flatnonzero(labels.any(axis=1))
    assert labels.sum() > 500
    top_row, bottom_row = _row(lay, lay["bar_y"][1], h), _row(lay, lay["bar_y"][0], h)
    assert rows_with_text.min() < top_row + 15 and rows_with_text.max() > bottom_row - 15
    assert dark[:top_row - 5, int(0.5 * w):].sum() > 100      # title above the bar
    assert "Deviation [mm]" in session["legend_texts_auto"]
    assert "+ = material left" in session["legend_texts_auto"]


def test_legend_clear_of_the_navigation_cube(session):
    shown, corner, size = session["navicube"]
    w, h = session["image_size"]
    lay = session["layout_one"]
    title_top_px = (1 - (lay["title_y"] + 0.03 + 1) / 2) * h     # 17 px font above title_y
    if shown and corner == 1:                                   # top right (the default)
        assert title_top_px > size
    assert lay["bar_y"][0] > -1.0 and lay["bar_y"][1] < lay["title_y"]


def test_manual_range_out_of_range_colours_and_arrows(session):
    img = read_image(session["shot_manual"])
    assert session["range_manual"] == [-0.02, 0.02]
    lo, hi = session["dev_minmax"]
    assert hi > 0.02 and lo < -0.02
    # the largest deviation lies beyond +0.02: light grey, not the scheme's red
    assert_allclose(_pixel(img, session["extreme_pixels"][0]),
                    colormap.OUT_OF_RANGE_COLORS["above"], atol=0.08)
    assert_allclose(_pixel(img, session["extreme_pixels"][1]),
                    colormap.OUT_OF_RANGE_COLORS["below"], atol=0.08)
    lay = session["layout_one"]
    h = img.shape[0]
    # the arrows past the bar's ends, in those colours
    y_above = lay["bar_y"][1] + 0.015
    y_below = lay["bar_y"][0] - 0.015
    x = int(round((0.5 * sum(lay["bar_x"]) + 1) / 2 * img.shape[1]))
    assert_allclose(img[_row(lay, y_above, h), x], colormap.OUT_OF_RANGE_COLORS["above"],
                    atol=0.08)
    assert_allclose(img[_row(lay, y_below, h), x], colormap.OUT_OF_RANGE_COLORS["below"],
                    atol=0.08)
    texts = session["legend_texts_manual"]
    assert any(t.startswith("> ") and t.endswith("%") for t in texts)
    assert any(t.startswith("< ") and t.endswith("%") for t in texts)


def test_stepped_bar_has_flat_steps(session):
    img = read_image(session["shot_stepped"])
    lay = session["layout_one"]
    # inside one step (0.30 .. 0.40 of 10 steps) the colour is the step's middle colour
    want = colormap.map_colors([-0.02 + 0.35 * 0.04], -0.02, 0.02)[0]
    for f in (0.31, 0.35, 0.39):
        assert_allclose(_legend_pixel(img, lay, f), want, atol=0.06)


def test_tolerance_band_warning_band_and_percentages(session):
    img = read_image(session["shot_tolerance"])
    cols = dict(colormap.TOLERANCE_COLORS, warning=colormap.WARNING_COLOR)
    for name in ("inside", "above", "below", "warning"):
        assert len(session["tolerance_pixels"][name]) >= 3, name
        for xy in session["tolerance_pixels"][name]:
            assert_allclose(_pixel(img, xy, 0, 0), cols[name], atol=0.1,
                            err_msg="%s node at %s" % (name, xy))
    fr = session["band_fractions"]
    texts = session["tolerance_legend"]
    for word, key in (("in", "inside"), ("above", "above"), ("below", "below"),
                      ("warn", "warning")):
        assert "%s %.1f %%" % (word, fr[key]) in texts
    assert abs(fr["inside"] + fr["above"] + fr["below"] - 100.0) < 1e-9


def test_other_maps_redraw_without_recompute_and_state_their_sign(session):
    for q, m in session["maps"].items():
        a = max(m["nodes_absmax"], colormap.MIN_HALF_RANGE)   # filtered: residual 0
        assert_allclose(m["range"], [-a, a], rtol=1e-12, err_msg=q)
    assert session["maps"]["random"]["nodes_absmax"] < 0.3 * max(map(abs, session["dev_minmax"]))
    assert session["comp_touched_after_restyle"] is False
    assert "+ = material removed (the face moves in by it)" in session["correction_legend"]
    assert "Correction [mm]" in session["correction_legend"]


def test_shared_range_is_the_same_for_every_map_of_the_measurement(session):
    lo, hi = session["dev_minmax"]
    a = max(-lo, hi, session["maps"]["correction"]["nodes_absmax"])
    assert_allclose(session["shared_random_range"], [-a, a], rtol=1e-12)


def test_histogram_panel_coloured_like_the_legend(session):
    h = session["histogram"]
    assert h is not None and h["visible"] is True and h["bars"] == len(h["colors"])
    assert h["sum"] == h["total"] == 2025
    lo, hi = session["dev_minmax"]
    a = max(-lo, hi)
    edges = np.array(h["edges"])
    assert_allclose([edges[0], edges[-1]], [-a, a], rtol=1e-12)
    assert_allclose(h["colors"], colormap.map_colors(0.5 * (edges[1:] + edges[:-1]), -a, a),
                    atol=1e-12)
    img = read_image(session["histogram_png"])
    assert np.any(np.all(np.abs(img - [1, 0, 0]) < 0.1, axis=2))   # red bars at the top end


def test_hover_shows_the_point_in_the_status_bar(session):
    hov = session["hover"]
    assert hov["node"] == hov["want_node"]
    status = hov["status"]
    assert status.startswith("Compensation point P") and "deviation %s" % \
        colormap.format_value(hov["deviation"]) in status
    for word in ("determined", "random", "correction", ") mm:"):
        assert word in status


def test_click_flags_the_point_and_removes_it(session):
    (name, subs), = session["click_without_readout"]
    assert name == "Compensation" and subs and subs[0].startswith(("Vertex", "Face"))
    # a tool path drawn in front takes a click on its line while the readout is off ...
    assert session["path_pixel_is_the_node's"] is True
    assert [name for name, _subs in session["click_path_without_readout"]] == ["ToolPath"]
    click = session["click_over_path"]
    assert click["selection"] == [["Compensation", []]]    # ... the map takes it while shown
    assert click["flags"] == [click["node"]]
    assert session["flags_after_second_click"] == []
    assert len(session["flags_kept"]) == 1 and session["flag_nodes_drawn"] == 1
    img = read_image(session["shot_flag"])
    x, y = session["flag_pixel"]
    patch = img[img.shape[0] - 1 - y - 3:img.shape[0] - y + 3, x - 3:x + 4]
    assert (patch.sum(axis=2) < 0.3).any()                  # the flag's black dot


def test_two_maps_stack_their_legends(session):
    a, b = session["layouts_two"]
    assert a["slots"] == b["slots"] == 2
    lo_top, hi_low = (a, b) if a["bar_y"][1] > b["bar_y"][1] else (b, a)
    # the lower legend (bar and title) lies wholly below the upper one's bar
    assert hi_low["title_y"] + 0.03 < lo_top["bar_y"][0]
    img = read_image(session["shot_two"])
    for lay in (a, b):
        assert_allclose(_legend_pixel(img, lay, 0.99), [1, 0, 0], atol=0.08)
    assert session["layout_after_hide"]["slots"] == 1


def test_saved_document_reopens_with_its_map_and_flags(session):
    name, mode, vertices, flags, drawn = session["reopened"]
    assert [name, mode, vertices] == ["ViewProviderCompensation", "Map", 8100]
    assert flags == session["flags_kept"] and drawn == 1


def test_headless_document_gets_its_maps(session):
    assert session["headless_opened"] == ["ViewProviderCompensation", "Map", 8100]


def test_no_python_traceback_in_the_report_view(session):
    assert "Traceback" not in session["report_view_end"]
