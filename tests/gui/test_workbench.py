"""The workbench in the real FreeCAD GUI (under Xvfb): every command on the bundled
example through FreeCAD's command mechanism, colour-map screenshots checked pixel by
pixel, task panel, report, preferences, errors as dialogs, save and reopen.

One GUI session (tests/gui/session_workbench.py) runs everything; the tests below
assert on what it recorded.
"""

import json
import os

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core import colormap
from tests.conftest import ROOT
from tests.gui.harness import read_image, run_gui

COMMAND_IDS = ["SurfComp_BuildFace", "SurfComp_DeviationMap", "SurfComp_Filter",
               "SurfComp_ImportMeasurements", "SurfComp_LoadNominal", "SurfComp_Mirror",
               "SurfComp_ReplaceInDocument", "SurfComp_Report", "SurfComp_RestoreNominal"]


def make_headless_document(path):
    """A document with a compensation made without the GUI (as the batch route saves
    them): its objects carry no view providers."""
    import subprocess
    import sys

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
    tmp = tmp_path_factory.mktemp("gui_session")
    make_headless_document(str(tmp / "headless.FCStd"))
    with open(os.path.join(os.path.dirname(__file__), "session_workbench.py")) as f:
        body = f.read()
    results, output = run_gui(body, tmp)
    results["output"] = output
    return results


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []


def test_workbench_menu_toolbar_and_icons(session):
    assert "SurfCompWorkbench" in session["workbenches"]
    assert session["active_workbench"] == "SurfCompWorkbench"
    assert session["commands"] == COMMAND_IDS
    assert "SurfComp" in session["toolbars"]
    actions = [a for a in session["toolbar_actions"] if a]
    assert len(actions) == len(COMMAND_IDS)
    assert session["toolbar_icons_null"] == []
    for cid, res in session["resources"].items():
        assert os.path.basename(res["Pixmap"]) == cid + ".svg"
        assert os.path.isfile(os.path.join(ROOT, "resources", "icons", cid + ".svg"))
        assert res["MenuText"] and len(res["ToolTip"]) > 20


def test_commands_enabled_only_with_their_inputs(session):
    act = session["active_empty_doc"]
    assert {k for k, v in act.items() if v} == {"SurfComp_LoadNominal",
                                               "SurfComp_ImportMeasurements"}
    assert session["map_active_without_selection"] is False
    assert session["map_active_with_selection"] is True
    assert session["filter_active"] is True
    assert session["replace_active"] == [True, False]
    assert session["after_replace"][1:] == [False, True]


def test_import_preview_then_measurement_object(session):
    assert session["nominal_faces"] == 1
    assert session["measurement_points"] == 2025
    assert session["measurement_vp"] == "ViewProviderMeasurement"
    text = session["preview"][0]
    assert "Points: 2025" in text
    assert "nominal+normal+deviation" in text
    assert "Problems found: none" in text


def test_load_nominal_checks_a_selected_face(session):
    added, text = session["load_selected_face"]
    assert added == 0
    assert "SurfComp nominal: nominal.Face1 (BSplineSurface, 7 x 7 poles)" in text


def test_unreadable_file_error_dialog_has_the_cli_message(session):
    assert session["cli_message"].endswith("bad.csv:3:4: column 'z_nom' holds 'x' "
                                           "(expected a number)")
    assert [m for _t, m in session["bad_import_errors"]] == [session["cli_message"]]
    assert session["bad_import_objects_added"] == 0


def test_measurement_off_the_face_error_dialog_document_unchanged(session):
    (title, message), = session["far_errors"]
    assert "Deviation map" in title
    assert "far.csv:" in message and "mm from the face" in message
    assert session["far_objects_unchanged"] is True


def test_deviation_map_is_one_undo_step_with_symmetric_range(session):
    assert session["errors_after_map"] == []
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


def _pixel(img, xy, dx=-2, dy=2):
    """Median colour of the 3 x 3 block next to a projected point (view y is up; the
    offset keeps off the label text, which starts at the point and runs right/up)."""
    h = img.shape[0]
    col, row = xy[0] + dx, h - 1 - xy[1] + dy
    return np.median(img[row - 1:row + 2, col - 1:col + 2].reshape(-1, 3), axis=0)


def _legend_pixel(img, layout, fraction):
    h, w = img.shape[:2]
    x = 0.5 * (layout["bar_x"][0] + layout["bar_x"][1])
    y0, y1 = layout["bar_y"]
    y = y0 + fraction * (y1 - y0)
    return img[int(round((1 - (y + 1) / 2) * h)), int(round((x + 1) / 2 * w))]


def test_screenshot_largest_deviation_has_the_legend_end_colour(session):
    img = read_image(session["shot_deviation"])
    assert list(img.shape[1::-1]) == session["image_size"]
    lay = session["legend_layout"]
    lo, hi = session["dev_minmax"]
    # the legend: ends of the rainbow scale and green at zero
    assert_allclose(_legend_pixel(img, lay, 0.99), [1, 0, 0], atol=0.08)
    assert_allclose(_legend_pixel(img, lay, 0.01), [0, 0, 1], atol=0.08)
    assert_allclose(_legend_pixel(img, lay, 0.5), [0, 1, 0], atol=0.08)
    # largest (positive) deviation: the top colour of the legend
    top = _legend_pixel(img, lay, 0.99)
    assert_allclose(_pixel(img, session["extreme_pixels"][0]), top, atol=0.08)
    # largest negative deviation: its own colour on the symmetric scale
    want = colormap.map_colors([lo], -hi, hi)[0]
    assert_allclose(_pixel(img, session["extreme_pixels"][1]), want, atol=0.08)


def test_screenshot_legend_has_labels_and_title(session):
    img = read_image(session["shot_deviation"])
    h, w = img.shape[:2]
    lay = session["legend_layout"]
    dark = img.sum(axis=2) < 0.6
    # text right of the bar (11 labels) and above it (title)
    x_text = int((lay["label_x"] + 1) / 2 * w)
    labels = dark[:, x_text:]
    rows_with_text = np.flatnonzero(labels.any(axis=1))
    assert labels.sum() > 500
    # labels spread over the bar's height: text near its top and its bottom
    top_row = int((1 - (lay["bar_y"][1] + 1) / 2) * h)
    bottom_row = int((1 - (lay["bar_y"][0] + 1) / 2) * h)
    assert rows_with_text.min() < top_row + 15 and rows_with_text.max() > bottom_row - 15
    title = dark[:top_row - 5, int(0.5 * w):]
    assert title.sum() > 100


def test_screenshot_manual_range(session):
    img = read_image(session["shot_manual"])
    assert session["range_manual"] == [-0.1, 0.1]
    _lo, hi = session["dev_minmax"]
    want = colormap.map_colors([hi], -0.1, 0.1)[0]
    assert_allclose(_pixel(img, session["extreme_pixels"][0]), want, atol=0.08)
    assert_allclose(_legend_pixel(img, session["legend_layout"], 0.99), [1, 0, 0], atol=0.08)


def test_screenshot_tolerance_band_colours(session):
    img = read_image(session["shot_tolerance"])
    cols = colormap.TOLERANCE_COLORS
    for name in ("inside", "above", "below"):
        assert len(session["tolerance_pixels"][name]) == 5
        for xy in session["tolerance_pixels"][name]:
            assert_allclose(_pixel(img, xy, 0, 0), cols[name], atol=0.08,
                            err_msg="%s node at %s" % (name, xy))
    # the legend shows three blocks: below | inside | above, at the band limits
    lay = session["legend_layout"]
    lo, hi = session["dev_minmax"]
    a = max(-lo, hi)
    f_lo, f_hi = (-0.01 + a) / (2 * a), (0.01 + a) / (2 * a)
    assert_allclose(_legend_pixel(img, lay, 0.5 * f_lo), cols["below"], atol=0.08)
    assert_allclose(_legend_pixel(img, lay, 0.5 * (f_lo + f_hi)), cols["inside"], atol=0.08)
    assert_allclose(_legend_pixel(img, lay, 0.5 * (f_hi + 1)), cols["above"], atol=0.08)


def test_other_maps_redraw_without_recompute(session):
    for q, m in session["maps"].items():
        assert_allclose(m["range"], [-m["nodes_absmax"], m["nodes_absmax"]], rtol=1e-12,
                        err_msg=q)
    # the random component is much smaller than the deviation (Werner's Table 1 pattern)
    assert session["maps"]["random"]["nodes_absmax"] < 0.3 * max(map(abs, session["dev_minmax"]))
    assert session["comp_touched_after_restyle"] is False


def test_filter_task_panel_live_cancel_and_ok(session):
    assert session["filter_dialog_open"] is True
    assert session["filter_live_mask"] == 9 and session["filter_live_changed"] is True
    message, accepted = session["filter_invalid"]
    assert "mask" in message.lower() and accepted is False
    assert session["filter_after_reject"][0] == 5
    assert session["filter_after_reject"][1] == 0.0     # cancel gives the old results back
    assert session["filter_after_accept"] == [3, "random", False]
    assert session["undo_after_filter"][0].startswith("Filter ")


def test_report_table_and_clipboard(session):
    rep = session["report"]
    stats = json.loads(session["statistics"])
    assert rep["rows"] == 7
    assert rep["headers"] == ["Deviation", "Determined", "Random", "Correction"]
    assert rep["max_neg"] == "%.4f" % stats["deviation"]["max_negative"]
    assert "Deviations (mm)" in rep["clipboard"]
    assert ("%.4f" % stats["random"]["std"]) in rep["clipboard"]



def test_report_saves_the_html_report(session):
    """The GUI's Report writes the same self-contained HTML report as compensate --html."""
    rep = session["report_html"]
    assert rep["path"] and rep["path"].endswith("report.html") and rep["errors"] == []
    html = rep["text"]
    for section in ("inputs", "method", "maps", "histograms", "statistics", "checks"):
        assert 'id="%s"' % section in html
    assert html.count("data:image/png;base64,") >= 5
    assert "measurements.csv" in html and "Face1" in html

def test_mirror_build_replace_restore(session):
    method, stock, quantity, state = session["mirror"]
    assert (method, quantity) == ("mirror", "correction") and "Up-to-date" in state
    assert_allclose(stock, 0.1)
    assert session["after_mirror_undo"] == ["filtered", 0.0]
    n, area, comp_area = session["corrected_face"]
    assert n == 1 and area > 2000
    assert_allclose(area, comp_area, rtol=1e-9)
    assert session["after_replace"][0].startswith("Compensation")
    assert session["after_restore"] == ["Nominal"]


def test_preferences_page_and_defaults(session):
    combos = session["pref_combos"]
    choices = session["pref_choices"]
    assert set(choices) == set(combos)
    for name, items in choices.items():
        assert combos[name] == items, name      # combo index <-> getter order
    assert session["pref_defaults"] == [5, "filtered", "renormalize", "rainbow", False,
                                        [-0.01, 0.01], "mm"]
    name, method, scheme, unit, band = session["pref_new_map"]
    assert (method, scheme, unit, band) == ("raw", "blue-white-red", "um", True)


def test_saved_document_reopens_with_its_map(session):
    assert session["reopened"] == ["ViewProviderCompensation", "Map", 8100]


def test_headless_document_gets_its_maps(session):
    """Objects saved by freecadcmd/the batch route have no view provider; opening the
    document in the GUI gives them one and shows the map."""
    assert session["headless_opened"] == ["ViewProviderCompensation", "Map", 8100]


def test_no_python_traceback_in_the_report_view(session):
    text = session["report_view_before_far"]
    # the only tracebacks: FreeCAD's report of the recomputes that failed on purpose
    # (even filter mask, measurement 5 mm off the face), see the report to the lead
    blocks = text.split("Traceback")[1:]
    assert len(blocks) <= 1 and all("mask" in b.lower() for b in blocks)
    blocks = session["report_view"].split("Traceback")[1:]
    assert all("far.csv" in b or "mask" in b.lower() for b in blocks)
    assert "Recursive calling of recompute" not in session["report_view"]
