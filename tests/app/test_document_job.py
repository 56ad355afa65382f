# SPDX-License-Identifier: LGPL-2.1-or-later
"""The batch route on a shop document: open, compensate, replace, regenerate, save, post."""

import hashlib
import os
import re
import sys
import time

import FreeCAD
import numpy as np
import pytest

from surfcomp.app import cam, cam_job, documents, features
from surfcomp.app.document_route import run_document_job, summary_lines
from surfcomp.app.nominal import nominal_from_face
from surfcomp.core.compensation.pipeline import Options
from surfcomp.errors import ComputationError, InputError, MeasurementFileError
from tests.app.helpers import grid_on_face, write_cmm_csv
from tests.app.test_features import add_part, block_solid, error_model
from tests.app.test_path_regen import g1_points

POST_ARGS = "--no-show-editor --no-header --precision=4"


def sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


@pytest.fixture(scope="module")
def shop(tmp_path_factory):
    """shop.FCStd: a block under a Job with a 3D Surface op on Face2; meas.csv for Face2."""
    tmp = tmp_path_factory.mktemp("shop")
    cam.setup_workbench()
    doc = FreeCAD.newDocument("shop")
    solid = block_solid()
    add_part(doc, solid, "Block")
    job = cam_job.create_job(doc, [doc.getObject("Block")])
    tc = cam_job.ball_end_tool_controller(job, 6.0)
    op = cam_job.surface_operation(job, doc.getObject("Block"), ["Face2"], tc, step_over=100.0,
                                   sample_interval=2.0, linear_deflection=0.005)
    doc.recompute()
    cam_job.model_clone(job, doc.getObject("Block")).touch()   # settle Path's stock box
    doc.recompute()
    cl = cam_job.cutter_locations(op)
    gcode = cam_job.post_process(job, "linuxcnc", POST_ARGS)
    path = str(tmp / "shop.FCStd")
    doc.saveAs(path)
    FreeCAD.closeDocument(doc.Name)
    nominal = nominal_from_face(solid.Faces[1], face_name="Face2")
    P, N, _, _ = grid_on_face(nominal, 15, 15, margin=0.0)
    meas = str(tmp / "meas.csv")
    write_cmm_csv(meas, P, N, error_model(P))
    return {"doc": path, "meas": meas, "cl": cl, "gcode": gcode, "dir": tmp}


def test_update_a_shop_document(shop, tmp_path):
    digest = sha(shop["doc"])
    out, ngc = str(tmp_path / "out.FCStd"), str(tmp_path / "out.ngc")
    res = run_document_job(shop["doc"], shop["meas"], "Block", face="Face2", save=out,
                           replace=True, gcode=ngc, post="linuxcnc", post_args=POST_ARGS,
                           options=Options(refine=1))
    assert sha(shop["doc"]) == digest                       # the input is untouched
    assert res.saved == out and res.gcode == ngc and res.jobs == ["Job"]
    # the summary's volume figures: the change, and -integral(delta dA) named as such (the
    # correction cuts here: its integral, CorrVol, is positive)
    assert res.correction_volume > 1.0
    assert ("volume change %.4f mm^3, expected from the correction %.4f mm^3 (-integral of "
            "delta dA)" % (res.volume_change, -res.correction_volume)) in \
        "\n".join(summary_lines(res))
    assert res.operations == ["Surface"] and res.replaced == [("Clone", "Objects")]
    assert res.statistics["deviation"]["count"] == 225
    assert res.checks["max_error_at_points_mm"] < 1e-4
    assert sorted(os.listdir(tmp_path)) == ["out.FCStd", "out.ngc"]     # no temporary files
    doc = FreeCAD.openDocument(out)
    try:
        assert documents.restore_failures(doc, out) == []
        comp = doc.getObject(res.compensation)
        assert features.is_compensation(comp) and comp.Output == "solid"
        # every option of the run is on the object (options_of reads them all back)
        assert features.options_of(comp) == Options(refine=1, stock=0.0, context="document")
        assert comp.Measurement.SourceName == "meas.csv" and comp.Measurement.PointCount == 225
        clone = doc.getObject("Clone")
        assert clone.Objects == [comp] and doc.getObject("Block").Visibility is False
        assert len(clone.Shape.Faces) == 6 and clone.Shape.isValid()
        op = doc.getObject("Surface")
        assert op.Base == [(clone, ("Face2",))]
        # the report counts the commands that changed: most moved with the correction
        (job_rep,) = res.toolpaths
        (op_rep,) = job_rep.operations
        assert (job_rep.name, job_rep.lost, op_rep.name, op_rep.status) == \
            ("Job", [], "Surface", "regenerated")
        assert op_rep.commands == len(op.Path.Commands)
        assert 0.5 * op_rep.commands < op_rep.changed <= op_rep.commands
        cl = cam_job.cutter_locations(op)
        # the regenerated path went down where the correction removes material (t > 0)
        assert abs(len(cl) - len(shop["cl"])) <= 0.05 * len(cl)
        corr = np.asarray(comp.Correction)
        assert corr.max() > 0.02
        from scipy.spatial import cKDTree
        d, k = cKDTree(shop["cl"][:, :2]).query(cl[:, :2])
        dz = (cl[:, 2] - shop["cl"][k, 2])[d < 0.05]
        assert dz.size > 0.5 * len(cl)
        assert -0.06 < dz.min() < -0.01 and dz.max() < 0.03
    finally:
        FreeCAD.closeDocument(doc.Name)
    # the written program is the saved document's program (FreeCAD stores paths with
    # fewer digits, so a last 4th decimal may differ by one)
    text = open(ngc).read()
    again = cam_gcode_of(out)
    np.testing.assert_allclose(g1_points(text), g1_points(again), atol=1.01e-4)
    assert [s for s in text.splitlines() if not s.startswith("G1 ")] == \
        [s for s in again.splitlines() if not s.startswith("G1 ")]
    assert text != shop["gcode"] and text.count("\nG1 ") > 50


def cam_gcode_of(path):
    doc = FreeCAD.openDocument(path)
    try:
        return cam_job.post_process(doc.getObject("Job"), "linuxcnc", POST_ARGS)
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_never_overwrites_the_input(shop, tmp_path):
    before = set(FreeCAD.listDocuments())    # a session fixture's documents may be open
    digest = sha(shop["doc"])
    with pytest.raises(InputError,
                       match=r"--save would overwrite the input document \(--overwrite-input"):
        run_document_job(shop["doc"], shop["meas"], "Block", face="Face2",
                         save=shop["doc"])
    with pytest.raises(InputError, match="need --save"):
        run_document_job(shop["doc"], shop["meas"], "Block", face="Face2")
    assert sha(shop["doc"]) == digest
    assert set(FreeCAD.listDocuments()) == before      # the route left nothing open


def test_bad_measurements_write_nothing(shop, tmp_path):
    before = set(FreeCAD.listDocuments())
    bad = tmp_path / "bad.csv"
    bad.write_text("x_nom,y_nom,z_nom,i,j,k,dev\n1,2,3,0,0,1,0.01\n1,2,abc,0,0,1,0.02\n")
    with pytest.raises(MeasurementFileError, match=r"bad.csv:3"):
        run_document_job(shop["doc"], str(bad), "Block", face="Face2",
                         save=str(tmp_path / "o.FCStd"), gcode=str(tmp_path / "o.ngc"))
    assert sorted(os.listdir(tmp_path)) == ["bad.csv"]
    with pytest.raises(Exception, match="no object 'Nope'"):
        run_document_job(shop["doc"], shop["meas"], "Nope", save=str(tmp_path / "o.FCStd"))
    assert set(FreeCAD.listDocuments()) == before      # the route left nothing open


PROXY_MODULE = '''
class Thing:
    def __init__(self, obj):
        obj.Proxy = self
    def execute(self, obj):
        pass
    def __getstate__(self):
        return None
    def __setstate__(self, state):
        return None
'''


def test_refuses_a_document_whose_objects_did_not_restore(shop, tmp_path, monkeypatch):
    """An object whose proxy module is not importable at open time loses its proxy; saving
    would make that loss permanent, so the route refuses and writes nothing."""
    before = set(FreeCAD.listDocuments())
    mod_dir = tmp_path / "mods"
    mod_dir.mkdir()
    (mod_dir / "surfcomp_test_gone.py").write_text(PROXY_MODULE)
    monkeypatch.syspath_prepend(str(mod_dir))
    import surfcomp_test_gone

    doc = FreeCAD.openDocument(shop["doc"])
    thing = doc.addObject("App::FeaturePython", "Thing")
    surfcomp_test_gone.Thing(thing)
    broken = str(tmp_path / "broken.FCStd")
    doc.saveAs(broken)
    FreeCAD.closeDocument(doc.Name)
    del sys.modules["surfcomp_test_gone"]
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p != str(mod_dir)])
    (mod_dir / "surfcomp_test_gone.py").unlink()
    out = tmp_path / "out.FCStd"
    with pytest.raises(InputError, match=r"1 object\(s\) did not restore.*Thing "
                                         r"\(App::FeaturePython, label 'Thing'\): its Python "
                                         r"proxy was not restored"):
        run_document_job(broken, shop["meas"], "Block", face="Face2", save=str(out))
    assert not out.exists()
    assert set(FreeCAD.listDocuments()) == before      # the route left nothing open


def test_the_batch_command_line(shop, tmp_path):
    """The issue's command: compensate DOC MEAS --object --face --replace --save --gcode --post."""
    import subprocess

    from tests.app.helpers import ROOT

    digest = sha(shop["doc"])
    out, ngc = tmp_path / "out.FCStd", tmp_path / "out.ngc"
    cmd = [sys.executable, "-m", "surfcomp", "compensate", shop["doc"], shop["meas"],
           "--object", "Block", "--face", "Face2", "--replace", "--save", str(out),
           "--gcode", str(ngc), "--post", "linuxcnc", "--post-args", POST_ARGS, "--refine", "1",
           "--format", "table", "--quiet"]
    run = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    assert "replaced the nominal in: Clone.Objects" in run.stdout
    assert re.search(r"^Path job Job: Surface regenerated \((\d+) of (\d+) commands changed\)$",
                     run.stdout, re.M) and "wrote %s" % out in run.stdout
    assert sha(shop["doc"]) == digest
    # the same program as the library route of test_update_a_shop_document
    np.testing.assert_allclose(g1_points(ngc.read_text()), g1_points(cam_gcode_of(str(out))),
                               atol=1.01e-4)
    assert ngc.read_text() != shop["gcode"]
    # files and the document route do not mix; the input is refused as output
    bad = subprocess.run(cmd[:-1] + ["-o", str(tmp_path / "c.step")], cwd=ROOT,
                         capture_output=True, text=True, timeout=600)
    assert bad.returncode == 2 and "cannot be combined" in bad.stderr
    bad = subprocess.run(cmd[:10] + ["--save", shop["doc"], "--quiet"], cwd=ROOT,
                         capture_output=True, text=True, timeout=600)
    assert bad.returncode == 2 and sha(shop["doc"]) == digest
    # the reader options reach the measurement reader: a CSV read as XYZIJK is refused
    bad = subprocess.run(cmd[:-3] + ["--format", "xyzijk", "--quiet"], cwd=ROOT,
                         capture_output=True, text=True, timeout=600)
    assert bad.returncode == 2 and "XYZIJK" in bad.stderr and sha(shop["doc"]) == digest


@pytest.fixture(scope="module")
def no_tool(shop):
    """The shop document with its tool controller's tool number 0: FreeCAD's operations log
    "No Tool Controller is selected" and return, keeping their old path, in an object FreeCAD
    marks recomputed without error."""
    path = str(shop["dir"] / "no_tool.FCStd")
    doc = documents.open_document(shop["doc"])[0]
    try:
        doc.getObject("Surface").ToolController.ToolNumber = 0
        doc.saveAs(path)
    finally:
        FreeCAD.closeDocument(doc.Name)
    return path


def test_a_cam_error_refuses_the_route_and_writes_nothing(shop, no_tool, tmp_path):
    digest = sha(no_tool)
    out, ngc = str(tmp_path / "out.FCStd"), str(tmp_path / "out.ngc")
    with pytest.raises(ComputationError) as err:
        run_document_job(no_tool, shop["meas"], "Block", face="Face2", save=out, replace=True,
                         gcode=ngc, post="linuxcnc", post_args=POST_ARGS,
                         options=Options(refine=1))
    # before: "Path job Job: Surface tool path unchanged", and the nominal's program written
    assert "Surface (Surface): the CAM workbench reported: No Tool Controller is selected" \
        in str(err.value)
    assert os.listdir(tmp_path) == [] and sha(no_tool) == digest


@pytest.mark.parametrize("route", ["in process", "child process"])
def test_a_cam_error_is_reported_as_failed_not_unchanged(shop, no_tool, route):
    """Replace and Restore in the GUI recompute in this process or in a child, then say what
    happened to each operation (surfcomp.app.toolpaths)."""
    from surfcomp.app import progress, recompute, toolpaths

    doc = documents.open_document(no_tool)[0]
    try:
        op = doc.getObject("Surface")
        before = toolpaths.snapshot(doc)
        op.touch()
        if route == "in process":
            progress.recompute_with_progress(doc, route)
        else:
            job = recompute.ChildRecompute(doc).start()
            while job.poll():
                time.sleep(0.05)
            job.finish()
        (rep,) = toolpaths.compare(doc, before)
        (found,) = rep.operations
        assert found.status == "failed", found
        assert found.detail == ("the CAM workbench reported: No Tool Controller is selected. "
                                "We need a tool to build a Path.")
        assert toolpaths.describe([rep]) == [
            "Path job %s: Surface NOT regenerated, it failed: %s" % (rep.label, found.detail)]
        assert "Touched" in op.State        # not marked as recomputed
        # a next command that does not recompute it does not report that failure again
        (rep,) = toolpaths.compare(doc, toolpaths.snapshot(doc))
        assert rep.operations[0].status == "unchanged"
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_a_document_open_in_this_session_is_refused_and_left_alone(shop, tmp_path):
    """FreeCAD hands back a document that is open already instead of reading the file: the
    route would add its objects to the user's open document and replace its nominal there
    (before: it did, and left them there when it failed later, e.g. on an unknown --job)."""
    from surfcomp.app.region_docroute import run_region_document

    doc = documents.open_document(shop["doc"])[0]
    try:
        names = [o.Name for o in doc.Objects]
        out, ngc = str(tmp_path / "out.FCStd"), str(tmp_path / "out.ngc")
        for run in (lambda: run_document_job(shop["doc"], shop["meas"], "Block", face="Face2",
                                             save=out, replace=True, gcode=ngc,
                                             job_name="Nope"),
                    lambda: run_region_document(shop["doc"], shop["meas"], "Block", "Face2",
                                                save=out, replace=True)):
            with pytest.raises(InputError, match=r"shop.FCStd: the document is open in this "
                                                 r"FreeCAD session \(as shop\).*nothing was "
                                                 r"changed.*save and close it first"):
                run()
            assert [o.Name for o in doc.Objects] == names
            assert doc.getObject("Clone").Objects == [doc.getObject("Block")]
            assert doc.Label == "shop" and doc.Name in FreeCAD.listDocuments()
        assert os.listdir(tmp_path) == []
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_an_unknown_job_name_names_the_jobs_that_use_the_compensation(shop, tmp_path):
    """Before: "no Path jobs use the compensation (none)", although the Job did."""
    digest = sha(shop["doc"])
    with pytest.raises(InputError, match=r"^no Path job named 'Nope' uses the compensation "
                                         r"\(the Jobs that do: Job\); expected one of their "
                                         r"names or labels$"):
        run_document_job(shop["doc"], shop["meas"], "Block", face="Face2",
                         save=str(tmp_path / "o.FCStd"), replace=True,
                         gcode=str(tmp_path / "o.ngc"), job_name="Nope",
                         options=Options(refine=1))
    assert os.listdir(tmp_path) == [] and sha(shop["doc"]) == digest


def test_replace_refuses_a_job_moved_by_a_surface_correction_dressup(shop, tmp_path):
    """The Surface correction dressup moves the operation's program by a correction; with
    the nominal replaced the operation cuts the corrected face, and the dressup moved that
    again (before: the route posted the program moved twice, summary "regenerated")."""
    from surfcomp.app import dressup_surface, replace
    from surfcomp.io.readers import read_any

    dressed = str(tmp_path / "dressed.FCStd")
    doc = documents.open_document(shop["doc"])[0]
    try:
        block = doc.getObject("Block")
        meas = features.make_measurement_from_set(doc, read_any(shop["meas"]))
        first = features.make_compensation(doc, block, "Face2", meas, output="solid",
                                           name="Round1")
        first.Refine = 1
        doc.recompute()
        dressup = dressup_surface.Create(doc.getObject("Surface"), first)
        doc.recompute()
        assert dressup.MovedMoves > 0 and "Invalid" not in dressup.State
        doc.saveAs(dressed)
        # Replace itself (the GUI's) refuses and leaves every link as it was
        second = features.make_compensation(doc, block, "Face2", meas, output="solid")
        second.Refine = 1
        doc.recompute()
        with pytest.raises(InputError, match=r"^Job holds the surface correction dressup "
                                             r"DressupSurfaceCorrection, which moves its "
                                             r"program by the correction of Round1 already"):
            replace.replace(doc, second)
        assert doc.getObject("Clone").Objects == [block] and dressup.Compensation is first
        assert second.ReplacedLinks == "" and block.Visibility
    finally:
        FreeCAD.closeDocument(doc.Name)
    digest = sha(dressed)
    out, ngc = str(tmp_path / "out.FCStd"), str(tmp_path / "out.ngc")
    with pytest.raises(InputError, match="would move that a second time; nothing was replaced"):
        run_document_job(dressed, shop["meas"], "Block", face="Face2", save=out, replace=True,
                         gcode=ngc, post_args=POST_ARGS, options=Options(refine=1))
    assert os.listdir(tmp_path) == ["dressed.FCStd"] and sha(dressed) == digest


def test_the_next_round_stacks_on_the_compensation_the_job_cuts(shop, tmp_path):
    """A document whose nominal a compensation replaces: ``--object`` naming that
    compensation adds its next round (Base), deviations against the nominal; naming the
    nominal with --replace is refused with what to name instead. Before: the nominal was
    refused as used by nothing, and a compensation was taken for a nominal (its corrected
    face measured against, no Base, its earlier correction lost from the record)."""
    first = str(tmp_path / "first.FCStd")
    one = run_document_job(shop["doc"], shop["meas"], "Block", face="Face2", save=first,
                           replace=True, options=Options(refine=1))
    digest = sha(first)
    with pytest.raises(InputError, match=r"first.FCStd: Block is replaced by Compensation now "
                                         r".*expected --object Compensation for the next "
                                         r"round of Compensation, or restore the nominal"):
        run_document_job(first, shop["meas"], "Block", face="Face2",
                         save=str(tmp_path / "o.FCStd"), replace=True)
    with pytest.raises(InputError, match=r"Compensation compensates Block.Face2, not Face3"):
        run_document_job(first, shop["meas"], "Compensation", face="Face3",
                         save=str(tmp_path / "o.FCStd"), replace=True)
    assert sorted(os.listdir(tmp_path)) == ["first.FCStd"] and sha(first) == digest
    second, ngc = str(tmp_path / "second.FCStd"), str(tmp_path / "second.ngc")
    two = run_document_job(first, shop["meas"], "Compensation", save=second, replace=True,
                           gcode=ngc, post_args=POST_ARGS, options=Options(refine=1))
    assert (two.base, two.round, two.output) == ("Compensation", 2, "solid")
    assert "round 2: stacked on Compensation" in "\n".join(summary_lines(two))
    assert two.operations == ["Surface"] and sha(first) == digest
    # the same measurement again: the earlier correction plus about as much again
    assert two.statistics["deviation"]["count"] == 225
    assert two.correction_volume == pytest.approx(2 * one.correction_volume, rel=0.05)
    doc = FreeCAD.openDocument(second)
    try:
        comp, base = doc.getObject(two.compensation), doc.getObject("Compensation")
        assert comp.Base is base and comp.Nominal is doc.getObject("Block")
        assert comp.FaceName == "Face2" and doc.getObject("Clone").Objects == [comp]
        np.testing.assert_allclose(comp.Correction, np.add(base.Correction, comp.Increment),
                                   atol=1e-12)
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_save_where_links_to_other_documents_would_break_is_refused(shop, tmp_path):
    """FreeCAD keeps a link to another document as a path relative to the document's folder,
    also in a copy saved elsewhere: saved in another folder the document reopened without
    the link (before: written, "wrote B/out.FCStd")."""
    here, there = tmp_path / "A", tmp_path / "B"
    here.mkdir()
    there.mkdir()
    parts = FreeCAD.newDocument("parts")
    doc = documents.open_document(shop["doc"])[0]
    try:
        box = parts.addObject("Part::Box", "Fixture")
        parts.recompute()
        parts.saveAs(str(here / "parts.FCStd"))
        doc.saveAs(str(here / "shop.FCStd"))
        doc.addObject("App::Link", "FixtureLink").LinkedObject = box
        doc.recompute()
        doc.save()
    finally:
        FreeCAD.closeDocument(doc.Name)
        FreeCAD.closeDocument(parts.Name)
    source = str(here / "shop.FCStd")
    with pytest.raises(InputError, match=r"out.FCStd: --save in .*B: the document links "
                                         r"objects of .*A/parts.FCStd by a path relative to "
                                         r"its folder.*B/parts.FCStd.*nothing was written. "
                                         r"Expected --save in the document's folder .*A$"):
        run_document_job(source, shop["meas"], "Block", face="Face2",
                         save=str(there / "out.FCStd"), replace=True, options=Options(refine=1))
    assert os.listdir(there) == []
    before = set(FreeCAD.listDocuments())
    run_document_job(source, shop["meas"], "Block", face="Face2", save=str(here / "out.FCStd"),
                     replace=True, options=Options(refine=1))
    doc = FreeCAD.openDocument(str(here / "out.FCStd"))
    try:
        linked = doc.getObject("FixtureLink").LinkedObject
        assert linked is not None and linked.Document.FileName == str(here / "parts.FCStd")
    finally:
        for name in set(FreeCAD.listDocuments()) - before:
            FreeCAD.closeDocument(name)
