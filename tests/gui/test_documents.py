# SPDX-License-Identifier: LGPL-2.1-or-later
"""Documents and preferences in the real FreeCAD GUI (under Xvfb), issue 24: a document
saved with a colour map opens unmodified (the map's automatic range was written back to
the view on every drawing, which marked a just opened document modified), while a real
change still marks it; an old document made headless opens migrated, with its maps, and
unmodified; the Preferences dialog shows the SurfComp page with an icon."""

import pytest

from tests.gui.harness import run_session


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("documents", tmp_path_factory.mktemp("gui_documents"))


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []
    assert session["errors_at_end"] == []


def test_a_saved_document_opens_unmodified(session):
    r = session["reopened"]
    assert r["proxy"] == "ViewProviderCompensation" and r["mode"] == "Map"
    assert r["drawn"] > 1000                    # the map was drawn on opening ...
    assert r["modified"] is False               # ... and that changed nothing
    assert session["modified_after_change"] is True


def test_an_old_headless_document_opens_migrated_drawn_and_unmodified(session):
    r = session["old_document"]
    for name, (proxy, mode, colours) in r["views"].items():
        assert proxy == "ViewProviderCompensation" and mode == "Map", name
        assert colours > 1000, name
    assert r["versions"] == [r["version"]] * 3         # migrated ...
    assert r["renamed"] == [True, False]
    assert r["modified"] is False                       # ... while it was being opened


def test_preferences_page_has_an_icon(session):
    groups = {name: null for name, null in session["preferences"]["groups"]}
    assert "SurfComp" in groups, groups
    assert groups["SurfComp"] is False          # not a null icon
