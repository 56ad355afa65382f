# SPDX-License-Identifier: LGPL-2.1-or-later
"""--deviation-units on the command line (issue 24, item 5, as the import preview has it):
a CMM report with coordinates in mm and deviations in um, neither named with its unit, read
by the file route and the document route."""

import json
import subprocess
import sys

import numpy as np
import Part
from numpy.testing import assert_allclose

from surfcomp.io.readers import read_any
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP, ROOT, run_in_process


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "surfcomp", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def _um_file(tmp_path):
    path = tmp_path / "um.csv"
    with open(EXAMPLE_CSV) as f, open(path, "w") as out:
        for line in f.read().splitlines():
            parts = line.split(",")
            if parts[0].startswith("P"):
                parts[7] = "%.1f" % (float(parts[7]) * 1000.0)
            out.write(",".join(parts) + "\n")
    return path


def test_file_route_reads_the_deviations_in_um(tmp_path):
    um = _um_file(tmp_path)
    out = run_cli("inspect", EXAMPLE_STEP, um, "--report", tmp_path / "r.json", "--quiet")
    assert out.returncode == 2 and "are the deviations in um?" in out.stderr
    out = run_in_process("inspect", EXAMPLE_STEP, um, "--deviation-units", "um",
                         "--report", tmp_path / "r.json", "--quiet")
    assert out.returncode == 0, out.stderr
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["inputs"]["measurements"]["units"] == "mm, deviation um"
    example = read_any(EXAMPLE_CSV).deviation
    assert_allclose(rep["points"]["deviation"], example, atol=5e-5 + 1e-12)   # 0.1 um digits
    assert_allclose(np.asarray(rep["points"]["nominal"]), read_any(EXAMPLE_CSV).nominal,
                    atol=1e-12)


def test_document_route_reads_the_deviations_in_um(tmp_path):
    import FreeCAD

    doc = FreeCAD.newDocument("test")
    try:
        nom = doc.addObject("Part::Feature", "Nominal")
        nom.Shape = Part.read(EXAMPLE_STEP)
        doc.recompute()
        doc.saveAs(str(tmp_path / "d.FCStd"))
    finally:
        # closed: the route refuses a document open in its session (it would change it)
        FreeCAD.closeDocument(doc.Name)
    out = run_in_process("compensate", tmp_path / "d.FCStd", _um_file(tmp_path), "--object",
                         "Nominal", "--save", tmp_path / "out.FCStd", "--deviation-units", "um",
                         "--quiet")
    assert out.returncode == 0, out.stderr
    saved = FreeCAD.openDocument(str(tmp_path / "out.FCStd"))
    try:
        meas = saved.getObject("Measurement")
        assert meas.Units == "mm, deviation um"
        assert_allclose(meas.Deviation, read_any(EXAMPLE_CSV).deviation, atol=5e-5 + 1e-12)
        assert abs(max(meas.NominalX) - 44.1178) < 1e-3
    finally:
        FreeCAD.closeDocument(saved.Name)
