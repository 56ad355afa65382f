# SPDX-License-Identifier: LGPL-2.1-or-later
"""A file's nominal points must be on the face, and its measured points on their nominal
points' normals (surfcomp/core/compensation/plausibility.py ``check_file_points``, called
by ``prepare``): nominal and measured points moved off the face together (another frame or
model), or a measured column shifted by a row, were taken silently as deviations of some
15 um; they are now refused, and small offsets or a few unpaired points are reported."""

import numpy as np
import pytest

from surfcomp.core.compensation import plausibility as pl
from surfcomp.core.compensation.pipeline import Options, prepare
from surfcomp.core.limits import NOMINAL_OFF_FACE, NOMINAL_OFF_FACE_WARNING
from surfcomp.core.simulation.presets import werner_surface
from surfcomp.core.surface import bspline
from surfcomp.errors import MeasurementFileError
from surfcomp.io.measurements import MeasurementSet

N = 15


@pytest.fixture(scope="module")
def face():
    """The Werner face, a 15 x 15 grid on it: nominal points, outward normals, and measured
    points 2-20 um out along them."""
    s = werner_surface()
    u, v = np.meshgrid(np.linspace(0.05, 0.95, N), np.linspace(0.05, 0.95, N), indexing="ij")
    u, v = u.ravel(), v.ravel()
    nominal = bspline.evaluate(s, u, v)
    normal = bspline.normals(s, u, v)
    dev = 0.002 + 0.018 * (u * v)
    return s, nominal, normal, dev


def run(s, **columns):
    ms = MeasurementSet(lines=np.arange(N * N) + 2, source="m.csv", **columns)
    return prepare(s, 1, ms, Options())


def test_pairs_on_the_face_pass_and_give_their_deviations(face):
    s, nominal, normal, dev = face
    got = run(s, nominal=nominal, measured=nominal + dev[:, None] * normal)
    np.testing.assert_allclose(got.deviation, dev, atol=1e-12)
    assert not [w for w in got.warnings if "nominal" in w]


def test_nominal_and_measured_moved_off_the_face_together_are_refused(face):
    """Before: accepted, deviations as in the file (2-20 um) while the points lie 0.5 mm
    off the face."""
    s, nominal, normal, dev = face
    up = np.array([0.0, 0.0, 0.5])
    with pytest.raises(MeasurementFileError) as err:
        run(s, nominal=nominal + up, measured=nominal + dev[:, None] * normal + up)
    text = str(err.value)
    assert text.startswith("m.csv:")
    assert "mm from the face (225 of 225 nominal points are more than 10 um from it): the " \
           "file's nominal points are not on this face" in text


def test_a_deviation_file_whose_nominal_points_are_off_the_face_is_refused(face):
    s, nominal, normal, dev = face
    off = nominal + 0.02 * normal
    with pytest.raises(MeasurementFileError, match="0.0200 mm from the face"):
        run(s, nominal=off, normal=normal, deviation=dev)


def test_nominal_points_a_few_um_off_are_reported_with_the_largest(face):
    s, nominal, normal, dev = face
    shift = np.zeros(N * N)
    shift[[7, 40]] = [0.004, -0.006]           # lines 9 and 42
    got = run(s, nominal=nominal + shift[:, None] * normal, normal=normal, deviation=dev)
    said = [w for w in got.warnings if "nominal points lie" in w]
    assert said == ["m.csv:42: the file's nominal points lie up to 6.00 um off the face (this "
                    "line; 2 of 225 nominal points are more than 1 um from it): the deviations "
                    "are taken against them, so they are off by as much"]


@pytest.mark.parametrize("dist, refused", [(NOMINAL_OFF_FACE_WARNING * 0.99, None),
                                           (NOMINAL_OFF_FACE_WARNING * 1.01, False),
                                           (NOMINAL_OFF_FACE * 0.99, False),
                                           (NOMINAL_OFF_FACE * 1.01, True)])
def test_the_limits(dist, refused):
    got = pl.nominal_off_face(np.array([0.0, -dist, dist / 2]))
    assert (got if got is None else got[2]) is refused
    if got is not None:
        assert got[0] == 1


def test_a_measured_column_shifted_by_one_row_is_refused(face):
    """Before: deviations of mean 11.5 um taken from pairs 0.9-1.9 mm apart."""
    s, nominal, normal, dev = face
    measured = np.roll(nominal + dev[:, None] * normal, 1, axis=0)
    with pytest.raises(MeasurementFileError) as err:
        run(s, nominal=nominal, measured=measured)
    text = str(err.value)
    assert "225 of 225 measured points lie beside their own nominal point" in text
    assert "the measured points do not pair with the nominal points of their rows" in text


def test_a_few_points_beside_their_nominal_point_are_reported(face):
    s, nominal, normal, dev = face
    measured = nominal + dev[:, None] * normal
    tangent = np.cross(normal[20], [0.0, 0.0, 1.0])
    tangent /= np.linalg.norm(tangent)
    measured[20] += 1.8 * tangent              # line 22: 1.8 mm beside its nominal point
    got = run(s, nominal=nominal, measured=measured)
    said = [w for w in got.warnings if "beside" in w]
    assert len(said) == 1 and said[0].startswith(
        "m.csv:22: 1 of 225 measured points lie beside their own nominal point rather than "
        "on its normal (this line: 1.8000 mm beside it")
    assert "their deviations are taken along the normal of the nominal point" in said[0]


def test_a_probe_on_the_normal_with_a_tilted_surface_is_no_mistake(face):
    """Measured points a few um beside the normal (a real probe's lateral error, the part's
    slope error times the tip radius) pass silently."""
    s, nominal, normal, dev = face
    rng = np.random.default_rng(3)
    side = rng.normal(0.0, 0.003, (N * N, 3))
    side -= np.einsum("ij,ij->i", side, normal)[:, None] * normal
    got = run(s, nominal=nominal, measured=nominal + dev[:, None] * normal + side)
    assert not [w for w in got.warnings if "beside" in w or "nominal points" in w]
    np.testing.assert_allclose(got.deviation, dev, atol=1e-12)


def test_measured_points_with_x_and_y_swapped_are_reported(face):
    """Before: deviations spread by half a millimetre (within max_offset 1 mm) were taken
    without a word; the face's size tolerance is +-0.15 mm (ISO 2768-1 fine)."""
    s, nominal, normal, dev = face
    measured = nominal + dev[:, None] * normal
    ok = run(s, measured=measured)
    assert not [w for w in ok.warnings if "spread" in w]
    swapped = run(s, measured=measured[:, [1, 0, 2]])
    said = [w for w in swapped.warnings if "spread" in w]
    spread = np.std(swapped.deviation, ddof=1)
    assert 0.15 < spread < 1.0
    assert said == ["m.csv: the deviations spread by %.0f um (standard deviation), more than "
                    "the face's size tolerance (ISO 2768-1 fine: +-0.15 mm for its largest "
                    "dimension %.1f mm): more than a machining error leaves; is this the "
                    "measurement of this face, in its frame, with the columns in the right "
                    "order?" % (spread * 1e3, pl.largest_dimension(pl.face_samples(s)))]


@pytest.mark.parametrize("spread, warned", [(0.149, False), (0.151, True)])
def test_the_spread_limit_is_the_size_tolerance(spread, warned):
    d = np.array([-1.0, 0.0, 1.0]) * spread        # sample standard deviation = spread
    assert (pl.spread_warning(d, 100.0) is not None) is warned


def test_a_dev_column_in_um_is_pointed_to_deviation_units(face):
    """Before: the hint said units um, which scales the coordinates as well (the points then
    lie 1000 times nearer the origin and are refused as another unit); a dev column's own
    unit is deviation_units."""
    s, nominal, normal, dev = face
    with pytest.raises(MeasurementFileError) as exc:
        run(s, nominal=nominal, normal=normal, deviation=1e3 * dev, columns={"dev": "dev"})
    assert exc.value.message.endswith("are the deviations in um? Give the unit "
                                      "(deviation_units um, or a column name like 'dev [um]')")
    assert exc.value.options == ("max_offset", "deviation_units")
    # a deviation not read from a dev column (a hand-built set): the unit of the values
    with pytest.raises(MeasurementFileError) as exc:
        run(s, nominal=nominal, normal=normal, deviation=1e3 * dev)
    assert "(units um, or" in exc.value.message
