# SPDX-License-Identifier: LGPL-2.1-or-later
"""The colour map in the real FreeCAD GUI (under Xvfb), part 2: screenshots checked pixel by
pixel (the legend panel: manual range with out-of-range colours, steps, tolerance and warning
bands with percentages), the other maps, a shared range, the histogram panel (closed by
Histogram = false), the point readout in the status bar and flags (also over a tool path;
leader lines clear of the max label), four maps with one named, full-size legend each in one
panel beside the 3D view, save and reopen."""

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


def _legend_pixel(shot, fraction, dx=0.5):
    """Colour of the legend image ``shot`` (:func:`legend_shot` of the session) at
    ``fraction`` (0 bottom .. 1 top) along its bar."""
    img = read_image(shot["png"])
    left, top, width, height = shot["bar"]
    return img[int(round(top + (1.0 - fraction) * (height - 1))), int(round(left + dx * width))]


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
    # um is the default display unit
    assert session["labels"] == ["  max %s" % colormap.format_value(hi, "um"),
                                 "  min %s" % colormap.format_value(lo, "um")]


def test_screenshot_largest_deviation_has_the_legend_end_colour(session):
    img = read_image(session["shot_deviation"])
    assert list(img.shape[1::-1]) == session["image_size"]
    leg = session["legend_one"]
    lo, hi = session["dev_minmax"]
    assert_allclose(_legend_pixel(leg, 0.99), [1, 0, 0], atol=0.08)
    assert_allclose(_legend_pixel(leg, 0.01), [0, 0, 1], atol=0.08)
    assert_allclose(_legend_pixel(leg, 0.5), [0, 1, 0], atol=0.08)
    assert_allclose(_pixel(img, session["extreme_pixels"][0]), _legend_pixel(leg, 0.99),
                    atol=0.08)
    want = colormap.map_colors([lo], -hi, hi)[0]
    assert_allclose(_pixel(img, session["extreme_pixels"][1]), want, atol=0.08)


def test_legend_panel_names_the_map_with_labels_title_and_sign_note(session):
    leg = session["legend_one"]
    img = read_image(leg["png"])
    left, top, width, height = leg["bar"]
    dark = img.sum(axis=2) < 0.6
    labels = dark[int(top) - 10:int(top + height) + 10, int(left + width) + 2:]
    rows = np.flatnonzero(labels.any(axis=1))
    assert labels.sum() > 500
    # labels from the top of the bar to its bottom
    assert rows.min() < 20 and rows.max() > height - 10
    assert dark[:int(top) - 5].sum() > 100                       # name and title above the bar
    texts = leg["texts"]
    assert texts[:3] == ["Compensation", "Deviation [\u00b5m]", "+ = material left"]
    assert "+0.0 \u00b5m" in texts or "0.0 \u00b5m" in texts
    assert "Deviation [\u00b5m]" in session["legend_texts_auto"]


def test_legend_panel_beside_the_3d_view(session):
    dock, view = session["legend_dock_beside_view"]
    dx, dy, dw, dh = dock
    vx, vy, vw, vh = view
    # in the main window's coordinates the dock and the 3D view do not overlap
    assert dx >= vx + vw or dx + dw <= vx or dy >= vy + vh or dy + dh <= vy
    assert dw >= 250


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
    # the arrows past the bar's ends, in those colours
    leg = session["legend_manual"]
    assert_allclose(_legend_pixel(leg, 1.0 + 5.0 / leg["bar"][3]),
                    colormap.OUT_OF_RANGE_COLORS["above"], atol=0.08)
    assert_allclose(_legend_pixel(leg, -5.0 / leg["bar"][3]),
                    colormap.OUT_OF_RANGE_COLORS["below"], atol=0.08)
    texts = session["legend_texts_manual"]
    assert any(t.startswith("> ") and t.endswith("%") for t in texts)
    assert any(t.startswith("< ") and t.endswith("%") for t in texts)


def test_stepped_bar_has_flat_steps(session):
    leg = session["legend_stepped"]
    # inside one step (0.30 .. 0.40 of 10 steps) the colour is the step's middle colour
    want = colormap.map_colors([-0.02 + 0.35 * 0.04], -0.02, 0.02)[0]
    for f in (0.31, 0.35, 0.39):
        assert_allclose(_legend_pixel(leg, f), want, atol=0.06)


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
    assert "Correction [\u00b5m]" in session["correction_legend"]


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
    assert session["histogram_after_off"] is False                # Histogram = false closes it


def test_hover_shows_the_point_in_the_status_bar(session):
    hov = session["hover"]
    assert hov["node"] == hov["want_node"]
    status = hov["status"]
    assert status.startswith("Compensation point P") and "deviation %s" % \
        colormap.format_value(hov["deviation"], "um") in status
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


def test_flag_leader_line_keeps_its_text_clear_of_the_max_label(session):
    f = session["flag_on_max"]
    (px, py), (ex, ey) = f["point"], f["end"]
    assert np.hypot(ex - px, ey - py) >= 30                 # a leader line, not a label on it
    without = read_image(f["labels_only"]).sum(axis=2) < 0.6
    withflag = read_image(f["shot"]).sum(axis=2) < 0.6
    h = without.shape[0]
    row, col = h - 1 - py, px
    # the max label: dark pixels right of the point, on its line (text grows upwards)
    band = without[row - 16:row + 5, col + 3:col + 260]
    rows, cols = np.nonzero(band)
    assert cols.size > 50, "no max label found"
    top, bottom = row - 16 + rows.min(), row - 16 + rows.max()
    left, right = col + 3 + cols.min(), col + 3 + cols.max()
    # what the flag added (dot, leader, text) stays out of the label's box, but for the
    # dot and the start of the leader at the point itself
    added = withflag & ~without
    box = added[top - 1:bottom + 2, left - 1:right + 2].copy()
    yy, xx = np.mgrid[top - 1:bottom + 2, left - 1:right + 2]
    box[np.hypot(yy - row, xx - col) < 9] = False
    assert box.sum() <= 3, box.sum()
    mx, my = (px + ex) // 2, (py + ey) // 2
    assert added[h - 1 - my - 2:h - my + 2, mx - 2:mx + 3].any()      # the leader line
    assert f["text"].strip().endswith("\u00b5m")
    assert session["flag_relaid"] is True


def test_four_maps_one_legend_panel_named_and_full_size(session):
    four = session["legends_four"]
    assert len(four) == 4 and len(set(four)) == 4           # one entry per map, by its name
    titles = sorted(v["title"] for v in four.values())
    assert titles == ["Correction [\u00b5m]", "Determined component [\u00b5m]",
                      "Deviation [\u00b5m]", "Random component [\u00b5m]"]
    assert {v["bar"] for v in four.values()} == {session["bar_height"]}    # not squashed
    for name, leg in session["legend_four_shots"].items():
        assert leg is not None, name
        # every bar shows its scheme's ends (the correction's range is its own)
        assert_allclose(_legend_pixel(leg, 0.99), [1, 0, 0], atol=0.08, err_msg=name)
        assert_allclose(_legend_pixel(leg, 0.01), [0, 0, 1], atol=0.08, err_msg=name)
    assert len(session["legends_after_hide"]) == 3
    assert session["legends_after_remove"] == ["Compensation"]


def test_a_flag_gives_the_value_of_the_map_it_is_on(session):
    """The flag on the largest deviation, on the residual and increment maps: their value
    at the point (filtered: residual 0, increment the determined component), not the
    deviation it showed on every map but the four the readout names."""
    texts, values = session["flag_on_max_texts"], session["flag_on_max_values"]
    unit = session["unit"]
    for q, text in texts.items():
        assert text.endswith("  " + colormap.format_value(values[q], unit)), (q, text)
    assert texts["residual"].endswith("  " + colormap.format_value(0.0, unit))
    assert texts["increment"] != texts["deviation"]


def test_saved_document_reopens_with_its_map_and_flags(session):
    name, mode, vertices, flags, drawn = session["reopened"]
    assert [name, mode, vertices] == ["ViewProviderCompensation", "Map", 8100]
    assert flags == session["flags_kept"] and drawn == 1


def test_headless_document_gets_its_maps(session):
    assert session["headless_opened"] == ["ViewProviderCompensation", "Map", 8100]


def test_no_python_traceback_in_the_report_view(session):
    assert "Traceback" not in session["report_view_end"]
