# SPDX-License-Identifier: LGPL-2.1-or-later
"""The deviation column's unit apart from the coordinates' (issue 24, item 5): a file with
coordinates in mm and deviations in um, both without a unit in the column name."""

import os
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.errors import InputError
from surfcomp.io.readers import read_any

ROWS = [(0.8822, 0.8822, 0.301106, 0.0, 0.0, 1.0, 10.5), (2.723793, 0.8822, 0.561186, 0.0, 0.0,
        1.0, -28.9), (4.4, 0.8822, 0.79, 0.0, 0.0, 1.0, 47.1)]


def _file(tmp_path, dev_name="dev", x_name="x_nom"):
    path = tmp_path / "m.csv"
    with open(path, "w") as f:
        f.write("id,%s,y_nom,z_nom,i,j,k,%s\n" % (x_name, dev_name))
        for n, r in enumerate(ROWS, 1):
            f.write("P%d,%s\n" % (n, ",".join("%.10g" % v for v in r)))
    return path


def test_deviation_in_um_coordinates_in_mm(tmp_path):
    ms = read_any(_file(tmp_path), units="mm", deviation_units="um")
    xyz = np.array([r[:3] for r in ROWS])
    assert_allclose(ms.nominal, xyz, atol=1e-12)                    # untouched
    assert_allclose(ms.deviation, [0.0105, -0.0289, 0.0471], atol=1e-12)
    assert ms.units == "mm, deviation um"
    # the other way round: coordinates in um, deviations in mm
    ms = read_any(_file(tmp_path), units="um", deviation_units="mm")
    assert_allclose(ms.nominal, 1e-3 * xyz, atol=1e-15)
    assert_allclose(ms.deviation, [10.5, -28.9, 47.1], atol=1e-12)
    # the same unit twice is the one-unit reading
    ms = read_any(_file(tmp_path), units="um", deviation_units="um")
    assert ms.units == "um" and abs(ms.deviation[0] - 0.0105) < 1e-15


def test_a_column_with_its_own_unit_keeps_it(tmp_path):
    ms = read_any(_file(tmp_path, dev_name="dev [mm]"), units="mm", deviation_units="um")
    assert_allclose(ms.deviation, [10.5, -28.9, 47.1], atol=1e-12)
    ms = read_any(_file(tmp_path, x_name="x_nom [um]"), units="mm", deviation_units="um")
    assert_allclose(ms.nominal[:, 0], 1e-3 * np.array([r[0] for r in ROWS]), atol=1e-15)
    assert_allclose(ms.nominal[:, 1], [r[1] for r in ROWS], atol=1e-12)


def test_a_deviation_computed_from_the_points_keeps_their_unit(tmp_path):
    path = tmp_path / "pts.csv"
    with open(path, "w") as f:
        f.write("x_nom,y_nom,z_nom,i,j,k,x_meas,y_meas,z_meas\n")
        f.write("0,0,0,0,0,1,0,0,0.02\n1,0,0,0,0,1,1,0,-0.01\n")
    ms = read_any(path, units="mm", deviation_units="um")
    assert_allclose(ms.deviation, [0.02, -0.01], atol=1e-12)
    assert ms.units == "mm"


def test_an_unknown_deviation_unit_is_refused(tmp_path):
    # every unit the readers take is named (cm and m were taken but not named)
    with pytest.raises(InputError, match=r"unknown unit 'furlong' \(expected one of mm, um, "
                                         r"in, cm, m\)"):
        read_any(_file(tmp_path), units="mm", deviation_units="furlong")
    assert read_any(_file(tmp_path), units="cm").units == "cm"


def test_a_qif_file_refuses_another_deviation_unit(tmp_path):
    """A QIF file's deviations are in the unit of its points: read in another unit they
    were scaled apart from the points they are checked against (and with FileUnits the
    option was dropped while the report said 'deviation um')."""
    from tests.conftest import ROOT

    qif = os.path.join(ROOT, "tests", "data", "pointfiles", "two_parts_inch.qif")
    with pytest.raises(InputError) as exc:
        read_any(qif, deviation_units="um")
    assert str(exc.value) == (
        "%s: deviation_units um applies to the deviation column of a table; this QIF file "
        "gives its deviations in the unit of its points (in; expected no deviation_units, or "
        "the same as units)" % qif)
    assert exc.value.options == ("deviation_units", "units")
    with open(qif, encoding="utf-8") as fh:     # without FileUnits: read in units
        text = re.sub(r"<FileUnits>.*?</FileUnits>", "", fh.read(), flags=re.S)
    bare = tmp_path / "bare.qif"
    bare.write_text(text.replace(' linearUnit="mm"', ""))
    with pytest.raises(InputError, match="this QIF file gives its deviations"):
        read_any(str(bare), units="mm", deviation_units="um")
    ms = read_any(str(bare), units="um", deviation_units="um")
    assert ms.units == "um" and abs(ms.deviation[0] - 1e-5) < 1e-15
