# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measurement plan as an operation of the shop document's CAM Job, posted by the Job's
own post-processor (linuxcnc) and read by LinuxCNC's interpreter (rs274).

Set-up: the committed shop document (FreeCAD 0.20, opened as it is on 1.0 and 1.1), a 5 x 4
grid plan on the block's free-form top ``Face2``, the plan added to the Job. Checks: every
STRAIGHT_PROBE of the posted program runs along the planned -normal within 0.01 deg, in the
plan's order, and ends the overtravel past the nominal contact (within rs274's printed
0.5e-4 mm); the operation follows the plan when it changes; a plan that cannot be probed or
a post without comments is refused.
"""

import os
import re
import shutil

import FreeCAD
import numpy as np
import pytest

from surfcomp.app import cam, documents, progress
from surfcomp.app.plan_feature import make_measurement_plan
from surfcomp.app.probe_op import (
    add_probe_operation,
    is_probe_operation,
    post_probe_job,
    probe_moves,
    recompute_probing,
)
from surfcomp.errors import GCodeError, InputError
from tests.conftest import ROOT
from tests.probe_checks import check_probe_moves, rs274_moves

SHOP = os.path.join(ROOT, "tests", "data", "documents", "shop-0.20.FCStd")
POST_ARGS = "--no-show-editor --no-header --precision=4"


@pytest.fixture
def shop(tmp_path):
    cam.setup_workbench()
    path = str(tmp_path / "shop.FCStd")
    shutil.copyfile(SHOP, path)
    doc, _refused, _info = documents.open_document(path)
    progress.recompute_with_progress(doc, "open")
    name = doc.Name
    yield doc
    if name in FreeCAD.listDocuments():
        FreeCAD.closeDocument(name)


def block_plan(shop, count, **values):
    """The shop document's Job and a recomputed grid plan of ``count`` points on Block's
    Face2."""
    plan = make_measurement_plan(shop, shop.getObject("Block"), "Face2", Layout="grid",
                                 Count=count, **values)
    progress.recompute_with_progress(shop, "test")
    return shop.getObject("Job"), plan


def plan_arrays(plan):
    return (np.array([tuple(p) for p in plan.PlanPoints]),
            np.array([tuple(n) for n in plan.PlanNormals]))


def posted_probes(job, plan, op, tmp_path, name, native=False):
    text = post_probe_job(job, "linuxcnc", POST_ARGS, native=native)
    ngc = tmp_path / name
    ngc.write_text(text)
    tools = [int(tc.ToolNumber) for tc in job.Tools.Group if int(tc.ToolNumber) != 99]
    moves = rs274_moves(ngc, tmp_path, tool=99, diameter=2 * plan.TipRadius,
                        other_tools=tools)
    P, N = plan_arrays(plan)
    probes, worst = check_probe_moves(moves, P, N, plan.TipRadius, op.Overtravel)
    return text, probes, worst


def test_the_jobs_post_processor_writes_the_plan(shop, tmp_path):
    job, plan = block_plan(shop, "5x4", TipRadius=1.5)
    assert plan.Kept == 20
    op = add_probe_operation(job, plan, tool=99, Overtravel=2.0)
    assert op in job.Operations.Group and is_probe_operation(op)
    assert [o.Name for o in job.Operations.Group][-1] == op.Name
    tc = op.ToolController
    assert tc in job.Tools.Group and int(tc.ToolNumber) == 99
    assert op.Probes == 20 and abs(op.SafeHeight - plan.SafeZ) < 1e-9
    assert [c.Name for c in op.Path.Commands].count("G38.2") == 20
    text, probes, worst = posted_probes(job, plan, op, tmp_path, "job.ngc")
    assert len(probes) == 20 and worst <= 0.01
    lines = [ln.rstrip() for ln in text.splitlines()]
    # the probe tool's change with its length offset, the work offset and the log, in order
    i = lines.index("M6 T99")
    assert lines[i + 1] == "G43 H99" and "M3" not in " ".join(lines[i:])
    j = lines.index("(PROBEOPEN probe.log)")
    assert i < lines.index("G54", i) < j < lines.index("(PROBECLOSE)") and j < \
        min(k for k, ln in enumerate(lines) if ln.startswith("G38.2"))
    # the Job's other operation is still in the program, before the probing
    assert sum(1 for ln in lines[:i] if ln.startswith("G1 ")) > 50
    # G38.2 feed: the touch feed in mm/min
    assert re.search(r"^G38\.2 X\S+ Y\S+ Z\S+ F100\.0+ *$", text, re.M)
    # FreeCAD's own Post Process command writes the same probe moves
    native, probes2, worst2 = posted_probes(job, plan, op, tmp_path, "native.ngc", native=True)
    assert len(probes2) == 20 and worst2 <= 0.01
    for a, b in zip(probes, probes2):
        np.testing.assert_allclose(a[1], b[1], atol=1e-4, rtol=0)
    assert "M6 T99" in native and "(PROBEOPEN probe.log)" in native


def test_the_operation_follows_the_plan(shop, tmp_path):
    job, plan = block_plan(shop, "5x4")
    op = add_probe_operation(job, plan)
    plan.Count = "3x3"
    plan.TipRadius = 2.0
    # the probe's ball follows the plan's (the tool controller of another ball is refused:
    # test_the_probe_is_the_plans_ball)
    op.ToolController.Tool.Diameter = 4.0
    # a plan changed but not recomputed: the operation's moves are the old plan's, and the
    # post says so instead of writing them
    with pytest.raises(InputError, match="MeasurementPlan is out of date"):
        post_probe_job(job, "linuxcnc", POST_ARGS)
    progress.recompute_with_progress(shop, "test")
    assert plan.Kept == 9 and op.Probes == 9
    _text, probes, worst = posted_probes(job, plan, op, tmp_path, "again.ngc")
    assert len(probes) == 9 and worst <= 0.01
    # saved and reopened, the moves are the same (FreeCAD keeps 6 decimals)
    path = str(tmp_path / "saved.FCStd")
    before = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
    shop.saveAs(path)
    name, plan_name = op.Name, plan.Name
    FreeCAD.closeDocument(shop.Name)
    doc, _r, _i = documents.open_document(path)
    try:
        again = doc.getObject(name)
        assert is_probe_operation(again) and again.Plan.Name == plan_name
        after = [(c.Name, dict(c.Parameters)) for c in again.Path.Commands]
        assert [n for n, _p in after] == [n for n, _p in before]
        np.testing.assert_allclose([v for _n, p in after for v in p.values()],
                                   [v for _n, p in before for v in p.values()],
                                   atol=1e-6, rtol=0)
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_no_claim_without_moves(shop):
    job, plan = block_plan(shop, "4x4")
    op = add_probe_operation(job, plan)
    # a post that drops comments would probe and log nothing: refused
    with pytest.raises(GCodeError, match=r"wrote 16 G38.2, 0 PROBEOPEN, 0 PROBECLOSE where "
                                         r"the probe operations need 16 G38.2, 1 PROBEOPEN"):
        post_probe_job(job, "linuxcnc", POST_ARGS + " --no-comments")
    # an empty log file name would write "(PROBEOPEN )": refused, the field named by its
    # label as the GUI shows it
    from surfcomp.gui import option_labels

    op.LogFile = ""
    with pytest.raises(InputError) as err:
        probe_moves(op)
    assert option_labels.shown(err.value) == ("Log file '': expected the name of the file "
                                              "LinuxCNC writes the probe log to")
    op.LogFile = "probe.log"
    # a plan the probe cannot reach from above (all points dropped) fails, and so does the
    # post: the operation's old moves are never posted
    plan.MaxTilt = 0.001
    progress.recompute_with_progress(shop, "test")
    with pytest.raises(InputError, match="did not recompute"):
        post_probe_job(job, "linuxcnc", POST_ARGS)
    assert op.Probes in (0, 16)
    with pytest.raises(InputError, match=r"tool 0: expected a whole number from 1 to 9999"):
        add_probe_operation(job, plan, tool=0)


def test_the_probe_is_the_plans_ball(shop, tmp_path):
    job, plan = block_plan(shop, "3x3")
    # tool 1 is the Job's ball end mill: its spindle turns at 10000 rpm, so the probe moves
    # would run with it turning (the post wrote no M5 and no tool change before G38.2)
    with pytest.raises(InputError, match=r"TC: Ball end 6 mm turns the spindle \(Forward, "
                                         r"10000 rpm\)"):
        add_probe_operation(job, plan, tool=1)
    assert not any(is_probe_operation(o) for o in job.Operations.Group)
    op = add_probe_operation(job, plan)
    # the plan's ball changes, the probe's does not: the program's tip centres would be
    # those of a 4 mm ball probed with a 2 mm one
    plan.TipRadius = 2.0
    progress.recompute_with_progress(shop, "test")
    with pytest.raises(InputError, match=r"TC: Probe T99's tool is 2 mm across, but "
                                         r"measurement plan MeasurementPlan has TipRadius 2 mm "
                                         r"\(expected a 4 mm ball"):
        post_probe_job(job, "linuxcnc", POST_ARGS)
    op.ToolController.Tool.Diameter = 4.0
    progress.recompute_with_progress(shop, "test")
    assert op.Probes == 9 and post_probe_job(job, "linuxcnc", POST_ARGS).count("G38.2") == 9
    # a spindle turned on after the operation was made: refused at the post
    op.ToolController.SpindleDir = "Forward"
    op.ToolController.SpindleSpeed = 1000.0
    with pytest.raises(InputError, match="turns the spindle"):
        post_probe_job(job, "linuxcnc", POST_ARGS)


def test_the_probe_runs_in_the_jobs_work_offset_in_mm(shop, tmp_path):
    job, plan = block_plan(shop, "3x3")
    op = add_probe_operation(job, plan)
    # two fixtures: each pass would probe the G54 part (the operation's own G54) and the
    # second PROBEOPEN would overwrite the first log
    job.Fixtures = ["G54", "G55"]
    with pytest.raises(InputError, match=r"ProbePlan probes in G54 \(its WorkOffset\) but "
                                         r"Job Job machines in G54, G55"):
        post_probe_job(job, "linuxcnc", POST_ARGS)
    # the Job moved to G55 after the operation was added: the part would be probed in G54
    job.Fixtures = ["G55"]
    with pytest.raises(InputError, match="machines in G55: the program would probe another "
                                         "part's offset"):
        post_probe_job(job, "linuxcnc", POST_ARGS)
    # the operation's recompute refuses it too (FreeCAD's own Post Process checks nothing):
    # no probe moves are left to post
    op.touch()
    recompute_probing(op)
    assert "Invalid" in op.State and len(op.Path.Commands) == 0
    op.WorkOffset = "G55"
    progress.recompute_with_progress(shop, "test")
    text, probes, _worst = posted_probes(job, plan, op, tmp_path, "g55.ngc")
    lines = [ln.strip() for ln in text.splitlines()]
    k = lines.index("(PROBEOPEN probe.log)")
    assert len(probes) == 9 and "G55" in lines[k - 3:k] and "G54" not in lines
    # an inch post: LinuxCNC would log the trip points in inches, joined to a plan in mm
    with pytest.raises(GCodeError, match=r"wrote an inch program \(G20\)"):
        post_probe_job(job, "linuxcnc", POST_ARGS + " --inches")
    # the Job's own post arguments in inches: refused at the operation's recompute
    job.PostProcessorArgs = "--no-show-editor --inches"
    op.touch()
    recompute_probing(op)
    assert "Invalid" in op.State and len(op.Path.Commands) == 0


def test_no_post_of_a_stale_or_overwritten_log(shop):
    job, plan = block_plan(shop, "3x3")
    block = shop.getObject("Block")
    add_probe_operation(job, plan)
    safe = plan.SafeZ
    # the nominal moved but the document was not recomputed: the plan is not touched
    # itself, yet its points are those of the old nominal
    shape = block.Shape.copy()
    shape.translate(FreeCAD.Vector(0, 0, 1))
    block.Shape = shape
    with pytest.raises(InputError, match=r"Block, the input of MeasurementPlan, is out of "
                                         r"date: recompute the document"):
        post_probe_job(job, "linuxcnc", POST_ARGS)
    progress.recompute_with_progress(shop, "test")
    assert abs(plan.SafeZ - (safe + 1.0)) < 1e-6
    # a second plan gets a log file of its own; logging to the same file would overwrite
    # the first one's log: the operation's recompute refuses it (FreeCAD's own Post
    # Process checks nothing), and so does the post
    plan2 = make_measurement_plan(shop, block, "Face2", Layout="grid", Count="2x2")
    progress.recompute_with_progress(shop, "test")
    op2 = add_probe_operation(job, plan2, name="ProbeTwo")
    assert op2.LogFile == "probe-ProbeTwo.log"
    op2.LogFile = "probe.log"
    recompute_probing(op2)
    assert "Invalid" in op2.State and len(op2.Path.Commands) == 0
    with pytest.raises(InputError, match=r"ProbePlan and ProbeTwo both log to probe.log"):
        post_probe_job(job, "linuxcnc", POST_ARGS)
    op2.LogFile = "probe2.log"
    progress.recompute_with_progress(shop, "test")
    text = post_probe_job(job, "linuxcnc", POST_ARGS)
    assert text.count("G38.2") == 13 and "(PROBEOPEN probe2.log)" in text


def test_replacing_the_nominal_leaves_the_plan_on_it(shop):
    from surfcomp.app import replace

    job, plan = block_plan(shop, "3x3")
    block = shop.getObject("Block")
    add_probe_operation(job, plan)
    before = plan_arrays(plan)[0]
    mirror = shop.addObject("Part::Mirroring", "Mirror")     # a user the replace rebinds
    mirror.Source = block
    changed = replace.replace(shop, shop.getObject("Round1"))
    progress.recompute_with_progress(shop, "test")
    # the plan's points are nominal points: deviations are against the nominal, never
    # against the corrected face (which lies up to 29 um from it here)
    assert [tuple(c) for c in changed] == [("Mirror", "Source")]
    assert plan.Nominal is block
    np.testing.assert_allclose(plan_arrays(plan)[0], before, atol=1e-12, rtol=0)
    assert post_probe_job(job, "linuxcnc", POST_ARGS).count("G38.2") == 9
