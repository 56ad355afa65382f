# SPDX-License-Identifier: LGPL-2.1-or-later
"""The README's "Scripting" example, run as it stands there in a fresh ``python3``, checked
against the command line on the same input and read back by OpenCASCADE and FreeCAD."""

import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest
from numpy.testing import assert_allclose

from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP, ROOT, realised_by_occt

#: the printed statistics are rounded to 1e-9 mm (RMS) and 1e-6 mm (min, max)
RMS_TOL, EXTREME_TOL = 0.6e-9, 0.6e-6


def readme_script():
    """The first ``python`` block under the README's "## Scripting" heading."""
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as fh:
        text = fh.read()
    section = text[text.index("\n## Scripting\n"):]
    section = section[:section.index("\n## ", 1)]
    block = re.search(r"\n```python\n(.*?)\n```\n", section, re.S)
    assert block, "the README's Scripting section has no python block"
    return block.group(1) + "\n"


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The README script's output folder and stdout, and the command line's outputs on the
    same example."""
    work = tmp_path_factory.mktemp("readme")
    os.symlink(os.path.join(ROOT, "examples"), work / "examples")
    (work / "script.py").write_text(readme_script())
    env = dict(os.environ, PYTHONPATH=ROOT)
    script = subprocess.run([sys.executable, "script.py"], cwd=work, env=env,
                            capture_output=True, text=True, timeout=600)
    assert script.returncode == 0, script.stderr
    cli = work / "cli"
    cli.mkdir()
    out = subprocess.run([sys.executable, "-m", "surfcomp", "compensate", EXAMPLE_STEP,
                          EXAMPLE_CSV, "-o", cli / "c.step", "--report", cli / "r.json",
                          "--points", cli / "p.csv", "--quiet"],
                         cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    return work / "out", script.stdout, json.loads((cli / "r.json").read_text()), cli


def printed(stdout):
    """``name -> (rms, min, max)`` of the script's statistics lines."""
    rows = re.findall(r"^(\w+) +RMS ([-\d.]+) mm, min ([-\d.]+) mm, max ([-\d.]+) mm$",
                      stdout, re.M)
    return {name: tuple(map(float, values)) for name, *values in rows}


def test_statistics_are_the_command_lines(runs):
    _out, stdout, report, _cli = runs
    stats = printed(stdout)
    assert sorted(stats) == ["correction", "deviation", "random"], stdout
    for name, (rms, lo, hi) in stats.items():
        ref = report["statistics"][name]
        assert abs(rms - ref["rms"]) <= RMS_TOL, (name, rms, ref["rms"])
        assert abs(lo - ref["min"]) <= EXTREME_TOL and abs(hi - ref["max"]) <= EXTREME_TOL
    # the example's figures (README "What command 1 prints"): 47.13 um largest deviation
    assert stats["deviation"][2] == pytest.approx(0.047134, abs=1e-6)
    assert 0.02 < stats["deviation"][0] < 0.03
    assert "points: 2025 (nominal+normal+deviation)" in stdout
    assert "nominal: Face1 of examples/nominal.step, outward +1" in stdout
    assert "warning:" not in stdout
    # the job's report, as the command line's
    job = float(re.search(r"^job: deviation RMS ([\d.]+) mm$", stdout, re.M).group(1))
    assert abs(job - report["statistics"]["deviation"]["rms"]) <= RMS_TOL


def test_errors_name_the_options(runs):
    _out, stdout, _report, _cli = runs
    assert "refused: method 'mirror' needs stock (the semi-finishing allowance in mm" in stdout


def test_written_face_is_the_command_lines_and_realises_the_correction(runs):
    import Part

    out, _stdout, _report, cli = runs
    assert sorted(os.listdir(out)) == ["script.FCStd", "script_corrected.step",
                                       "script_face.brep", "script_job.json",
                                       "script_job.step"]    # no temporary file left
    solid = Part.read(str(out / "script_corrected.step"))
    face = Part.read(str(out / "script_face.brep"))
    reference = Part.read(str(cli / "c.step"))
    assert solid.isValid() and face.isValid()
    # the example is a lone face: the solid route gives the face too
    assert len(solid.Faces) == len(face.Faces) == len(reference.Faces) == 1
    # the same surface as the command line's, at points spread over the face
    f = solid.Faces[0]
    u0, u1, v0, v1 = f.ParameterRange
    for shape in (face, reference, Part.read(str(out / "script_job.step"))):
        far = max(shape.distToShape(Part.Vertex(f.valueAt(u, v)))[0]
                  for u in np.linspace(u0, u1, 9) for v in np.linspace(v0, v1, 9))
        assert far < 1e-7, far
    # the intended correction (the command line's --points) is realised at the points
    table = np.loadtxt(cli / "p.csv", delimiter=",", skiprows=1)[::25]
    P, N, intended = table[:, 2:5], table[:, 5:8], table[:, 8]
    realised = realised_by_occt(f, P, N)
    assert_allclose(realised, intended, atol=2e-5)      # measured: 4.1e-6 mm at 81 points
    assert np.abs(intended).max() > 0.03     # a correction that moved the face


def test_written_document_recomputes_to_the_same_statistics(runs):
    import FreeCAD

    out, stdout, report, _cli = runs
    doc = FreeCAD.openDocument(str(out / "script.FCStd"))
    try:
        comp = doc.getObject("Compensation")
        assert comp.Nominal.Name == "Nominal" and comp.FaceName == "Face1"
        assert comp.Method == "filtered" and comp.MaskSize == 5
        comp.touch()
        doc.recompute()
        assert not [o.Name for o in doc.Objects if "Invalid" in o.State or "Error" in o.State]
        stats = json.loads(comp.Statistics)
        assert abs(stats["deviation"]["rms"] - report["statistics"]["deviation"]["rms"]) < 1e-12
        assert abs(stats["deviation"]["rms"] - printed(stdout)["deviation"][0]) <= RMS_TOL
        assert len(comp.Shape.Faces) == 1
    finally:
        FreeCAD.closeDocument(doc.Name)


def readme_report_keys():
    """The keys the README's "JSON report" table names in its first column (``inputs.nominal``
    as written)."""
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as fh:
        text = fh.read()
    section = text[text.index("\n## JSON report\n"):]
    section = section[:section.index("\n## ", 1)]
    rows = re.findall(r"^\| ([^|]+) \|", section, re.M)
    return {key for row in rows for key in re.findall(r"`([\w.]+)`", row)}


def test_readme_report_table_names_every_key_the_report_has(runs):
    """Every top-level key of the command line's report (and every input it records) is in
    the README's table, and the table names no top-level key the report lacks but the
    scattered layouts' fit."""
    _out, _stdout, report, _cli = runs
    documented = readme_report_keys()
    present = {k for k in report if k != "inputs"} | {"inputs." + k for k in report["inputs"]}
    assert present - documented == set(), sorted(present - documented)
    # the example is a grid: no scattered fit; everything else is in its report
    assert {k for k in documented if "." not in k} - set(report) == {"scattered_fit"}
    assert report["units"] == "mm" and report["statistics_ddof"] == 1
