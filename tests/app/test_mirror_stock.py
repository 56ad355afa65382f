# SPDX-License-Identifier: LGPL-2.1-or-later
"""The mirror stock check on the command line and in the document object (issue 24, item
4): the example is a finished part (mean deviation 15.7 um), so the default stock 0.1 mm
is refused with the measured mean, exit 2 and nothing written, unless confirmed with
--accept-stock / StockOk; the predicted residual says what it assumes."""

import json
import os
import subprocess
import sys

import numpy as np
import Part
import pytest
from numpy.testing import assert_allclose

from surfcomp.app import features
from surfcomp.app.nominal import load_nominal
from surfcomp.errors import InputError
from tests.app.helpers import (
    EXAMPLE_CSV,
    EXAMPLE_STEP,
    ROOT,
    grid_on_face,
    run_in_process,
    write_cmm_csv,
)


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "surfcomp", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def _outputs(tmp_path):
    return ["-o", tmp_path / "c.step", "--report", tmp_path / "r.json",
            "--html", tmp_path / "r.html", "--quiet"]


def test_cli_refuses_the_default_stock_on_a_finished_part(tmp_path):
    out = run_cli("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--method", "mirror",
                  "--stock", "0.1", *_outputs(tmp_path))
    assert out.returncode == 2, out.stderr
    assert "Traceback" not in out.stderr and out.stdout == ""
    msg = out.stderr
    assert msg.startswith("surfcomp: error: the stock 0.1 mm (Stock in the document) does not "
                          "fit the measured deviations")
    assert "measured mean deviation 15.7 um (spread 19.1 um)" in msg
    assert "a mean of 0.1 mm +- 57.2 um" in msg
    assert "--accept-stock (StockOk = true in the document)" in msg
    assert os.listdir(tmp_path) == []      # nothing written, no temporary file left


def test_cli_confirmed_stock_runs_and_says_what_it_assumed(tmp_path):
    out = run_in_process("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--method", "mirror",
                         "--stock", "0.1", "--accept-stock", *_outputs(tmp_path))
    assert out.returncode == 0, out.stderr
    assert "INCONSISTENT, used by --accept-stock" in out.stdout
    assert "predicted residual assumes the measured part carries the stock 0.1 mm" in out.stdout
    rep = json.loads((tmp_path / "r.json").read_text())
    check = rep["method"]["stock_check"]
    assert check["consistent"] is False and check["accepted"] is True
    assert_allclose([check["mean_mm"], check["spread_mm"], check["tolerance_mm"]],
                    [0.015675, 0.019082, 3 * 0.019082], atol=1e-6)
    assert "carries the stock 0.1 mm" in rep["method"]["residual_assumes"]
    # delta = d - s at every point (mirror paper eq. 1-2): the face moves out by up to 0.13
    d = np.asarray(rep["points"]["deviation"])
    assert_allclose(rep["points"]["correction"], d - 0.1, atol=1e-12)
    assert_allclose(min(rep["points"]["correction"]), -0.12885, atol=1e-5)
    html = (tmp_path / "r.html").read_text()
    assert "Stock check: mean deviation 15.7 µm" in html and "inconsistent" in html


def test_cli_a_stock_that_fits_needs_no_confirmation(tmp_path):
    """A semi-finished part (stock 0.2 mm, error 10 um sin) as the mirror paper measures it."""
    nom = load_nominal(EXAMPLE_STEP)
    P, N, _U, _V = grid_on_face(nom, 9, 9)
    e = 0.01 * np.sin(np.linspace(0, 3, 9))[:, None] * np.ones(9)
    meas = tmp_path / "semi.csv"
    write_cmm_csv(meas, P, N, 0.2 + e)
    out = run_in_process("compensate", EXAMPLE_STEP, meas, "--method", "mirror", "--stock",
                         "0.2", "-o", tmp_path / "c.step", "--quiet")
    assert out.returncode == 0, out.stderr
    assert "a part measured with the stock 0.2 mm should have a mean of 0.2 mm +- 100.0 um " \
           "(the larger of stock/2 and 3 x the spread): consistent" in out.stdout


def test_document_object_refuses_until_accept_stock(fresh_doc):
    doc = fresh_doc
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(EXAMPLE_STEP)
    m = features.make_measurement(doc, EXAMPLE_CSV)
    c = features.make_compensation(doc, nom, "Face1", m, method="mirror", stock=0.1)
    assert c.StockOk is False
    doc.recompute()
    assert "Invalid" in c.State
    with pytest.raises(InputError, match=r"measured mean deviation 15\.7 um .*StockOk = "
                                         r"true in the document"):
        features.compensation_result(c)
    c.StockOk = True
    doc.recompute()
    assert "Invalid" not in c.State and not c.Shape.isNull()
    assert_allclose(c.Correction, np.asarray(c.Deviation) - 0.1, atol=1e-15)
    # a stock within the part's scatter is used without confirmation
    c.StockOk, c.Stock = False, 0.02
    doc.recompute()
    assert "Invalid" not in c.State
    assert_allclose(c.Correction, np.asarray(c.Deviation) - 0.02, atol=1e-15)
