# SPDX-License-Identifier: LGPL-2.1-or-later
"""The legend panel wraps its texts: a long note under the map's name and a long list of
points outside the trimmed face (a 70-character id without a space among them) stay inside
the entry's width, the entry is as tall as its wrapped texts, and the panel scrolls to its
end; the last line of the list is drawn (its red text found in the entry's image)."""

import pytest

from tests.gui.harness import read_image, run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("legend_wrap", tmp_path_factory.mktemp("gui_legend_wrap"))


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["errors_at_end"] == []


def test_texts_wrap_inside_the_entry(session):
    e = session["entry"]
    width, height = e["size"]
    line = e["line"]
    blocks = {text: (x, y, w, h) for text, x, y, w, h in e["blocks"]}
    note = [t for t in blocks if t.startswith("measured before the mirror")][0]
    listed = [t for t in blocks if "outside the trimmed face" in t][0]
    assert listed.startswith("400 point(s) outside") and listed.endswith(" and 388 more")
    assert "X" * 70 in listed
    for text, (x, y, w, h) in blocks.items():
        assert x >= 0 and x + w <= width, (text, blocks[text], width)
        assert y >= 0 and y + h <= height, (text, blocks[text], height)
    # the note and the list wrap over several lines (the entry is under 400 px wide)
    assert width < 400
    assert blocks[note][3] >= 2 * line
    assert blocks[listed][3] >= 6 * line
    # the bar sits below the wrapped note, the list below the bar
    bx, by, bw, bh = e["bar"]
    assert by > blocks[note][1] + blocks[note][3] and blocks[listed][1] > by + bh
    assert e["least"] == height


def test_last_line_of_the_list_is_drawn(session):
    path, ratio = session["entry_shot"]
    img = read_image(path)
    e = session["entry"]
    x, y, w, h = [b[1:] for b in e["blocks"] if "outside the trimmed face" in b[0]][0]
    line = e["line"]
    # the rows of the list's last line, in device pixels: red text (150, 0, 0), smoothed
    last = img[int((y + h - line) * ratio):int((y + h) * ratio)]
    red = (last[..., 0] > 0.35) & (last[..., 1] < 0.25) & (last[..., 2] < 0.25)
    assert red.sum() > 20
    # and nothing red below the list
    below = img[int((y + h + 1) * ratio):]
    assert not ((below[..., 0] > 0.35) & (below[..., 1] < 0.25) & (below[..., 2] < 0.25)).any()


def test_panel_scrolls_to_the_end_of_the_entry(session):
    """Taller than the panel (FreeCAD 0.20's panel beside the report view: 435 px): the
    panel scrolls by the difference and, scrolled down, shows the entry's end; shorter
    (1.1's panel spans the window: 613 px): no scrolling, the end in sight."""
    maximum, viewport, inner = session["scroll"]
    assert maximum == max(0, inner - viewport)
    bottom, port = session["scrolled_bottom"]
    assert session["entry"]["size"][1] > 600
    assert 0 < bottom <= port
    assert read_image(session["panel_shot"]).shape[0] > 200
