# SPDX-License-Identifier: LGPL-2.1-or-later
"""The filter task panel, the report and the mirror command in the real FreeCAD GUI (under
Xvfb), part 3: the live map follows every change of mask size, weights, kind and edge
handling (the issue's stale map: mask 5 -> 11 left the picture unchanged), the RMS figures,
weights that set the mask size, a bad mask shown in the panel without a traceback; the
report's table, clipboard and HTML (the GUI's colour scheme); the explained stock."""

import json

import pytest
from numpy.testing import assert_allclose

from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("filter", tmp_path_factory.mktemp("gui_filter"))


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []
    assert session["errors_at_end"] == []


def test_the_map_follows_the_mask_size(session):
    """The stale-map case: after mask 5 -> 11 the 3D image changes."""
    assert session["filter_dialog_open"] is True and session["filter_active"] is True
    size, changed = session["mask11"]
    assert size == 11 and changed > 1e-6
    assert session["colours_changed_mask"] > 0.01
    before, after = (read_image(p) for p in session["shots_mask"])
    differ = (abs(before - after).sum(axis=2) > 0.05).mean()
    assert differ > 0.02, differ        # a visible part of the picture changed


def test_weights_set_the_mask_size_and_redraw(session):
    size, enabled, prop, weights, changed = session["weights"]
    assert (size, enabled, prop, weights) == (3, False, 3, "1 2 1; 2 4 2; 1 2 1")
    assert changed > 0.01


def test_kind_and_edge_redraw(session):
    kind, changed = session["kind"]
    assert kind == "gaussian" and changed > 1e-3
    edge, changed = session["edge"]
    assert edge and changed > 0.0


def test_panel_shows_rms_and_predicted_residual(session):
    for text in (session["figures_initial"], session["figures_mask11"]):
        assert "RMS  deviation" in text and "determined" in text and "random" in text
        assert "Predicted residual" in text and "next part" in text and "µm" in text
    assert session["figures_initial"] != session["figures_mask11"]


def test_bad_mask_shown_in_the_panel_without_a_traceback(session):
    message, ok, accepted, state, state_before = session["filter_invalid"]
    # the option named as the panel's field (the command line says --mask)
    assert "Mask size 4: expected an odd whole number" in message
    assert "mask_size" not in message
    assert ok is False and accepted is False
    assert state == state_before                            # no recompute was tried
    added = session["report_view_added"]
    assert "Traceback" not in added and "Recompute failed" not in added


def test_cancel_and_ok(session):
    assert session["filter_after_reject"] == [5, "box", 0.0]
    # nothing left marked for a recompute after Cancel (the tree's mark, the Recompute
    # button): the undo put back every value, as a recompute confirms
    state, must = session["state_after_reject"]
    assert "Touched" not in state and must is False
    assert session["recomputed_after_reject"] == 0.0
    assert session["filter_after_accept"] == [3, "random", False]
    assert session["undo_after_filter"][0].startswith("Filter ")


def test_report_table_and_clipboard(session):
    rep = session["report"]
    stats = json.loads(session["statistics"])
    assert rep["rows"] == 7
    assert rep["headers"] == ["Deviation", "Determined", "Random", "Correction"]
    # in um, the default display unit
    assert rep["max_neg"] == "%.2f" % (1e3 * stats["deviation"]["max_negative"])
    assert "Deviations (\u00b5m)" in rep["clipboard"]
    assert ("%.2f" % (1e3 * stats["random"]["std"])) in rep["clipboard"]


def test_report_html_uses_the_gui_scheme_and_range(session):
    rep = session["report_html"]
    assert rep["path"] and rep["path"].endswith("report.html") and rep["errors"] == []
    html = rep["text"]
    for section in ("inputs", "method", "maps", "histograms", "statistics", "checks"):
        assert 'id="%s"' % section in html
    assert html.count("data:image/png;base64,") >= 5
    assert "Colour scheme rainbow, range -20.0 .. 20.0 µm as in the GUI" in html
    assert "+ = material removed" in html or "material removed" in html


def test_mirror_stock_explained_and_residual_defined(session):
    dlg = session["stock_dialog"]
    assert "semi-finishing allowance" in dlg["tooltip"] and "-(d - stock)" in dlg["tooltip"]
    assert dlg["suffix"] == " mm" and dlg["value"] == 0.1
    img = read_image(dlg["png"])
    blue = ((abs(img - [43 / 255, 108 / 255, 176 / 255]).sum(axis=2)) < 0.1).sum()
    red = ((abs(img - [197 / 255, 48 / 255, 48 / 255]).sum(axis=2)) < 0.1).sum()
    assert blue > 100 and red > 100             # the measured and the corrected curve
    method, stock, quantity, state = session["mirror"]
    assert (method, quantity) == ("mirror", "correction") and "Up-to-date" in state
    assert_allclose(stock, 0.1)
    largest, vs_random = session["mirror_residual"]
    assert largest > 1e-4                      # not all 0.00 (the issue)
    assert vs_random < 1e-9                    # = -random for the mirror method
    assert session["after_mirror_undo"] == ["filtered", 0.0]


def test_panel_and_property_view_show_the_option_registry(session):
    """The filter panel's ranges, items and tooltips and the compensation's property
    tooltips and enumerations, as the user meets them, are the option registry's."""
    from surfcomp.core.options import OPTIONS, tooltip

    seen = session["panel_options"]
    size = OPTIONS["mask_size"]
    assert seen["mask_range"] == [size.low, size.high] == [1, 201]
    assert seen["kind_items"] == list(OPTIONS["mask_kind"].choices) == ["box", "gaussian"]
    assert seen["edge_items"] == list(OPTIONS["edge"].choices)
    for name, tip in seen["tooltips"].items():
        assert tip == tooltip(name), name
    assert "Weights" in seen["tooltips"]["mask_size"]       # the property's name, not a flag
    # the fields' labels: the names the panel's messages use
    assert seen["labels"] == {name: OPTIONS[name].label for name in seen["labels"]}
    assert seen["labels"]["mask_size"] == "Mask size"
    props = {o.prop: o for o in OPTIONS.values()}
    for prop, (doc, items) in session["property_options"].items():
        assert doc == tooltip(props[prop].name), prop
        if items is not None:
            assert items == list(props[prop].choices), prop
    assert "0: MaskSize / 4" in session["property_options"]["Sigma"][0]
    stock = OPTIONS["stock"]                # the stock dialog's spin box: the stock's domain
    assert session["stock_dialog"]["range"] == [stock.low, stock.high] == [0.0, 10.0]
