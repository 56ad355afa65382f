# SPDX-License-Identifier: LGPL-2.1-or-later
"""Restore and Replace with a long 3D Surface recompute in the real FreeCAD GUI (under Xvfb):
the window keeps painting (the operation computes in a child process), each operation is
computed once (not at all in the GUI process), Esc (a key event to the focused widget) stops
the child within a second and leaves the document as it was, without a recompute."""

import pytest

from tests.gui.harness import run_session

#: response times: alone on the machine, after the parallel part (tools/test.sh)
pytestmark = pytest.mark.latency

#: the window must paint at least this often during Replace and Restore (s)
MAX_GAP = 0.5


def _max_gap(step):
    """:data:`MAX_GAP`, stretched only by the share of the cores that other jobs took while
    the step ran (the load average over the cores, when above 1): a GUI process starved of
    the CPU cannot paint on time, whatever it does (bench/bench_responsive.py reports the
    gaps themselves)."""
    return MAX_GAP * max(1.0, step["load"] / step["cores"])


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_session("responsive", tmp_path_factory.mktemp("gui_responsive"), timeout=600)


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []
    assert session["errors_at_end"] == []


def _recomputed_once_in_the_child(step):
    assert step["errors"] == [] and step["invalid"] == [] and step["touched"] == []
    assert step["gui_executions"] == 0
    assert step["child_executions"] == [{"Surface": 1}]


def test_restore_keeps_painting_and_computes_the_operation_once(session):
    step = session["restore"]
    assert session["fine_commands"] > 500       # the committed operation has 142
    assert step["record"] == "" and step["path_changed"] is True
    _recomputed_once_in_the_child(step)
    assert step["seconds"] > 2.0          # long enough to show a freeze
    # Known limit: the first step of Restore puts the links back and shows the nominal
    # again, and FreeCAD draws its shape in the GUI process within those property sets
    # (1.06 s of the 1.07 s step at a load of 4.4 on 2 cores): that gap is bounded apart;
    # every gap after it, while the operation computes and its results are written back,
    # within MAX_GAP
    link_step = step["phases"][0][1]
    for start, length in step["gaps"]:
        bound = 2.0 if start < link_step else MAX_GAP
        assert length < bound * max(1.0, step["load"] / step["cores"]), step


def test_replace_keeps_painting_and_computes_the_operation_once(session):
    step = session["replace"]
    assert step["record"] is True and step["path_changed"] is True
    _recomputed_once_in_the_child(step)
    assert step["gap"] < _max_gap(step), step


def test_escape_stops_the_child_within_a_second_and_changes_nothing(session):
    step = session["esc"]
    assert step["modal"] == "QProgressDialog"
    assert step["answer_seconds"] is not None and step["answer_seconds"] < 1.0
    assert [m for _t, m in step["infos"]] == ["Cancelled: the document is as before."]
    assert step["record"] == "" and step["source"] == "Block"
    assert step["path_unchanged"] is True and step["clone_unchanged"] is True
    assert step["gui_executions"] == 0 and step["child_executions"] == []
    assert step["touched"] == [] and step["invalid"] == []
    assert step["gap"] < _max_gap(step), step
