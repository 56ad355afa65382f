# SPDX-License-Identifier: LGPL-2.1-or-later
"""The batch CLI: exit codes, messages, atomic outputs (subprocesses of
/usr/bin/python3 -m surfcomp; the runs whose outputs a test checks run the command line in
this process, tests/app/helpers.py run_in_process)."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from surfcomp.app.nominal import load_nominal
from tests.app.helpers import (
    EXAMPLE_CSV,
    EXAMPLE_STEP,
    ROOT,
    grid_on_face,
    run_in_process,
    write_cmm_csv,
)
from tests.conftest import REALDATA, default_signals


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "surfcomp", *map(str, args)], cwd=cwd or ROOT,
                          capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def example_run(tmp_path_factory):
    """One compensation of the example that writes every output (face, JSON report, points,
    curve net and HTML report); the tests below assert on its outputs."""
    folder = tmp_path_factory.mktemp("example")
    out = run_in_process("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "-o", folder / "c.step",
                  "--report", folder / "r.json", "--points", folder / "p.csv",
                  "--curves", folder / "net.step", "--html", folder / "r.html", "--quiet")
    return out, folder


def test_compensate_example_writes_step_and_report(example_run):
    out, tmp_path = example_run
    assert out.returncode == 0, out.stderr
    assert "Max. positive" in out.stdout and "47.13" in out.stdout
    assert "realised - intended correction at the 2025 measured points" in out.stdout
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["inputs"]["measurements"]["sha256"] == __import__("hashlib").sha256(
        open(EXAMPLE_CSV, "rb").read()).hexdigest()
    assert rep["method"]["name"] == "filtered" and rep["method"]["mask_size"] == 5
    assert len(rep["points"]["deviation"]) == 2025
    assert (tmp_path / "p.csv").read_text().count("\n") == 2026
    import Part

    net = Part.read(str(tmp_path / "net.step"))
    assert len(net.Edges) == 90  # 45 curves along each grid direction (Werner Fig. 3b)
    assert oct(os.stat(tmp_path / "c.step").st_mode & 0o777) != "0o600"


def test_inspect_prints_statistics_only(tmp_path):
    out = run_in_process("inspect", EXAMPLE_STEP, EXAMPLE_CSV, "--report", tmp_path / "r.json",
                         "--html", tmp_path / "r.html", "--quiet")
    assert out.returncode == 0, out.stderr
    assert "Standard deviation (ddof=1)" in out.stdout
    assert "Corrected face" not in out.stdout
    assert "corrected_face" not in json.loads((tmp_path / "r.json").read_text())
    html = (tmp_path / "r.html").read_text()
    assert 'id="maps"' in html and "No corrected face was built (inspect)" in html


def _bad(tmp_path, *args):
    out = run_cli(*args, "-o", tmp_path / "c.step", "--report", tmp_path / "r.json", "--quiet")
    assert out.returncode == 2, (out.returncode, out.stderr)
    assert "Traceback" not in out.stderr
    left = [x for x in os.listdir(tmp_path) if x.startswith(".") or x in ("c.step", "r.json")]
    assert left == []  # no outputs, no temporary files
    return out.stderr


def test_bad_measurement_file_names_file_and_line(tmp_path):
    meas = tmp_path / "bad.csv"
    meas.write_text("x_nom,y_nom,z_nom,i,j,k,dev\n1,2,3,0,0,1,0.01\n1,2,abc,0,0,1,0.02\n")
    err = _bad(tmp_path, "compensate", EXAMPLE_STEP, meas)
    assert "bad.csv:3" in err and "abc" in err


def test_point_too_far_from_the_face(tmp_path):
    nom = load_nominal(EXAMPLE_STEP)
    P, N, _, _ = grid_on_face(nom, 5, 5)
    P[2, 3] += 2.5 * N[2, 3]
    meas = tmp_path / "far.csv"
    write_cmm_csv(meas, P, N, np.zeros((5, 5)))
    err = _bad(tmp_path, "compensate", EXAMPLE_STEP, meas)
    # serpentine order: column 3 is written reversed, so row 2 is the 3rd point of that row
    assert "far.csv:" in err and "is 2.5000 mm from the face" in err and "--max-offset 1" in err


def test_normals_on_the_other_side(tmp_path):
    nom = load_nominal(EXAMPLE_STEP)
    P, N, _, _ = grid_on_face(nom, 5, 5)
    meas = tmp_path / "flip.csv"
    write_cmm_csv(meas, P, -N, np.full((5, 5), 0.01))
    err = _bad(tmp_path, "compensate", EXAMPLE_STEP, meas)
    assert "flip.csv:2:" in err and "--flip-normals" in err
    ok = run_in_process("compensate", EXAMPLE_STEP, meas, "--flip-normals", "--method", "raw",
                        "--report", tmp_path / "ok.json", "--quiet")
    assert ok.returncode == 0, ok.stderr
    rep = json.loads((tmp_path / "ok.json").read_text())
    np.testing.assert_allclose(rep["points"]["deviation"], -0.01, atol=1e-12)


def test_incomplete_grid_is_refused_with_what_is_missing(tmp_path):
    nom = load_nominal(EXAMPLE_STEP)
    P, N, _, _ = grid_on_face(nom, 6, 5)
    meas = tmp_path / "holes.csv"
    write_cmm_csv(meas, P, N, np.zeros((6, 5)))
    lines = meas.read_text().splitlines()
    meas.write_text("\n".join(lines[:8] + lines[9:]) + "\n")
    err = _bad(tmp_path, "compensate", EXAMPLE_STEP, meas, "--layout", "grid")
    assert "do not form a complete n x m grid" in err and "has 5 points (missing near u=" in err
    # by default such a set is used as a scattered layout, with the same reason as a warning
    out = run_in_process("inspect", EXAMPLE_STEP, meas, "--quiet")
    assert out.returncode == 0, out.stderr
    assert "has 5 points (missing near u=" in out.stderr and "scattered layout" in out.stderr
    assert "29 scattered points" in out.stdout


@pytest.mark.parametrize("args,words", [
    (("--face", "Face7"), "has no Face7 (it has one face: Face1)"),
    (("--method", "mirror"), "needs --stock"),
    (("--weights", "1 1; 1 1"), "odd"),
    (("--mask", "4"), "odd"),
    (("--object", "Box"), "--object applies to FCStd"),
])
def test_bad_options(tmp_path, args, words):
    err = _bad(tmp_path, "compensate", EXAMPLE_STEP, EXAMPLE_CSV, *args)
    assert words in err


def test_ambiguous_face_lists_the_choices(tmp_path):
    err = _bad(tmp_path, "compensate",
               os.path.join(REALDATA, "cad", "axom_data", "boxed_sphere.step"), EXAMPLE_CSV)
    assert "42 B-spline faces among 192 faces" in err and "--face FaceN" in err


def test_missing_nominal(tmp_path):
    err = _bad(tmp_path, "compensate", tmp_path / "nope.step", EXAMPLE_CSV)
    assert "nope.step: nominal file not found" in err


def test_freecadcmd_job_route(tmp_path):
    (tmp_path / "out").mkdir()
    job = tmp_path / "job.json"
    job.write_text(json.dumps({"command": "compensate", "nominal": EXAMPLE_STEP,
                               "measurements": EXAMPLE_CSV, "output": "out/c.step",
                               "report": "out/r.json", "method": "raw"}))
    out = subprocess.run(["freecadcmd", os.path.join(ROOT, "macros", "surfcomp_job.py")],
                         env=dict(os.environ, SURFCOMP_JOB=str(job)), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    rep = json.loads((tmp_path / "out" / "r.json").read_text())
    assert rep["method"]["name"] == "raw" and rep["corrected_face"]["max_error_at_points_mm"] < 1e-4
    bad = tmp_path / "bad.json"
    bad.write_text('{"nominal": "x.step", "measurements": "y.csv", "colour": 3}')
    out = subprocess.run(["freecadcmd", os.path.join(ROOT, "macros", "surfcomp_job.py")],
                         env=dict(os.environ, SURFCOMP_JOB=str(bad)), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 2 and "unknown job file keys: colour" in out.stderr


def test_nominal_from_an_fcstd_document(tmp_path):
    import FreeCAD
    import Part

    doc = FreeCAD.newDocument("SurfCompNominal")
    try:
        box = doc.addObject("Part::Box", "Box")
        part = doc.addObject("Part::Feature", "Nominal")
        part.Shape = Part.read(EXAMPLE_STEP)
        doc.recompute()
        path = tmp_path / "shop.FCStd"
        doc.saveAs(str(path))
    finally:
        FreeCAD.closeDocument(doc.Name)
    before = path.read_bytes()
    out = run_in_process("compensate", path, EXAMPLE_CSV, "--object", "Nominal", "--face",
                         "Face1", "--report", tmp_path / "r.json", "--quiet")
    assert out.returncode == 0, out.stderr
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["inputs"]["nominal"]["object"] == "Nominal"
    assert rep["statistics"]["deviation"]["count"] == 2025
    assert path.read_bytes() == before  # the document is never modified
    bad_dir = tmp_path / "bad"
    bad_dir.mkdir()
    err = _bad(bad_dir, "compensate", path, EXAMPLE_CSV, "--object", "Nope")
    assert "no object 'Nope' in the document" in err and "Nominal" in err
    del box


def _measured_points(n=15, m=12, seed=7):
    """Measured points on the example face (nominal + d n) and their deviations d (mm)."""
    nom = load_nominal(EXAMPLE_STEP)
    P, N, U, V = grid_on_face(nom, n, m)
    d = 0.02 * np.sin(U / U.max() * 3) * np.cos(V / V.max() * 2) + np.random.default_rng(
        seed).normal(0, 0.002, U.shape)
    return P + d[..., None] * N, N, d


@pytest.mark.parametrize("kind", ["xyz_inch_header", "xyzijk_inch", "probe_log"])
def test_point_only_files_through_the_pipeline(tmp_path, kind):
    """Files with measured points only: deviations come from the projection engine and
    equal the synthetic ones (units converted; file-stated units win with a warning)."""
    M, N, d = _measured_points()
    pts = M.reshape(-1, 3)
    if kind == "xyz_inch_header":
        path = tmp_path / "scan.xyz"
        rows = ["x[in] y[in] z[in]"] + ["%.9f %.9f %.9f" % tuple(p / 25.4) for p in pts]
        extra = ["--units", "mm"]  # overridden by the header's [in], with a warning
    elif kind == "xyzijk_inch":
        path = tmp_path / "scan.txt"
        rows = ["XYZIJK"] + ["%.9f,%.9f,%.9f,%.9f,%.9f,%.9f" % (tuple(p / 25.4) + tuple(nv))
                             for p, nv in zip(pts, N.reshape(-1, 3))]
        extra = []
    else:
        path = tmp_path / "probe.txt"
        rows = ["%.6f %.6f %.6f 0 0 0 0 0 0" % tuple(p) for p in pts]
        extra = ["--format", "probe"]
    path.write_text("\n".join(rows) + "\n")
    out = run_in_process("inspect", EXAMPLE_STEP, path, "--report", tmp_path / "r.json",
                         "--quiet", *extra)
    assert out.returncode == 0, out.stderr
    rep = json.loads((tmp_path / "r.json").read_text())
    got = np.array(rep["points"]["deviation"])
    # file order = row-major over the 15 x 12 grid; values printed to 1e-9 in / 1e-6 mm
    tol = 1e-6 if kind == "probe_log" else 5e-8
    np.testing.assert_allclose(np.sort(got), np.sort(d.ravel()), atol=tol)
    assert rep["grid"]["shape"] == [15, 12] or rep["grid"]["shape"] == [12, 15]
    if kind == "xyz_inch_header":
        assert "the file states its units (in); --units mm applies only" in out.stderr


def test_html_report_written_with_the_other_outputs(example_run):
    out, tmp_path = example_run
    assert out.returncode == 0, out.stderr
    html = (tmp_path / "r.html").read_text()
    for section in ("inputs", "method", "maps", "histograms", "statistics", "checks"):
        assert 'id="%s"' % section in html
    assert html.count("data:image/png;base64,") >= 5
    assert "wrote %s" % (tmp_path / "r.html") in out.stdout
    # an input path among the outputs is refused before anything is written
    bad = run_cli("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--html", EXAMPLE_CSV, "--quiet")
    assert bad.returncode == 2 and "--html would overwrite the input MEASUREMENTS" in bad.stderr


def test_probe_log_tip_radius_compensation(tmp_path):
    """A LinuxCNC probe log holds tip centres R outside the contact points: with
    --tip-radius R the deviations are the contact points' (within the 1e-6 mm print
    precision); without it they are off by R and a warning says so."""
    M, N, d = _measured_points(seed=11)
    R = 1.5
    centres = (M + R * N).reshape(-1, 3)   # ball of radius R touching at M
    path = tmp_path / "probe.txt"
    path.write_text("\n".join("%.6f %.6f %.6f 0 0 0 0 0 0" % tuple(c) for c in centres) + "\n")
    # R is above the default --max-offset: the check applies to the contact points
    out = run_in_process("inspect", EXAMPLE_STEP, path, "--tip-radius", R, "--report",
                         tmp_path / "r.json", "--quiet")
    assert out.returncode == 0, out.stderr
    got = np.array(json.loads((tmp_path / "r.json").read_text())["points"]["deviation"])
    np.testing.assert_allclose(np.sort(got), np.sort(d.ravel()), atol=2e-6)
    out = run_in_process("inspect", EXAMPLE_STEP, path, "--max-offset", 2, "--quiet")
    assert out.returncode == 0 and "tip centres (probe log); without --tip-radius" in out.stderr
    assert "1541.5" in out.stdout or "Max. positive" in out.stdout
    bad = run_cli("inspect", EXAMPLE_STEP, EXAMPLE_CSV, "--tip-radius", 1, "--quiet")
    assert bad.returncode == 2 and "already compensated" in bad.stderr


def test_scattered_adaptive_layout_end_to_end(tmp_path):
    """A 7 x 10 adaptive layout like the mirror paper's (points along 7 curves, unevenly
    spaced, no grid): the smoothing fit replaces the mask filter, and the corrected face
    meets the pipeline's requirements (realised = intended within 0.1 um at the points,
    no overshoot, zero field gives the nominal) checked independently with OCCT."""
    import Part

    from tests.app.helpers import realised_by_occt

    nom = load_nominal(EXAMPLE_STEP)
    rng = np.random.default_rng(5)
    (u0, u1), (v0, v1) = nom.surface.u_range, nom.surface.v_range
    curves = np.linspace(0.06, 0.94, 7) + rng.uniform(-0.02, 0.02, 7)
    U, V = [], []
    for c in curves:
        # unevenly spaced along the curve, but not closer than ~40 % of the mean step
        t = np.linspace(0.04, 0.96, 10) + rng.uniform(-0.03, 0.03, 10)
        U.append(u0 + (u1 - u0) * (c + 0.05 * np.sin(6 * t)))
        V.append(v0 + (v1 - v0) * t)
    U, V = np.concatenate(U), np.concatenate(V)
    from surfcomp.core.surface import bspline

    P = bspline.evaluate(nom.surface, U, V)
    N = bspline.normals(nom.surface, U, V) * nom.outward
    d = 0.03 * np.sin(2 * U / u1) * np.cos(1.5 * V / v1) + 0.01 + rng.normal(0, 0.002, U.size)
    meas = tmp_path / "adaptive.csv"
    meas.write_text("x_nom,y_nom,z_nom,i,j,k,dev\n" + "".join(
        "%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.9f\n" % (tuple(p) + tuple(n) + (x,))
        for p, n, x in zip(P, N, d)))
    for method in ("filtered", "raw"):
        out = run_in_process("compensate", EXAMPLE_STEP, meas, "--method", method, "-o",
                             tmp_path / "c.step", "--report", tmp_path / "r.json", "--html",
                             tmp_path / "r.html", "--quiet")
        assert out.returncode == 0, out.stderr
        assert "70 scattered points" in out.stdout and "do not form" in out.stderr
        rep = json.loads((tmp_path / "r.json").read_text())
        assert rep["grid"]["layout"] == "scattered" and rep["points"]["row"] is None
        fit = rep["scattered_fit"]
        assert fit["chosen_by"] == "gcv" and 0 < fit["loo_rms"] < 0.01
        cf = rep["corrected_face"]
        assert cf["max_error_at_points_mm"] < 1e-4
        assert cf["max_deviation_from_nominal_with_zero_correction_mm"] < 1e-4
        assert (cf["max_abs_realised_correction_on_face_mm"]
                <= cf["max_abs_intended_correction_mm"] + 1e-3)
        face = Part.read(str(tmp_path / "c.step")).Faces[0]
        want = np.array(rep["points"]["correction"])
        if method == "filtered":   # the smoothed values, not the raw ones
            assert np.abs(want - d).max() > 0.002
        np.testing.assert_allclose(realised_by_occt(face, P, N), want, atol=1e-4)
        assert 'id="maps"' in (tmp_path / "r.html").read_text()


#: runs the CLI with the corrected-surface construction held at its first progress report,
#: so the interrupt lands there however loaded the machine is
HOLD_IN_BUILD = r"""
import sys, time
import surfcomp.core.compensation.corrected as corrected
from surfcomp.cli import main
report = corrected.report
def held(progress, fraction, message=""):
    report(progress, fraction, message)
    if message == "building the corrected surface":
        sys.stderr.write("HELD\n"); sys.stderr.flush()
        time.sleep(120)
corrected.report = held
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.parametrize("signame, code", [("SIGINT", 130), ("SIGTERM", 143),
                                            ("SIGHUP", 129)])
def test_interrupt_leaves_no_outputs(tmp_path, signame, code):
    """Ctrl-C, SIGTERM or SIGHUP while the corrected surface is being built: exit 130, 143
    or 129, nothing written (no temporary file either)."""
    import signal

    nom = load_nominal(EXAMPLE_STEP)
    P, N, U, V = grid_on_face(nom, 40, 40)
    write_cmm_csv(tmp_path / "m.csv", P, N, 0.02 * np.sin(U / U.max() * 3))
    proc = subprocess.Popen([sys.executable, "-c", HOLD_IN_BUILD, "compensate", EXAMPLE_STEP,
                             tmp_path / "m.csv", "-o", tmp_path / "c.step", "--report",
                             tmp_path / "r.json"], cwd=ROOT, stderr=subprocess.PIPE, text=True,
                            preexec_fn=default_signals)
    seen = []
    for line in proc.stderr:
        seen.append(line)
        if line.strip() == "HELD":
            proc.send_signal(getattr(signal, signame))
            break
    rest = proc.stderr.read()
    assert proc.wait(timeout=300) == code, "".join(seen) + rest
    assert ("interrupted" if code == 130 else "terminated by signal") in rest
    assert "; nothing was written" in rest
    assert sorted(os.listdir(tmp_path)) == ["m.csv"]


@pytest.mark.parametrize("scale, unit, name", [(25.4, "in", "inches"), (1000.0, "m", "metres")])
def test_measured_points_in_another_unit_are_refused_and_nothing_written(tmp_path, scale, unit,
                                                                          name):
    """The example's measured points written in inches or metres (no unit given) land in a
    corner of the face, near enough to pass as on it: refused, naming the unit and the
    option, nothing written; with the unit given they are taken (before: a 63 MB face built
    from the corner, or a 36 GiB allocation)."""
    rows = np.loadtxt(EXAMPLE_CSV, delimiter=",", comments="#", skiprows=3,
                      usecols=range(1, 8))
    P, N, d = rows[:, 0:3], rows[:, 3:6], rows[:, 6]
    X = (P + d[:, None] * N) / scale
    path = tmp_path / "xyz.csv"
    np.savetxt(path, X, delimiter=",", header="x,y,z", comments="", fmt="%.9f")
    out = run_in_process("compensate", EXAMPLE_STEP, path, "-o", tmp_path / "c.step",
                         "--quiet")
    assert out.returncode == 2, out.stdout + out.stderr
    # the option where it offers the unit (inches), else the column names (metres)
    advice = "--units in, or a column name like 'x [in]'" if unit == "in" else \
        "a column name like 'x [m]'"
    assert ("multiplied by %g they lie on it: the file's coordinates are in %s, not mm (give "
            "the unit: %s)" % (scale, name, advice)) in out.stderr
    assert sorted(os.listdir(tmp_path)) == ["xyz.csv"]
    path.write_text(path.read_text().replace("x,y,z", "x [%s],y [%s],z [%s]" % ((unit,) * 3)))
    ok = run_in_process("inspect", EXAMPLE_STEP, path, "--quiet")
    assert ok.returncode == 0, ok.stderr
