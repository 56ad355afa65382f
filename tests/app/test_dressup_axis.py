# SPDX-License-Identifier: LGPL-2.1-or-later
"""The axis-error compensation dressup on real Path operations, headless."""

import json
import os
import subprocess

import FreeCAD
import numpy as np
import Part
import Path
import pytest

from surfcomp.app import cam, dressup_axis
from surfcomp.core.axis.axis_errors import AxisErrorModel, SimulatedMachine
from surfcomp.errors import GCodeError
from surfcomp.io.axis_csv import write_axis_errors
from tests.conftest import ROOT

MOVES = ("G0", "G00", "G1", "G01", "G2", "G02", "G3", "G03")


def machine_model():
    """Errors of a few tens of um over the box: scale, squareness, quadratic Z, flatness."""
    return AxisErrorModel.from_components(
        scale={"x": 1e-3, "y": -5e-4}, positional={"z": (0.0, 2e-5)},
        straightness={"z(x)": (0.0, 1e-6)}, squareness={"xy": 1e-4, "zx": 2e-4})


def measured(model):
    return SimulatedMachine(model).measure({"x": np.linspace(-10, 50, 7),
                                            "y": np.linspace(-10, 40, 6),
                                            "z": np.linspace(-5, 20, 6)})


@pytest.fixture
def home():
    """Path finds its post-processors and tool-bit shapes under FreeCAD.getHomePath(),
    which is the library folder when FreeCAD is imported from python3 (cam fixes it)."""
    return cam.setup_workbench(require_ocl=False)


@pytest.fixture
def doc():
    d = FreeCAD.newDocument("axisdressup")
    yield d
    FreeCAD.closeDocument(d.Name)


def profile_job(doc):
    box = doc.addObject("Part::Box", "Box")
    box.Length, box.Width, box.Height = 40, 30, 10
    doc.recompute()
    job = cam.create_job(doc, [box])
    tc = job.Tools.Group[0]
    tc.HorizFeed = 600       # a bare number is taken in the internal unit, mm/s
    tc.VertFeed = 120
    op = cam.create_operation("Profile", "Profile", job)
    doc.recompute()
    assert len(op.Path.Commands) > 20
    return job, op


def move_points(cmds):
    """Absolute end points of the move commands (mm), modal axes carried over."""
    pos = [np.nan, np.nan, np.nan]
    out = []
    for c in cmds:
        if c.Name in MOVES:
            for a, L in enumerate("XYZ"):
                if L in c.Parameters:
                    pos[a] = c.Parameters[L]
            out.append(list(pos))
    return np.array(out)


def base_edges(cmds):
    pos = FreeCAD.Vector(0, 0, 0)
    edges = []
    for c in cmds:
        if c.Name in MOVES:
            e = cam.edge_for_command(c, pos)
            if e is not None:
                edges.append(e)
            pos = cam.command_end_point(c, pos)
    return Part.Compound(edges)


def feeds(cmds):
    f = [c.Parameters["F"] for c in cmds if c.Name in MOVES[2:] and "F" in c.Parameters]
    return [v for k, v in enumerate(f) if k == 0 or v != f[k - 1]]


def test_dressup_on_a_profile_operation(home, doc):
    job, op = profile_job(doc)
    model = machine_model()
    d = dressup_axis.Create(op, measured(model))
    assert d.Name.startswith("DressupAxisErrors")
    assert job.Operations.Group == [d] and d.Base == op
    doc.recompute()
    assert "Invalid" not in d.State and "Error" not in d.State
    base, out = op.Path.Commands, d.Path.Commands
    # arcs were turned into G1 pieces; every cutting piece keeps its feed (mm/s)
    assert any(c.Name == "G2" for c in base)
    assert not any(c.Name in ("G2", "G3") for c in out)
    assert feeds(out) == feeds(base) == [120.0, 600.0] * 3
    cutting = [c for c in out if c.Name == "G1"]
    assert all("F" in c.Parameters for c in cutting)
    # comments, tool and spindle commands are kept in order
    others = [(c.Name, c.Parameters) for c in base if c.Name not in MOVES]
    assert [(c.Name, c.Parameters) for c in out if c.Name not in MOVES] == others
    # the machine with these errors brings every command onto the base's tool path:
    # distance (OCCT) from the landed points to the base path's edges
    pts = move_points(out)
    known = ~np.isnan(pts).any(axis=1)
    landed = model.actual(pts[known])
    edges = base_edges(base)
    dist = [edges.distToShape(Part.Vertex(*p))[0] for p in landed]
    assert max(dist) < 1e-3 + 1e-6           # arc tolerance (chords) + numerics
    # without compensation the same points miss the path by up to ~47 um
    raw = [edges.distToShape(Part.Vertex(*p))[0] for p in model.actual(move_points(base)[
        ~np.isnan(move_points(base)).any(axis=1)])]
    assert max(raw) > 0.03
    assert d.ErrorBefore.Value > 0.03 and d.ErrorAfter.Value < 1e-9
    assert d.MaxCorrection.Value == pytest.approx(d.ErrorBefore.Value, rel=0.05)
    assert any("delta_z(z)" in s for s in d.FitSummary)
    # without a base: an empty path, and none of the figures above kept (nor the warnings
    # of an earlier run: they described a path that is gone)
    d.Warnings = ["a warning of the run before"]
    d.Base = None
    doc.recompute()
    assert d.Path.Commands == [] and d.FitSummary == [] and d.Warnings == []
    assert d.ErrorBefore.Value == d.ErrorAfter.Value == d.MaxCorrection.Value == 0.0


def test_zero_errors_leave_the_path_unchanged(home, doc):
    _job, op = profile_job(doc)
    zero = {"x": (np.array([0.0, 50.0]), np.zeros((2, 3)))}
    d = dressup_axis.Create(op, zero)
    doc.recompute()
    assert d.Path.toGCode() == op.Path.toGCode()
    assert d.MaxCorrection.Value == 0.0


def hand_made_base(doc, extra=()):
    base = doc.addObject("Path::Feature", "Hand")
    cmds = [Path.Command("(hand made)"), Path.Command("M6", {"T": 2.0}),
            Path.Command("M3", {"S": 8000.0}), Path.Command("G0", {"X": 0.0, "Y": 0.0}),
            Path.Command("G0", {"Z": 5.0}), Path.Command("G1", {"Z": -1.0, "F": 3.0}),
            Path.Command("G1", {"X": 30.0, "Y": 0.0, "Z": -1.0, "F": 12.0}),
            Path.Command("G3", {"X": 30.0, "Y": 20.0, "I": 0.0, "J": 10.0, "F": 12.0}),
            Path.Command("G0", {"Z": 5.0})] + list(extra)
    base.Path = Path.Path(cmds)
    return base


def test_data_lives_in_the_document_and_old_documents_upgrade(tmp_path):
    doc = FreeCAD.newDocument("olddoc")
    model = machine_model()
    csv = tmp_path / "axis.csv"
    write_axis_errors(str(csv), measured(model), units="um")
    base = hand_made_base(doc)
    d = dressup_axis.Create(base, str(csv))
    assert d.SourceFile == str(csv)
    os.unlink(csv)                       # the data is in the document, not in the file
    doc.recompute()
    n = len(d.Path.Commands)
    assert n > 10 and "Invalid" not in d.State
    # make it look like an older document: no ArcTolerance, version 0
    name = d.Name
    d.removeProperty("ArcTolerance")
    d.Version = 0
    path = str(tmp_path / "old.FCStd")
    doc.saveAs(path)
    FreeCAD.closeDocument(doc.Name)
    old = FreeCAD.openDocument(path)
    try:
        r = old.getObject(name)
        assert isinstance(r.Proxy, dressup_axis.DressupAxisErrors)
        assert r.Version == dressup_axis.VERSION
        assert r.ArcTolerance.Value == pytest.approx(1e-3)
        assert len(r.MeasuredPosition) == 7 + 6 + 6
        r.touch()
        old.recompute()
        assert len(r.Path.Commands) == n
        assert feeds(r.Path.Commands) == [3.0, 12.0]
        # changing the model choice recomputes from the stored data
        r.Model = "linear"
        old.recompute()
        assert "Invalid" not in r.State
    finally:
        FreeCAD.closeDocument(old.Name)


def test_unsupported_base_commands_are_refused(doc):
    base = hand_made_base(doc, [Path.Command("G81", {"X": 5.0, "Y": 5.0, "Z": -3.0,
                                                     "R": 1.0})])
    d = dressup_axis.Create(base, measured(machine_model()))
    d.Label = "Comp"
    with pytest.raises(GCodeError, match=r"^Comp \(on Hand\):10: G81: canned cycles"):
        dressup_axis.compensate_path(d)


SCRIPT = r"""
import json, sys
sys.path.insert(0, ROOT)
import FreeCAD, Path
import numpy as np
from surfcomp.app import cam, dressup_axis
from surfcomp.core.axis.axis_errors import AxisErrorModel, SimulatedMachine
doc = FreeCAD.newDocument("cmd")
box = doc.addObject("Part::Box", "Box")
doc.recompute()
job = cam.create_job(doc, [box])
job.Tools.Group[0].HorizFeed = 600
op = cam.create_operation("Profile", "Profile", job)
doc.recompute()
m = AxisErrorModel.from_components(scale={"x": 1e-3}, positional={"z": (0.0, 2e-5)})
data = SimulatedMachine(m).measure({"x": np.linspace(0, 20, 5), "z": np.linspace(-5, 15, 5)})
d = dressup_axis.Create(op, data)
doc.recompute()
print("RESULT " + json.dumps({"state": list(d.State), "gui": FreeCAD.GuiUp,
      "n_base": len(op.Path.Commands), "n": len(d.Path.Commands),
      "g2": sum(c.Name == "G2" for c in d.Path.Commands),
      "f": sorted({c.Parameters.get("F") for c in d.Path.Commands if c.Name == "G1"}),
    "f_base": sorted({c.Parameters.get("F") for c in op.Path.Commands
                      if c.Name in ("G1", "G2", "G3")})}))
"""


def test_recomputes_in_freecadcmd(tmp_path):
    script = tmp_path / "run.py"
    script.write_text("ROOT = %r\n" % ROOT + SCRIPT)
    out = subprocess.run(["freecadcmd", str(script)], capture_output=True, text=True,
                         timeout=300, cwd=str(tmp_path))
    line = [s for s in out.stdout.replace("\r", "\n").split("\n") if "RESULT " in s]
    assert line, out.stdout[-2000:] + out.stderr[-2000:]
    r = json.loads(line[-1].split("RESULT ", 1)[1])
    assert not r["gui"]
    assert "Invalid" not in r["state"]
    assert r["g2"] == 0 and r["n"] > r["n_base"]
    assert r["f"] == r["f_base"] == [600.0]
