# SPDX-License-Identifier: LGPL-2.1-or-later
"""Measured points that cover only part of the face are reported (surfcomp/app/nominal.py
``coverage_warning``): a 9 x 9 patch of 5.4 mm in a corner of the 45 mm example face built
a correction over the whole face (37.7 um at the opposite corner, where the full grid has
-10.4 um) without a word. The example's own grid, and a trimmed face measured inside its
trim, are not reported."""

import numpy as np
import pytest

from surfcomp.app.file_route import Job, run_job
from surfcomp.app.nominal import coverage, load_nominal, nominal_from_face
from surfcomp.core.compensation.pipeline import Options, prepare
from surfcomp.io.readers import read_any
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP
from tests.app.trim_cases import INSIDE, circle_face, measure, raw_deviation

SAID = "the measured points cover"


def _rows(path):
    lines = open(path).read().splitlines()
    start = next(k for k, t in enumerate(lines) if t.startswith("id,"))
    return lines[:start + 1], lines[start + 1:]


def test_a_patch_in_a_corner_is_reported_with_its_share(tmp_path):
    head, rows = _rows(EXAMPLE_CSV)
    xy = np.array([[float(f) for f in r.split(",")[1:3]] for r in rows])
    xs, ys = np.unique(xy[:, 0])[8], np.unique(xy[:, 1])[8]
    corner = [r for r, (x, y) in zip(rows, xy) if x <= xs and y <= ys]      # 9 x 9 points
    patch = tmp_path / "patch.csv"
    patch.write_text("\n".join(head + corner) + "\n")
    assert len(corner) == 81
    _comp, rep = run_job(Job(nominal=EXAMPLE_STEP, measurements=str(patch), command="inspect"))
    said = [w for w in rep["warnings"] if SAID in w]
    assert said == ["%s: the measured points cover 11 %% of Face1 (its area within 3 point "
                    "spacings of a point); over the rest of the face the correction is "
                    "continued from the border of the measured area, where nothing was "
                    "measured (expected measurements over the whole face)" % patch]
    # the share, on a 5 times finer sampling of the face: the same to a percent
    nominal = load_nominal(EXAMPLE_STEP)
    prep = prepare(nominal.surface, nominal.outward, read_any(str(patch)), Options())
    assert coverage(nominal, prep, n=300) == pytest.approx(coverage(nominal, prep), abs=0.01)
    assert 0.11 < coverage(nominal, prep, n=300) < 0.13


def test_the_example_grid_covers_its_face():
    nominal = load_nominal(EXAMPLE_STEP)
    prep = prepare(nominal.surface, nominal.outward, read_any(EXAMPLE_CSV), Options())
    assert coverage(nominal, prep) == pytest.approx(1.0, abs=1e-12)
    _comp, rep = run_job(Job(nominal=EXAMPLE_STEP, measurements=EXAMPLE_CSV, command="inspect"))
    assert not [w for w in rep["warnings"] if SAID in w]


def test_a_trimmed_face_measured_inside_its_trim_is_covered(tmp_path):
    """The circle face's grid inside the circle covers the face, not the rectangle of its
    surface (about 38 % of which the circle is)."""
    face = circle_face()
    src = tmp_path / "trimmed.brep"
    face.exportBrep(str(src))
    nominal = nominal_from_face(face)
    measure(tmp_path / "m.csv", nominal, 12, lambda P, U, V: raw_deviation(P), box=INSIDE)
    prep = prepare(nominal.surface, nominal.outward, read_any(str(tmp_path / "m.csv")),
                   Options())
    assert coverage(nominal, prep) > 0.95
