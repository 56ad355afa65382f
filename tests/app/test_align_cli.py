# SPDX-License-Identifier: LGPL-2.1-or-later
"""--align / --transform on the file route (issue 28): measured points in another frame."""

import json
import subprocess
import sys

import numpy as np
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from surfcomp.core.measurement import align
from surfcomp.io.readers import read_any
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP, ROOT, run_in_process

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
    out = run_in_process("inspect", EXAMPLE_STEP, _points(tmp_path, MOVE), "--transform",
                         tmp_path / "t.json", "--report", tmp_path / "a.json", "--quiet")
    assert out.returncode == 0, out.stderr
    out = run_in_process("inspect", EXAMPLE_STEP, _points(tmp_path, np.eye(4)), "--report",
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
    out = run_in_process("inspect", EXAMPLE_STEP, _points(tmp_path, MOVE), "--align",
                         "bestfit", "--transform", tmp_path / "t.json", "--report",
                         tmp_path / "r.json", "--html", tmp_path / "r.html", "--quiet")
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
    # the next part's prediction is in the fitted frame, and says so with what it leaves out
    assert "Expected RMS of the next part" in page
    assert ("That figure is in the best fit's frame: the mean offset (%.3f µm)"
            % a["absorbed"]["mean_offset_um"]) in page
    # from the measuring frame itself: the absorbed part cannot be told apart from the move
    out = run_in_process("inspect", EXAMPLE_STEP, _points(tmp_path, MOVE), "--align",
                         "bestfit", "--report", tmp_path / "f.json", "--quiet")
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


def block_points(tmp_path):
    """A block's STEP file and points on three of its datum faces (x = 0, y = 0, z = 0) and
    on its top face (with a machining error), moved by MOVE: ``(top face, datum faces,
    deviations, face of every point)``; writes ``box.step`` and ``p.xyz``."""
    import Part

    box = Part.makeBox(40.0, 30.0, 20.0)
    box.exportStep(str(tmp_path / "box.step"))
    rng = np.random.default_rng(28)

    def on(origin, eu, ev, n, a=(2.0, 38.0), b=(2.0, 18.0)):
        s, t = rng.uniform(*a, n), rng.uniform(*b, n)
        return np.asarray(origin) + s[:, None] * eu + t[:, None] * ev

    ex, ey, ez = np.eye(3)
    datums = np.vstack([on((0, 0, 0), ey, ez, 150, (2, 28)), on((0, 0, 0), ex, ez, 150),
                        on((0, 0, 0), ex, ey, 150, b=(2, 28))])
    top = on((0, 0, 20.0), ex, ey, 300, b=(2, 28))
    dev = 0.02 + 0.01 * np.sin(top[:, 0] / 7.0) + 0.0005 * top[:, 1]
    pts = align.apply(MOVE, np.vstack([datums, top + dev[:, None] * ez]))
    np.savetxt(tmp_path / "p.xyz", pts, fmt="%.10f", header="x y z", comments="")

    def face_at(axis, value):
        return next("Face%d" % (k + 1) for k, f in enumerate(box.Faces)
                    if abs(f.CenterOfMass[axis] - value) < 1e-9)

    names = [face_at(0, 0.0), face_at(1, 0.0), face_at(2, 0.0)]
    top_name = face_at(2, 20.0)
    per_point = [n for n in names for _ in range(150)] + [top_name] * 300
    return top_name, names, dev, per_point, pts


def test_datum_faces_of_a_solid_leave_the_deviations_unchanged(tmp_path):
    """Points on three datum faces of a block and on its top face, all moved: the fit on the
    datums puts the top's points back; their deviations are those never moved (0.1 um) and
    nothing is absorbed; the datum points serve the alignment only."""
    top_name, names, dev, _faces, _pts = block_points(tmp_path)
    out = run_in_process("inspect", tmp_path / "box.step", tmp_path / "p.xyz", "--face",
                         top_name, "--align", "bestfit", "--align-faces", ",".join(names),
                         "--report", tmp_path / "r.json", "--quiet")
    assert out.returncode == 0, out.stderr
    rep = json.loads((tmp_path / "r.json").read_text())
    a = rep["alignment"]
    assert a["faces"] == names and a["absorbed"] is None
    assert a["converged"] and rep["inputs"]["measurements"]["points"] == 750
    assert len(rep["points"]["deviation"]) == 300
    assert_allclose(rep["points"]["deviation"], dev, atol=1e-4)
    assert_allclose(a["matrix"], np.linalg.inv(MOVE), atol=1e-9)
    assert all(a["rms_after_um"][n] < 1e-3 for n in names)
    assert "served the alignment only" in out.stderr


def test_face_column_assigns_the_points(tmp_path):
    """A face column names every point's face; a name that is no reference is refused
    with its line."""
    top_name, names, dev, faces, pts = block_points(tmp_path)
    rows = ["x,y,z,face"] + ["%.10f,%.10f,%.10f,%s" % (tuple(p) + (f,))
                             for p, f in zip(pts, faces)]
    (tmp_path / "f.csv").write_text("\n".join(rows) + "\n")
    args = ("inspect", tmp_path / "box.step", tmp_path / "f.csv", "--face", top_name,
            "--align", "bestfit", "--align-faces", ",".join(names), "--quiet")
    out = run_in_process(*args, "--report", tmp_path / "r.json")
    assert out.returncode == 0, out.stderr
    rep = json.loads((tmp_path / "r.json").read_text())
    assert_allclose(rep["points"]["deviation"], dev, atol=1e-4)
    assert rep["alignment"]["points"] == {**{n: 150 for n in names}, top_name: 300}
    rows[5] = rows[5].rsplit(",", 1)[0] + ",Face9"
    (tmp_path / "f.csv").write_text("\n".join(rows) + "\n")
    out = run_cli(*args, "--report", tmp_path / "r2.json")
    assert out.returncode == 2 and "f.csv:6: face 'Face9' is not a reference face" in out.stderr
    assert not (tmp_path / "r2.json").exists()

