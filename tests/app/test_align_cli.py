# SPDX-License-Identifier: LGPL-2.1-or-later
"""--align / --transform on the file route (issue 28): measured points in another frame."""

import json
import subprocess
import sys

import numpy as np
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from surfcomp.core import align
from surfcomp.io.readers import read_any
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP, ROOT

#: the move of the measured points into the measuring frame (10 deg, 80 mm)
MOVE = align.rigid(Rotation.from_euler("xyz", [4.0, -3.0, 10.0], degrees=True)
                   .as_matrix(), [80.0, -35.0, 12.0])


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "surfcomp", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def _points(tmp_path, move):
    ms = read_any(EXAMPLE_CSV)
    pts = align.apply(move, ms.nominal + ms.normal * ms.deviation[:, None])
    path = tmp_path / "points.xyz"
    np.savetxt(path, pts, fmt="%.10f", header="x y z", comments="")
    return path


def test_transform_gives_the_deviations_of_unmoved_points(tmp_path):
    (tmp_path / "t.json").write_text(json.dumps({"matrix": np.linalg.inv(MOVE).tolist()}))
    out = run_cli("inspect", EXAMPLE_STEP, _points(tmp_path, MOVE), "--transform",
                  tmp_path / "t.json", "--report", tmp_path / "a.json", "--quiet")
    assert out.returncode == 0, out.stderr
    out = run_cli("inspect", EXAMPLE_STEP, _points(tmp_path, np.eye(4)), "--report",
                  tmp_path / "b.json", "--quiet")
    assert out.returncode == 0, out.stderr
    a = json.loads((tmp_path / "a.json").read_text())
    b = json.loads((tmp_path / "b.json").read_text())
    assert_allclose(a["points"]["deviation"], b["points"]["deviation"], atol=1e-4)
    assert_allclose(a["alignment"]["matrix"], np.linalg.inv(MOVE), atol=1e-12)
    assert a["alignment"]["method"] == "none" and b["alignment"] is None


def test_bestfit_on_the_compensated_face_reports_what_it_absorbed(tmp_path):
    """Brought near by the known transform, the fit on the face itself takes out the
    machining error's mean and tilt: the deviations change by what it reports."""
    (tmp_path / "t.json").write_text(json.dumps({"matrix": np.linalg.inv(MOVE).tolist()}))
    out = run_cli("inspect", EXAMPLE_STEP, _points(tmp_path, MOVE), "--align", "bestfit",
                  "--transform", tmp_path / "t.json", "--report", tmp_path / "r.json",
                  "--html", tmp_path / "r.html", "--quiet")
    assert out.returncode == 0, out.stderr
    rep = json.loads((tmp_path / "r.json").read_text())
    a = rep["alignment"]
    assert a["method"] == "bestfit" and a["converged"] and a["faces"] == ["Face1"]
    example = read_any(EXAMPLE_CSV).deviation
    change = np.asarray(rep["points"]["deviation"]) - example
    assert abs(a["absorbed"]["mean_offset_um"] - change.mean() * 1e3) < 0.1
    assert abs(a["absorbed"]["mean_offset_um"]) > 1.0          # the example's mean error
    assert a["rms_after_um"]["Face1"] < a["rms_before_um"]["Face1"]
    assert "absorbed a mean offset" in out.stderr
    assert "Alignment:    bestfit" in out.stdout and "iterations, converged" in out.stdout
    page = (tmp_path / "r.html").read_text()
    assert '<section id="alignment">' in page and "Absorbed on the compensated face" in page
    # from the measuring frame itself: the absorbed part cannot be told apart from the move
    out = run_cli("inspect", EXAMPLE_STEP, _points(tmp_path, MOVE), "--align", "bestfit",
                  "--report", tmp_path / "f.json", "--quiet")
    assert out.returncode == 0 and "cannot be told apart" in out.stderr
    far = json.loads((tmp_path / "f.json").read_text())
    assert_allclose(far["points"]["deviation"], rep["points"]["deviation"], atol=1e-4)


def test_bad_alignment_input_exits_2_and_writes_nothing(tmp_path):
    pts = _points(tmp_path, MOVE)
    scaled = np.eye(4)
    scaled[0, 0] = 1.001
    np.savetxt(tmp_path / "t.txt", scaled)
    out = run_cli("inspect", EXAMPLE_STEP, pts, "--transform", tmp_path / "t.txt",
                  "--report", tmp_path / "r.json", "--quiet")
    assert out.returncode == 2 and "not rigid" in out.stderr
    out = run_cli("inspect", EXAMPLE_STEP, pts, "--align", "rps", "--rps", "1,2,3;4,5;6",
                  "--report", tmp_path / "r.json", "--quiet")
    assert out.returncode == 2 and "collinear" in out.stderr, out.stderr
    out = run_cli("inspect", EXAMPLE_STEP, EXAMPLE_CSV, "--align", "bestfit",
                  "--report", tmp_path / "r.json", "--quiet")
    assert out.returncode == 2 and "already in the nominal's frame" in out.stderr
    assert not (tmp_path / "r.json").exists()
