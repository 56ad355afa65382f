# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct program route's nominal from the reader child (surfcomp/app/cadread.py
``prefetch_face``/``take_face``, surfcomp/app/face_data.py): the child is forked before
FreeCAD or numpy is imported, reads the STEP file and sends the face back as plain data.

* The parent imports neither FreeCAD nor numpy to take it, and the child's own work imports
  no numpy.
* The nominal made of it is the one loaded in the process, exactly: the surface's arrays,
  the orientation, the whole-domain answer and the boundary polylines (an untrimmed face and
  a face trimmed by a circle with a hole).
* A face that cannot be chosen gives the in-process messages; a crash in the child says the
  file is damaged; a process with a second thread starts no child (the face is then loaded
  in the process).
* ``compensate --program`` writes the same bytes either way, and without FreeCAD in its
  process when the child is taken.
"""

import json
import os
import pickle
import subprocess
import sys

import numpy as np
import Part
import pytest

from surfcomp.app.nominal import boundary_polylines, load_nominal, nominal_from_data
from surfcomp.errors import GeometryError
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP, ROOT
from tests.app.test_program_fork_cli import raster
from tests.app.trim_cases import HOLE, circle_face

#: take the face of argv[3] (argv[4]: its name, '' for none) through the child and pickle
#: it to argv[5]; prints what was started, the error and the modules this process imported
TAKE = r"""
import json, os, pickle, signal, sys, threading, time
sys.path.insert(0, sys.argv[1])
from surfcomp.app import cadread
from surfcomp.errors import GeometryError
case, path, face, out = sys.argv[2], sys.argv[3], sys.argv[4] or None, sys.argv[5]
if case == "crash":
    cadread._read_face = lambda src, dst, name: os.kill(os.getpid(), signal.SIGSEGV)
elif case == "thread":
    threading.Thread(target=time.sleep, args=(3,), daemon=True).start()
cadread.prefetch_face(path, face)
got = {"started": bool(cadread._FACES)}
try:
    data = cadread.take_face(path, face)
    with open(out, "wb") as fh:
        pickle.dump(data, fh)
except GeometryError as exc:
    got["error"] = str(exc)
got["modules"] = sorted(m for m in ("FreeCAD", "Part", "numpy") if m in sys.modules)
got["left"] = sorted(n for n in os.listdir(os.environ["TMPDIR"]) if n.startswith("surfcomp-read-"))
print(json.dumps(got))
"""


def take(tmp_path, path, face=None, case="read"):
    """``(what the script printed, the FaceData or None)``."""
    out = tmp_path / "face.pickle"
    res = subprocess.run([sys.executable, "-c", TAKE, ROOT, case, str(path), face or "",
                          str(out)], capture_output=True, text=True, timeout=300,
                         env=dict(os.environ, TMPDIR=str(tmp_path)), cwd=str(tmp_path))
    assert res.returncode == 0, res.stderr
    got = json.loads(res.stdout.strip().splitlines()[-1])
    data = None
    if out.exists():
        with open(out, "rb") as fh:
            data = pickle.load(fh)
    return got, data


def same_nominal(data, path, face=None):
    """The nominal made of ``data`` is the one loaded in this process, exactly."""
    mine = nominal_from_data(data, str(path))
    ref = load_nominal(str(path), face)
    a, b = mine.surface, ref.surface
    assert np.array_equal(a.poles, b.poles)
    assert np.array_equal(a.knots_u, b.knots_u) and np.array_equal(a.knots_v, b.knots_v)
    assert (a.weights is None) == (b.weights is None)
    if a.weights is not None:
        assert np.array_equal(a.weights, b.weights)
    assert (a.degree_u, a.degree_v, a.u_range, a.v_range) == \
        (b.degree_u, b.degree_v, b.u_range, b.v_range)
    assert (mine.outward, mine.face_name, mine.converted) == \
        (ref.outward, ref.face_name, ref.converted)
    assert mine.untrimmed == ref.untrimmed
    got, want = mine.boundary, boundary_polylines(ref.bspline_face)
    assert len(got) == len(want) > 0
    assert all(np.array_equal(g, w) for g, w in zip(got, want))
    return mine


def test_the_example_face_comes_without_freecad_or_numpy_in_the_parent(tmp_path):
    got, data = take(tmp_path, EXAMPLE_STEP)
    assert got == {"started": True, "modules": [], "left": []}
    assert same_nominal(data, EXAMPLE_STEP).untrimmed is True


def test_a_trimmed_face_with_a_hole_has_the_same_boundary(tmp_path):
    path = tmp_path / "trimmed.step"
    circle_face(hole=HOLE).exportStep(str(path))
    got, data = take(tmp_path, path)
    assert got["started"] is True and "error" not in got
    nominal = same_nominal(data, path)
    assert nominal.untrimmed is False and len(nominal.boundary) == 2


def test_the_childs_work_imports_no_numpy(tmp_path):
    """What the child does after the fork, run in a fresh Python: FreeCAD and Part only."""
    out = tmp_path / "face.pickle"
    script = ("import sys; sys.path.insert(0, %r)\n"
              "from surfcomp.app.cadread import _read_face\n"
              "code = _read_face(%r, %r, None)\n"
              "print(code, 'numpy' in sys.modules, 'Part' in sys.modules)"
              % (ROOT, EXAMPLE_STEP, str(out)))
    res = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=300)
    assert res.stdout.split() == ["0", "False", "True"], res.stderr
    assert out.stat().st_size > 1000


def _box_step(tmp_path):
    path = tmp_path / "box.step"
    Part.makeBox(10, 20, 30).exportStep(str(path))
    return path


@pytest.mark.parametrize("face", [None, "Face9", "Side"])
def test_a_face_that_cannot_be_chosen_says_what_the_process_says(face, tmp_path):
    path = _box_step(tmp_path)
    got, data = take(tmp_path, path, face)
    with pytest.raises(GeometryError) as ref:
        load_nominal(str(path), face)
    assert data is None and got["error"] == str(ref.value)
    assert got["left"] == []


def test_a_crash_in_the_child_says_the_file_is_damaged(tmp_path):
    got, data = take(tmp_path, EXAMPLE_STEP, case="crash")
    assert data is None and got["error"] == (
        "%s: could not read NOMINAL: the file is damaged (OpenCASCADE crashed while "
        "reading it)" % EXAMPLE_STEP)
    assert got["left"] == []


def test_a_second_thread_starts_no_child(tmp_path):
    got, data = take(tmp_path, EXAMPLE_STEP, case="thread")
    assert got == {"started": False, "modules": [], "left": []} and data is None


#: ``compensate --program`` (argv[2:]), with a second thread alive when argv[1] is "thread";
#: prints whether FreeCAD was imported in this process
RUN = r"""
import sys, threading, time
if sys.argv[1] == "thread":
    threading.Thread(target=time.sleep, args=(30,), daemon=True).start()
from surfcomp.cli import main
code = main(sys.argv[2:])
print("FREECAD", "FreeCAD" in sys.modules, code)
"""


def test_the_program_route_writes_the_same_bytes_with_and_without_the_child(tmp_path):
    program = tmp_path / "finish.ngc"
    raster(program, rows=12)
    outs = {}
    for case in ("child", "thread"):
        outs[case] = tmp_path / ("%s.ngc" % case)
        res = subprocess.run([sys.executable, "-c", RUN, case, "compensate", EXAMPLE_STEP,
                              EXAMPLE_CSV, "--program", str(program), "--tool", "ball:3",
                              "-o", str(outs[case])], capture_output=True, text=True,
                             timeout=300, cwd=ROOT)
        assert res.returncode == 0, res.stderr
        assert res.stdout.strip().splitlines()[-1] == "FREECAD %s 0" % (case == "thread")
    assert outs["child"].read_bytes() == outs["thread"].read_bytes()
    assert outs["child"].read_bytes() != program.read_bytes()


def test_points_outside_the_trim_are_told_from_the_childs_face_too(tmp_path):
    """The direct route said nothing of measured points outside a trimmed face (the file
    route names them); with the face from the child (no OCCT in the process) they are found
    alike, their distances from the boundary polylines on the surface within 2 um of OCCT's."""
    from surfcomp.app.nominal import outside_trim
    from surfcomp.core.compensation.pipeline import Options, prepare
    from surfcomp.io.readers import read_any
    from tests.app.trim_cases import measure, raw_deviation

    path = tmp_path / "trimmed.step"
    circle_face(hole=HOLE).exportStep(str(path))
    _got, data = take(tmp_path, path)
    mine, ref = nominal_from_data(data, str(path)), load_nominal(str(path))
    measure(tmp_path / "m.csv", ref, 9, lambda P, U, V: raw_deviation(P))
    prep = prepare(ref.surface, ref.outward, read_any(str(tmp_path / "m.csv")), Options())
    (k1, d1), (k2, d2) = outside_trim(mine, prep), outside_trim(ref, prep)
    assert np.array_equal(k1, k2) and k1.size > 20
    np.testing.assert_allclose(d1, d2, atol=2e-3)


def test_the_program_route_prints_the_faces_warnings(tmp_path):
    """A corner patch of the example's points: the direct route says how little of the face
    they cover, as the file route does."""
    program = tmp_path / "finish.ngc"
    raster(program, rows=12)
    rows = open(EXAMPLE_CSV).read().splitlines()
    start = next(k for k, t in enumerate(rows) if t.startswith("id,"))
    xy = np.array([[float(f) for f in r.split(",")[1:3]] for r in rows[start + 1:]])
    xs, ys = np.unique(xy[:, 0])[8], np.unique(xy[:, 1])[8]
    patch = tmp_path / "patch.csv"
    patch.write_text("\n".join(rows[:start + 1] + [r for r, (x, y) in zip(rows[start + 1:], xy)
                                                   if x <= xs and y <= ys]) + "\n")
    res = subprocess.run([sys.executable, "-m", "surfcomp", "compensate", EXAMPLE_STEP,
                          str(patch), "--program", str(program), "--tool", "ball:3", "-o",
                          str(tmp_path / "out.ngc")], capture_output=True, text=True,
                         timeout=300, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert "warning: %s: the measured points cover 11 %% of Face1" % patch in res.stderr
