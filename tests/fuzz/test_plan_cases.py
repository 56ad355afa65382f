# SPDX-License-Identifier: LGPL-2.1-or-later
"""``plan NOMINAL -o PLAN.csv`` and ``simulate --plan`` on bad input: counts, probe options,
layouts, faces, plan files; exit 2 naming what is wrong, nothing written."""

import pytest

from . import inputs as I
from .harness import EXAMPLE_STEP, Case, run_case

NOM = I.copy("nominal.step", EXAMPLE_STEP)


def plan(name, *extra, setup=NOM, **kw):
    return Case(name, ("plan", "nominal.step", "-o", "p.csv", "--dropped", "d.csv")
                + tuple(extra) + ("--quiet",), setup=setup, **kw)


#: a plan file of the example face whose second point is 2 mm off the face
_PLAN = ("id,x_nom,y_nom,z_nom,i,j,k\n"
         "P1,22.500048,22.498308,8.986155,0.060979958,0.027622833,0.997756696\n"
         "P2,22.500048,1.508288,4.826250,0.006361981,-0.314657164,0.949184068\n")

CASES = [
    plan("count-0x5", "--count", "0x5", says=("--count '0x5': expected at least 1 point",)),
    plan("count-over-a-million", "--count", "1001x1000",
         says=("--count '1001x1000': 1001000 points, expected at most 1000000",)),
    plan("count-text", "--count", "tenxten", says=("--count 'tenxten': expected UxV",)),
    plan("points-0", "--layout", "adaptive", "--points", "0",
         says=("--points 0: expected a whole number from 1 to 1000000",)),
    plan("points-with-grid", "--points", "50", says=("--points applies to the adaptive",)),
    plan("count-with-adaptive", "--layout", "uniform", "--count", "3x3",
         says=("--count applies to the grid and xy layouts",)),
    plan("tip-radius-0", "--tip-radius", "0", says=("--tip-radius 0",)),
    plan("tip-radius-nan", "--tip-radius", "nan", says=("--tip-radius nan",)),
    plan("tip-radius-above-concave", "--tip-radius", "56",
         says=("--tip-radius 56 mm is larger than the face's smallest concave radius",)),
    plan("max-tilt-95", "--max-tilt", "95", says=("--max-tilt 95.0: expected an angle",)),
    plan("edge-margin-negative", "--edge-margin=-1", says=("--edge-margin -1.0",)),
    plan("clearance-inf", "--clearance", "inf", says=("--clearance inf",)),
    plan("no-reachable-point", "--max-tilt", "0",
         says=("no reachable point on the face", "normal leans more than --max-tilt")),
    plan("face-99", "--face", "Face99", file="nominal.step", says=("no Face99",)),
    plan("dropped-equals-output", "--dropped", "p.csv", says=("name the same file",)),
    Case("simulate-plan-off-the-face", ("simulate", "nominal.step", "--plan", "pl.csv",
                                        "--grid", "5x5", "--replicas", "1", "--quiet"),
         setup=I.setup(NOM, I.put("pl.csv", _PLAN)), file="pl.csv", line=3,
         says=("point P2 lies", "expected the plan of this face")),
    Case("simulate-plan-not-a-plan", ("simulate", "nominal.step", "--plan", "pl.csv",
                                      "--grid", "5x5", "--replicas", "1", "--quiet"),
         setup=I.setup(NOM, I.put("pl.csv", "x,y,z\n1,2,3\n")), file="pl.csv", line=1),
]


@pytest.mark.parametrize("case", CASES, ids=str)
def test_case(case, tmp_path, request):
    request.getfixturevalue("cad_cache")
    run_case(case, tmp_path / "case")
