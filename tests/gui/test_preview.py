# SPDX-License-Identifier: LGPL-2.1-or-later
"""The filter panel's live preview in the real FreeCAD GUI (under Xvfb), with real input:
key presses through XTest at the X server (as a keyboard sends them), timed from the press
to the render of the 3D view that shows the map's new colours (issue 24: at most 0.3 s on
a 45 x 45 grid); the Filter command from a click on its toolbar button (issue 24: on
FreeCAD 1.1 the first click did nothing).

The figures beside the old code's are printed by bench/bench_filter_panel.py; the bound
here is the issue's 0.3 s on the median of eight presses, every press repainted (see
test_live_preview_within_0_3_s_of_the_key for a machine that other jobs load).
"""

import statistics

import pytest

from tests.gui.harness import run_session

#: response times: alone on the machine, after the parallel part (tools/test.sh)
pytestmark = pytest.mark.latency

#: issue 24: the map on screen within 0.3 s of the last key press
LIMIT = 0.3


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("preview", tmp_path_factory.mktemp("gui_preview"))


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []
    assert session["errors_at_end"] == []


def test_first_toolbar_click_opens_the_filter_panel(session):
    assert session["filter_button_enabled"] is True
    assert session["first_click"] == [True, True, True]


def test_keys_reach_the_panel(session):
    assert session["focus"] == ["QSpinBox", True]
    # four Up and four Down presses from mask 5: 7, 5, 7, 5 ... back to 5
    assert session["mask_after_presses"] == [5, 5]
    assert session["typed"] == ["1 2 1; 2 4 2; 1 2 1", "1 2 1; 2 4 2; 1 2 1", 3]


def test_every_key_press_is_repainted(session):
    for rec in session["presses"]:
        assert rec["changed"], rec                  # the colours changed ...
        assert rec["seconds"] is not None, rec      # ... and a render showed them


def test_live_preview_within_0_3_s_of_the_key(session):
    """FreeCAD's own work from the key to the repaint (CPU seconds of all its threads, the
    rendering's included) stays within the issue's 0.3 s whatever else runs on the
    machine; the time on screen too, stretched only by the share of the cores that other
    jobs took (the load average over the cores, when above 1)."""
    presses = session["presses"]
    stretch = max(1.0, session["load"] / session["cores"])
    cpu = statistics.median(rec["cpu"] for rec in presses)
    wall = statistics.median(rec["seconds"] for rec in presses)
    assert 0.0 < cpu <= LIMIT, (presses, session["load"])
    assert 0.0 < wall <= LIMIT * stretch, (presses, session["load"])
    typing = session["typing"]
    assert typing["changed"] and typing["seconds"] is not None
    assert typing["seconds"] <= LIMIT * stretch, (typing, session["load"])


def test_cancel_restores_the_filter(session):
    assert session["after_reject"] == [5, "", False]
