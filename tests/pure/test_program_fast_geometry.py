# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct route's fast geometry equals the full engine's (issue 27).

Cutter-location points of a program are projected from nearby feet
(:mod:`surfcomp.core.surface.projection_chain`) and the realised correction starts from the
neighbours' intersections (:mod:`surfcomp.core.compensation.realised_feet`); both must give
what the full projection engine and
:func:`surfcomp.core.compensation.corrected_check.realised_correction` give, to 1e-9 mm, on
the example's 3D Surface finishing program (an excerpt) and on a raster with rapids,
retracts and a second pass; and the moved programs must be the same bytes.
"""

import dataclasses
import os

import numpy as np
import pytest

from surfcomp.core.compensation.corrected_check import realised_correction
from surfcomp.core.compensation.program_offset import BallOffset
from surfcomp.core.compensation.realised_feet import RealisedAt
from surfcomp.core.simulation.presets import werner_surface
from surfcomp.core.surface.projection import Projector
from surfcomp.core.surface.projection_chain import path_anchors, project_chain
from surfcomp.io.gcode import ProgramFile, parse_gcode
from surfcomp.io.gcode.offset_stream import offset_stream
from tests.toolpath_checks import drop_cutter

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXCERPT = os.path.join(ROOT, "tests", "data", "gcode", "freecad_3dsurface_excerpt.ngc")
R = 3.0
SURF = werner_surface()
TOL = 1e-9


def corrected_surface():
    """The example face moved by a smooth field of up to ~40 um (poles moved along z)."""
    P = SURF.poles.copy()
    i, j = np.meshgrid(np.linspace(0, 1, P.shape[0]), np.linspace(0, 1, P.shape[1]),
                       indexing="ij")
    P[:, :, 2] -= 0.03 * np.sin(3 * i) * np.cos(2 * j) + 0.01
    return dataclasses.replace(SURF, poles=P)


def raster_two_passes():
    """A drop-cutter raster at 0.1 mm spacing, retracts between rows, a second pass
    across the first (rows along y) and a rapid back to the start."""
    lines = ["G21 G90 G17", "M3 S10000", "G0 Z20"]
    xs = np.arange(-2.0, 47.01, 0.1)
    for k, pos in enumerate(np.arange(3.0, 44.0, 10.0)):
        for along_x in (True, False):
            t = xs if k % 2 == 0 else xs[::-1]
            xy = (np.column_stack([t, np.full(t.size, pos)]) if along_x
                  else np.column_stack([np.full(t.size, pos), t]))
            z, _ = drop_cutter(SURF, 1, xy, np.full(t.size, 5.0), R)
            lines.append("G0 X%.4f Y%.4f" % tuple(xy[0]))
            lines.append("G1 Z%.4f F600" % z[0])
            lines.extend("G1 X%.4f Y%.4f Z%.4f" % (p[0], p[1], q) for p, q in zip(xy[1:], z[1:]))
            lines.append("G0 Z20")
    lines += ["G0 X0 Y0", "M2"]
    return "\n".join(lines) + "\n"


def path_points(text, step=0.05):
    """The programmed path's points in order: move ends and points every ``step`` mm."""
    prog, _ = parse_gcode(text)
    known = prog.known.all(axis=1)
    out = []
    for s, e in zip(prog.start[known], prog.end[known]):
        k = max(1, int(np.ceil(np.linalg.norm(e - s) / step)))
        out.append(s + (e - s) * (np.arange(1, k + 1) / k)[:, None])
    return np.concatenate(out)


@pytest.fixture(scope="module", params=["excerpt", "raster"])
def case(request):
    text = open(EXCERPT).read() if request.param == "excerpt" else raster_two_passes()
    return request.param, text


def test_anchors_cut_the_path_at_jumps_and_every_spacing():
    P = np.array([[0, 0, 0], [0.3, 0, 0], [0.6, 0, 0], [0.9, 0, 0], [0.9, 0, 5],
                  [np.nan, 0, 0], [1, 0, 0], [1.05, 0, 0]], dtype=float)
    assert path_anchors(P, 0.5).tolist() == [True, False, True, False, True, True, True,
                                             False]


def test_chain_projection_equals_the_full_engine(case):
    name, text = case
    centres = path_points(text)
    centres[:, 2] += R
    pj = Projector(SURF)
    full = pj.project(centres, max_distance=R + 2.0)
    counts = {}
    warm = project_chain(pj, centres, R + 2.0, counts=counts)
    assert counts["warm"] > 0.8 * full.converged.sum(), counts
    assert np.array_equal(full.converged, warm.converged)
    ok = full.converged
    assert ok.sum() > 1000
    np.testing.assert_allclose(warm.foot[ok], full.foot[ok], rtol=0, atol=TOL)
    np.testing.assert_allclose(warm.distance[ok], full.distance[ok], rtol=0, atol=TOL)
    np.testing.assert_allclose(warm.normal[ok], full.normal[ok], rtol=0, atol=TOL)
    assert np.array_equal(warm.outside, full.outside)


def test_realised_correction_at_feet_equals_the_full_one(case):
    _name, text = case
    centres = path_points(text)
    centres[:, 2] += R
    pr = Projector(SURF).project(centres, max_distance=R + 2.0)
    ok = pr.converged & ~pr.outside
    u, v, foot, normal = pr.u[ok], pr.v[ok], pr.foot[ok], pr.normal[ok]
    corrected = corrected_surface()
    exact = realised_correction(SURF, corrected, u, v, 1)
    fast = RealisedAt(SURF, corrected, 1)
    t = fast.at(u, v, foot, normal)
    assert fast.counts["warm"] > 0.8 * u.size, fast.counts
    assert 0.005 < np.abs(exact).max() < 0.05
    np.testing.assert_allclose(t, exact, rtol=0, atol=TOL)
    np.testing.assert_allclose(RealisedAt(SURF, corrected, 1, warm=False).at(u, v, foot, normal),
                               exact, rtol=0, atol=TOL)


def offsets(corrected):
    """The fast and the full :class:`BallOffset` of the example face's correction."""
    fast = BallOffset(SURF, 1, R, RealisedAt(SURF, corrected, 1), 1.0)
    full = BallOffset(SURF, 1, R, lambda u, v: realised_correction(SURF, corrected, u, v, 1),
                      1.0, warm=False)
    return fast, full


def test_displacements_equal_the_full_engine(case):
    _name, text = case
    fast, full = offsets(corrected_surface())
    pts = path_points(text)
    a, b = fast.displace(pts), full.displace(pts)
    assert fast.counts["warm"] > 0 and full.counts["warm"] == 0
    assert np.abs(b.move).max() > 0.005
    np.testing.assert_allclose(a.move, b.move, rtol=0, atol=TOL)
    fin = np.isfinite(b.gap)
    assert np.array_equal(fin, np.isfinite(a.gap))
    np.testing.assert_allclose(a.gap[fin], b.gap[fin], rtol=0, atol=TOL)
    np.testing.assert_allclose(a.weight, b.weight, rtol=0, atol=TOL)
    np.testing.assert_allclose(a.tilt, b.tilt, rtol=0, atol=TOL)
    assert np.array_equal(a.interior, b.interior)


def test_moved_program_is_the_same_with_the_fast_geometry(case, tmp_path):
    name, text = case
    path = tmp_path / ("%s.ngc" % name)
    path.write_text(text)
    outs, moved = [], []
    for off in offsets(corrected_surface()):
        out = []
        po = offset_stream(ProgramFile(str(path)), out.append, off, source=path.name)
        outs.append("".join(out))
        moved.append(po.stats()["moves_moved"])
    assert moved[0] == moved[1] > 100
    assert outs[0] == outs[1]
