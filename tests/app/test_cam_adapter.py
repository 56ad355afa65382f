# SPDX-License-Identifier: LGPL-2.1-or-later
"""The version adapter (surfcomp.app.cam) takes the branch the installed FreeCAD needs, and
each branch works: the version matrix runs this file on 0.20 (PathScripts, Factory tool
bits, PySide2), 1.0 (Path, Factory, PySide2) and 1.1 (Path, tool-bit library, PySide6)."""

import importlib.util
import os

import FreeCAD
import pytest

from surfcomp.app import cam
from surfcomp.errors import GCodeError


@pytest.fixture(scope="module")
def home():
    return cam.setup_workbench()


@pytest.fixture
def doc():
    d = FreeCAD.newDocument("camadapter")
    yield d
    FreeCAD.closeDocument(d.Name)


def test_branches_follow_what_is_installed(home):
    b = cam.branches()
    has_cam_folder = os.path.isdir(os.path.join(home, "Mod", "CAM"))
    assert b["modules"] == ("Path" if has_cam_folder else "PathScripts")
    assert b["toolbits"] == ("library" if cam._has_module("Path.Tool.toolbit") else "Factory")
    assert b["qt"] == ("PySide6" if importlib.util.find_spec("PySide6") else "PySide2")
    # what the releases of the matrix have (the branch is never chosen from this number)
    version = tuple(int(x) for x in FreeCAD.Version()[:2])
    expected = {(0, 20): ("PathScripts", "Factory"), (1, 0): ("Path", "Factory"),
                (1, 1): ("Path", "library")}
    if version in expected:
        assert (b["modules"], b["toolbits"]) == expected[version]
    # every module the adapter uses on this branch imports
    unused = "ToolBit" if b["toolbits"] == "library" else "toolbit"
    for role, name in cam.api().names.items():
        if role != unused:
            assert cam.module(role) is importlib.import_module(name)


def test_ball_end_bit_and_tool_controller(home, doc):
    bit = cam.create_tool_bit(doc, cam.BALL_END_BIT, "Ball")
    bit.Diameter = 4.0
    tc = cam.create_tool_controller("TC: Ball", bit, 3)
    doc.recompute()
    assert tc.Tool is bit and tc.ToolNumber == 3
    assert abs(float(tc.Tool.Diameter) - 4.0) < 1e-12
    # the bit's shape: BitShape file (0.20, 1.0) or ShapeID of the asset library (1.1)
    shape = bit.ShapeID if "ShapeID" in bit.PropertiesList else bit.BitShape
    assert "ball" in str(shape).lower()
    with pytest.raises(Exception, match="not installed"):
        cam.create_tool_bit(doc, "no_such_bit.fctb", "x")


def test_post_processor_scripts_load_fresh(home):
    posts = cam.available_posts()
    assert {"linuxcnc", "grbl"} <= set(posts)
    a, b = cam.load_post("linuxcnc"), cam.load_post("linuxcnc")
    assert callable(a.export) and a is not b          # options live in module globals
    with pytest.raises(GCodeError, match="unknown post-processor 'nope'.*linuxcnc"):
        cam.load_post("nope")


def test_profile_operation_and_helpers(home, doc):
    import Part

    box = doc.addObject("Part::Box", "Box")
    doc.recompute()
    job = cam.create_job(doc, [box])
    op = cam.create_operation("Profile", "Profile", job)
    doc.recompute()
    assert cam.find_parent_job(op) is job
    assert cam.base_operation(op) is op
    cmds = cam.placed_commands(op)
    assert len(cmds) > 10
    # the geometry helpers draw the profile around the 10 x 10 box (offset by the tool)
    pos = FreeCAD.Vector(0, 0, 0)
    edges = []
    for c in cmds:
        e = cam.edge_for_command(c, pos) if c.Name in ("G1", "G2", "G3") else None
        if e is not None:
            edges.append(e)
        pos = cam.command_end_point(c, pos)
    box_xy = Part.Compound(edges).BoundBox
    assert 10.0 < box_xy.XLength < 20.0 and 10.0 < box_xy.YLength < 20.0


ALIAS_SCRIPT = r"""
import json, os, sys
sys.path.insert(0, os.environ["SURFCOMP_ROOT"])
from surfcomp.app import cam, fcenv
fcenv.import_freecad()
cam.install_aliases()
cam.install_aliases()                     # idempotent: one finder
out = {"finders": sum(type(f).__name__ == "_AliasFinder" for f in sys.meta_path),
       "loaded": sorted(m for m in sys.modules if m.split(".")[0] in ("ocl", "opencamlib",
                                                                      "PathScripts"))}
cam.setup_workbench(require_ocl=False)    # FreeCAD's Mod folders on the path, as freecadcmd
import ocl
out["ocl"] = [ocl.__name__, ocl.__spec__.name, "opencamlib.ocl" in sys.modules
              and sys.modules["opencamlib.ocl"] is ocl]
import PathScripts.PathJob as job
import PathScripts.PathSurface as surface
out["job"] = [job.__name__, job.__spec__.name, hasattr(job, "ObjectJob")]
out["surface"] = [surface.__name__, hasattr(surface, "ObjectSurface")]
try:
    import PathScripts.PathNoSuchModule  # noqa: F401
    out["unknown"] = "imported"
except ImportError as exc:
    out["unknown"] = type(exc).__name__
print("RESULT " + json.dumps(out))
"""


def test_aliases_resolve_on_demand_to_one_module_with_its_own_spec(home):
    """``ocl`` and 0.20's CAM names resolve when imported (nothing before), to the very module
    they stand for, which keeps its own ``__spec__``; unknown names still fail."""
    import json
    import subprocess
    import sys

    from tests.conftest import ROOT

    run = subprocess.run([sys.executable, "-c", ALIAS_SCRIPT], capture_output=True, text=True,
                         timeout=300, env=dict(os.environ, SURFCOMP_ROOT=ROOT))
    line = [s for s in run.stdout.splitlines() if s.startswith("RESULT ")]
    assert line, run.stdout[-2000:] + run.stderr[-2000:]
    r = json.loads(line[-1][len("RESULT "):])
    assert r["finders"] == 1 and r["loaded"] == []
    name, spec, same = r["ocl"]
    # Debian 12's PyPI wheel and Debian's package ship opencamlib/ocl.so only: the alias
    assert (name, spec, same) == ("opencamlib.ocl", "opencamlib.ocl", True)
    if cam.api().modules == "Path":        # 1.x: 0.20's names are the 1.x modules
        assert r["job"] == ["Path.Main.Job", "Path.Main.Job", True]
        assert r["surface"] == ["Path.Op.Surface", True]
    else:                                  # 0.20: its own modules, no alias
        assert r["job"] == ["PathScripts.PathJob", "PathScripts.PathJob", True]
        assert r["surface"] == ["PathScripts.PathSurface", True]
    assert r["unknown"] == "ModuleNotFoundError"


@pytest.mark.parametrize("bit_file, shape", [
    (cam.BALL_END_BIT, "ballend"), ("5mm_Endmill.fctb", "endmill"),
    ("6mm_Bullnose.fctb", "bullnose"),
])
def test_the_tool_shape_is_read_on_every_release(home, doc, bit_file, shape):
    """0.20 and 1.0 name a bit's shape in ShapeName, 1.1 in ShapeID and ShapeType; the
    surface correction dressup refuses a base whose tool is no ball end mill (a flat or
    bull-nose cutter touches the face elsewhere than the ball the dressup moves)."""
    from types import SimpleNamespace

    from surfcomp.app.dressup_surface import check_ball_end
    from surfcomp.errors import InputError

    bit = cam.create_tool_bit(doc, bit_file, "Bit")
    assert cam.tool_shape(bit) == shape
    tc = cam.create_tool_controller("TC", bit)
    base = SimpleNamespace(Name="Surface", Label="Finish", ToolController=tc)
    dressup = SimpleNamespace(Label="DressupSurfaceCorrection")
    if shape == "ballend":
        check_ball_end(dressup, base)
        return
    with pytest.raises(InputError) as err:
        check_ball_end(dressup, base)
    assert ("DressupSurfaceCorrection: the tool of Finish (%s, tool controller %s) has the "
            "shape '%s', not a ball end mill's" % (bit.Label, tc.Label, shape)) in str(err.value)


def test_a_tool_that_names_no_shape_has_none():
    from types import SimpleNamespace

    assert cam.tool_shape(None) is None
    assert cam.tool_shape(SimpleNamespace(Diameter=6.0, ShapeName="")) is None
    assert cam.tool_shape(SimpleNamespace(ToolType="BallEndMill")) == "ballendmill"
    assert "ballendmill" in cam.BALL_END_SHAPES
