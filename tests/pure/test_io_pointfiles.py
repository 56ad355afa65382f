# SPDX-License-Identifier: LGPL-2.1-or-later
"""Readers of measured-points-only files: plain XYZ, PC-DMIS XYZIJK, LinuxCNC probe logs.

The samples under tests/data/pointfiles were written by hand for these tests; every
expected number below is the number written in the sample (times 25.4 for inches).
"""

import hashlib
import os
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from surfcomp.errors import InputError, MeasurementFileError
from surfcomp.io.measurements import MeasurementSet
from surfcomp.io.pointfiles import FORMATS, detect_format, is_tip_centre, read_point_file
from tests.conftest import ROOT

DATA = os.path.join(ROOT, "tests", "data", "pointfiles")


def sample(name):
    return os.path.join(DATA, name)


def write(tmp_path, text, name="f.txt", mode="w"):
    p = tmp_path / name
    if mode == "wb":
        p.write_bytes(text)
    else:
        p.write_text(text, encoding="utf-8", newline="")
    return str(p)


def error_of(path, **kw):
    with pytest.raises(MeasurementFileError) as exc:
        read_point_file(path, **kw)
    return exc.value


# ----------------------------------------------------------------------------- detection

@pytest.mark.parametrize("name, fmt", [
    ("plain_header.xyz", "xyz"),
    ("plain_ijk_noheader.csv", "xyz"),
    ("plain_semicolon_comma.txt", "xyz"),
    ("plain_tab_inch.txt", "xyz"),
    ("pcdmis_metric.xyz", "xyzijk"),
    ("pcdmis_inch.xyz", "xyzijk"),
    ("probe-results.txt", "probe"),
    ("two_parts_inch.qif", "qif"),
])
def test_detect_format_of_every_sample(name, fmt):
    assert detect_format(sample(name)) == fmt


def test_detect_format_edge_cases(tmp_path):
    # nine numbers on the first data lines -> probe log; eight -> plain xyz
    assert detect_format(write(tmp_path, "\n" + "1 2 3 4 5 6 7 8 9\n" * 3)) == "probe"
    assert detect_format(write(tmp_path, "1 2 3 4 5 6 7 8\n")) == "xyz"
    # the first non-blank line decides: a later bad line is the probe reader's error
    path = write(tmp_path, "1 2 3 4 5 6 7 8 9\n" * 3 + "1 2 3,5 4 5 6 7 8 9\n")
    assert detect_format(path) == "probe"
    err = error_of(path)
    assert (err.line, err.column) == (4, 5) and "'3,5' in field 3 (Z)" in err.message
    assert detect_format(write(tmp_path, "x y z a b c u v w\n1 2 3 4 5 6 7 8 9\n")) == "xyz"
    assert detect_format(write(tmp_path, "  <?xml version='1.0'?><a/>")) == "qif"
    assert detect_format(write(tmp_path, "XYZIJK    METRIC\n1,2,3\n")) == "xyzijk"
    with pytest.raises(MeasurementFileError, match="empty"):
        detect_format(write(tmp_path, " \n\n"))


def test_is_tip_centre():
    assert [is_tip_centre(f) for f in FORMATS] == [False, False, True, False]
    with pytest.raises(InputError, match="unknown point file format"):
        is_tip_centre("csv")


# ----------------------------------------------------------------------------- plain XYZ

def test_plain_xyz_with_header_comments_and_blank_line():
    path = sample("plain_header.xyz")
    ms = read_point_file(path)
    assert isinstance(ms, MeasurementSet)
    assert_allclose(ms.measured, [[10.0, 20.0, -1.5], [10.5, 20.0, -1.25],
                                  [11.0, 20.0, -1.0], [11.5, 20.5, -0.75]], rtol=0, atol=0)
    assert ms.nominal is None and ms.deviation is None and ms.normal is None
    assert ms.row is None and ms.col is None and ms.ids is None
    # comments on lines 1-2, header on line 3, blank line 6
    assert_array_equal(ms.lines, [4, 5, 7, 8])
    assert ms.units == "mm" and ms.separator == " " and not ms.decimal_comma
    assert ms.columns == {"x_meas": "x", "y_meas": "y", "z_meas": "z"}
    with open(path, "rb") as fh:
        assert ms.sha256 == hashlib.sha256(fh.read()).hexdigest()
    assert ms.warnings == []
    assert len(ms) == 4


def test_plain_xyz_units_argument_scales():
    ms = read_point_file(sample("plain_header.xyz"), units="in")
    assert_allclose(ms.measured[0], [254.0, 508.0, -38.1], rtol=0, atol=1e-12)
    assert ms.units == "in"
    ms = read_point_file(sample("plain_header.xyz"), units="um")
    assert_allclose(ms.measured[3], [0.0115, 0.0205, -0.00075], rtol=0, atol=1e-15)
    assert read_point_file(sample("plain_header.xyz"), units="INCH").units == "in"


def test_plain_xyz_without_header_six_columns_probing_direction():
    ms = read_point_file(sample("plain_ijk_noheader.csv"))
    assert_allclose(ms.measured, [[1, 2, 3], [4, 5, 6], [7, 8, 9]], rtol=0, atol=0)
    # (0, 0, 2) on line 3 is normalised to (0, 0, 1) with a warning naming line 3
    assert_allclose(ms.normal, [[0, 0, 1], [0, 0.6, 0.8], [0, 0, 1]], rtol=0, atol=1e-15)
    assert ms.separator == ","
    assert ms.columns["i"] == "column 4"
    assert len(ms.warnings) == 1
    assert ms.warnings[0].startswith(sample("plain_ijk_noheader.csv") + ":3: 1 direction")


def test_plain_xyz_semicolon_decimal_comma_crlf_ignored_column():
    ms = read_point_file(sample("plain_semicolon_comma.txt"))
    assert_allclose(ms.measured, [[1.5, 2.25, -0.125], [3.5, 4.75, 0.5]], rtol=0, atol=0)
    assert ms.separator == ";" and ms.decimal_comma
    assert ms.ignored_columns == ["note"]
    assert ms.columns == {"x_meas": "X", "y_meas": "Y", "z_meas": "Z"}
    assert_array_equal(ms.lines, [2, 3])
    assert any(":1: columns ignored" in w and "note" in w for w in ms.warnings)


def test_plain_xyz_tab_with_inch_header_units():
    ms = read_point_file(sample("plain_tab_inch.txt"))
    assert_allclose(ms.measured, np.array([[1, 2, 0.5], [-1, 0.25, 0.125]]) * 25.4,
                    rtol=0, atol=1e-12)
    assert ms.units == "in" and ms.separator == "\t"
    # the header's units win over the units argument (as unit suffixes do in tables)
    for units in ("in", "mm", "um"):
        again = read_point_file(sample("plain_tab_inch.txt"), units=units)
        assert again.units == "in"
        assert_allclose(again.measured, ms.measured, rtol=0, atol=0)


def test_plain_xyz_large_file_matches_written_values(tmp_path):
    """The vectorised path reads back exactly what was written (20 000 seeded points)."""
    rng = np.random.default_rng(5)
    pts = rng.normal(scale=150.0, size=(20000, 3))
    path = str(tmp_path / "big.xyz")
    np.savetxt(path, pts, fmt="%.17g", header="x y z", comments="")
    ms = read_point_file(path)
    assert_allclose(ms.measured, pts, rtol=0, atol=0)
    assert_array_equal(ms.lines, np.arange(2, 20002))


def test_plain_xyz_other_header_names_and_trailing_comment(tmp_path):
    path = write(tmp_path, "id,nx,ny,nz,X[mm],Y[mm],Z[mm]\nA,0,0,1,1,2,3 # first\n")
    ms = read_point_file(path)
    assert_allclose(ms.measured, [[1, 2, 3]], rtol=0, atol=0)
    assert_allclose(ms.normal, [[0, 0, 1]], rtol=0, atol=0)
    assert ms.ignored_columns == ["id"]
    assert ms.columns == {"x_meas": "X[mm]", "y_meas": "Y[mm]", "z_meas": "Z[mm]",
                          "i": "nx", "j": "ny", "k": "nz"}


# ------------------------------------------------------------------------- malformed XYZ

@pytest.mark.parametrize("text, line, column, match", [
    ("1.0 2.0 3.0\n4.0 x5 6.0\n", 2, 5, "malformed number 'x5' in field 2"),
    ("1 2 3\n4 5\n", 2, None, "wrong field count: 2 fields, expected 3"),
    ("1 2 3\n\n4 nan 6\n", 3, 3, "'nan' in field 2 .* not a finite number"),
    ("x,y,z\n1,2,inf\n", 2, 5, "'inf' in field 3"),
    ("x,y,z\n1,2,3\n1,2,3,\n", 3, 7, "wrong field count: 4 fields.*ends with a separator"),
    ("x,y,z\n1,,3\n", 2, 3, "empty field 2"),
    ("1 2 3 4\n", 1, None, "wrong field count: 4 fields, expected 3 .* or 6"),
    ("x y w\n1 2 3\n", 1, 1, "names no z column"),
    ("x y z i\n1 2 3 0\n", 1, 1, "names i but not all of i, j, k"),
    ("x y x\n1 2 3\n", 1, 5, "column 'x' repeats 'x'"),
    ("x[mm] y[in] z\n1 2 3\n", 1, None, "different units"),
    ("# only a comment\n\n// and another\n", None, None, "only comments"),
    ("x y z\n# nothing else\n", 1, None, "read as a header, but no points follow"),
    ("1_0 2 3\n", 1, None, "line 1 is not numeric and was read as a header"),
    ("1 2 3\n4 5 6 0 0 1\n", 2, 7, "wrong field count: 6 fields, expected 3"),
    ("1_0 2 3\n4 5 6\n", 1, 1, "line 1 is not numeric.*names no x, y, z column"),
    ("x y z\n1 2 1_0\n", 2, 5, "malformed number '1_0'"),
])
def test_plain_xyz_malformed(tmp_path, text, line, column, match):
    err = error_of(write(tmp_path, text))
    assert (err.line, err.column) == (line, column), str(err)
    assert re.search(match, err.message), err.message


def test_plain_xyz_error_deep_in_a_large_file_names_its_line(tmp_path):
    rng = np.random.default_rng(11)
    lines = ["%.6f %.6f %.6f" % tuple(p) for p in rng.normal(size=(9000, 3))]
    lines[8123] = "1.0 2.0 3.O"           # letter O instead of zero
    err = error_of(write(tmp_path, "x y z\n" + "\n".join(lines) + "\n"))
    assert (err.line, err.column) == (8125, 9)
    assert "'3.O'" in err.message
    lines[8123] = "1.0 2.0 NaN"
    err = error_of(write(tmp_path, "x y z\n" + "\n".join(lines) + "\n"))
    assert (err.line, err.column) == (8125, 9)


@pytest.mark.parametrize("data, line, match", [
    (b"", None, "empty"),
    (b"  \n\t\n", None, "empty"),
    ("x y z\n1 2 3\n".encode("utf-16"), 1, "UTF-16"),
    (b"x y z\n1 2 3\n# caf\xe9\n", 3, "not UTF-8"),
])
def test_encoding_and_empty_files(tmp_path, data, line, match):
    err = error_of(write(tmp_path, data, mode="wb"), fmt="xyz")
    assert err.line == line
    assert match in err.message


def test_missing_file_and_bad_arguments(tmp_path):
    err = error_of(str(tmp_path / "nope.xyz"), fmt="xyz")
    assert "cannot read the file" in err.message and err.file.endswith("nope.xyz")
    with pytest.raises(MeasurementFileError, match="cannot read"):
        detect_format(str(tmp_path / "nope.xyz"))
    with pytest.raises(InputError, match="unknown point file format 'csv'"):
        read_point_file(sample("plain_header.xyz"), fmt="csv")
    with pytest.raises(InputError, match="unknown unit"):
        read_point_file(sample("plain_header.xyz"), units="furlong")
    with pytest.raises(InputError, match="QIF files only"):
        read_point_file(sample("plain_header.xyz"), sample=1)


# ----------------------------------------------------------------------- PC-DMIS XYZIJK

def test_xyzijk_metric_with_directions_and_extra_fields():
    path = sample("pcdmis_metric.xyz")
    ms = read_point_file(path)
    assert_allclose(ms.measured, [[100.0, 50.0, -2.5], [101.0, 50.0, -2.4],
                                  [102.0, 50.5, -2.3]], rtol=0, atol=0)
    assert_allclose(ms.normal, [[0, 0, 1], [0, 0.6, 0.8], [0, 0, 1]], rtol=0, atol=1e-15)
    assert ms.units == "mm" and ms.separator == ","
    assert_array_equal(ms.lines, [2, 3, 4])
    assert ms.ignored_columns == ["field 7", "field 8"]
    assert ms.warnings == [path + ":4: 1 line(s) hold more than 6 numbers (this line first); "
                                  "fields 7-8 are ignored"]


def test_xyzijk_without_metric_is_inch():
    ms = read_point_file(sample("pcdmis_inch.xyz"))
    # file: 1.0,2.0,0.5 / 1.5,2.0,0.25 / -0.5,0.125,0 (inch) -> x 25.4
    assert_allclose(ms.measured, [[25.4, 50.8, 12.7], [38.1, 50.8, 6.35], [-12.7, 3.175, 0.0]],
                    rtol=0, atol=1e-12)
    assert ms.units == "in" and ms.normal is None
    # the header decides: units= (e.g. the CLI's default mm) does not override it
    for units in ("in", "mm"):
        again = read_point_file(sample("pcdmis_inch.xyz"), units=units)
        assert again.units == "in"
        assert_allclose(again.measured, ms.measured, rtol=0, atol=0)
    metric = read_point_file(sample("pcdmis_metric.xyz"), units="in")
    assert metric.units == "mm" and metric.measured[0, 0] == 100.0


def test_xyzijk_crlf_blanks_after_commas_and_bom(tmp_path):
    path = write(tmp_path, b"\xef\xbb\xbfXYZIJK    METRIC  \r\n 1.5, -2 ,3e1\r\n\r\n4,5,6\r\n",
                 mode="wb")
    ms = read_point_file(path)
    assert_allclose(ms.measured, [[1.5, -2.0, 30.0], [4.0, 5.0, 6.0]], rtol=0, atol=0)
    assert_array_equal(ms.lines, [2, 4])


@pytest.mark.parametrize("text, line, column, match", [
    ("XYZIJK METRIC\n1,2,3\n", 1, 8, "METRIC in columns 11-16"),
    ("XYZIJK    METRICS\n1,2,3\n", 1, 11, "malformed XYZIJK header: found 'METRICS'"),
    ("XYZIJK    INCH\n1,2,3\n", 1, 11, "found 'INCH'"),
    ("xyzijk\n1,2,3\n", 1, 1, "capital letters"),
    ("1,2,3\n", 1, 1, "XYZIJK"),
    ("XYZIJK    METRIC\n", 1, None, "no points"),
    ("XYZIJK    METRIC\n1,2,3\n1,2,3,0\n", 3, None, "4 fields, expected 3 .* or 6"),
    ("XYZIJK    METRIC\n1,2,3,0,0,1,5,6,7\n", 2, 17, "9 fields"),
    ("XYZIJK    METRIC\n1,2\n", 2, None, "2 fields"),
    ("XYZIJK    METRIC\n1,2,3\n\n1,2,3,0,0,1\n", 4, None, "line 2 has 3"),
    ("XYZIJK    METRIC\n1,2,3\n1, 2.5.1 ,3\n", 3, 4, "malformed number '2.5.1' in field 2 \\(Y\\)"),
    ("XYZIJK    METRIC\n1,2,3,0,0,0\n", 2, None, "direction vector i j k is zero"),
    ("XYZIJK    METRIC\n1,2,3\n1,2,-inf\n", 3, 5, "'-inf' in field 3"),
])
def test_xyzijk_malformed(tmp_path, text, line, column, match):
    err = error_of(write(tmp_path, text), fmt="xyzijk")
    assert (err.line, err.column) == (line, column), str(err)
    assert re.search(match, err.message), err.message


# ----------------------------------------------------------------------- LinuxCNC probe

def test_probe_log_default_mm_and_inch():
    path = sample("probe-results.txt")
    ms = read_point_file(path)
    expected = np.array([[0.0, 0.0, -0.1012], [0.25, 0.0, -0.1025], [0.5, 0.0, -0.1031],
                         [0.5, 0.25, -0.1009], [0.25, 0.25, -0.0998], [0.0, 0.25, -0.0987]])
    assert_allclose(ms.measured, expected, rtol=0, atol=0)
    assert ms.units == "mm" and ms.normal is None and ms.nominal is None
    assert ms.ignored_columns == ["A", "B", "C", "U", "V", "W"]
    assert ms.warnings == [path + ": probe logs do not record their units; read as mm (G21), "
                                  "give units='in' for G20 programs"]
    inch = read_point_file(path, units="in")          # gridprobe.ngc runs in G20
    assert_allclose(inch.measured, expected * 25.4, rtol=0, atol=1e-12)
    assert inch.units == "in" and inch.warnings == []
    assert_array_equal(inch.lines, np.arange(1, 7))


def test_probe_log_rotary_axes_warn(tmp_path):
    path = write(tmp_path, "1 2 3 0 0 0 0 0 0\n1 2 4 0 90 0 0 0 0.5\n")
    ms = read_point_file(path, fmt="probe", units="mm")
    assert ms.warnings == [path + ": axes B W are not zero in the probe log; only X Y Z are used"]


@pytest.mark.parametrize("text, line, column, match", [
    ("1 2 3 0 0 0 0 0 0\n1 2 3 0 0 0 0 0\n", 2, None, "8 fields, expected 9"),
    ("1 2 3 0 0 0 0 0 0\n\n1 2 3 0 0 0 0 0 0 7\n", 3, 19, "10 fields, expected 9"),
    ("1 2 3 0 0 0 0 0 0\n1 2 3,5 0 0 0 0 0 0\n", 2, 5, "malformed number '3,5' in field 3 \\(Z\\)"),
    ("1 2 nan 0 0 0 0 0 0\n", 1, 5, "'nan' in field 3"),
    ("\n\n", None, None, "empty"),
])
def test_probe_log_malformed(tmp_path, text, line, column, match):
    err = error_of(write(tmp_path, text), fmt="probe")
    assert (err.line, err.column) == (line, column), str(err)
    assert re.search(match, err.message), err.message


@pytest.mark.parametrize("fmt, text, pairs", [
    ("xyz", "x y z\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6.0000000000001\n", 2),
    ("xyzijk", "XYZIJK    METRIC\n1,2,3,0,0,1\n4,5,6,0,0,1\n7,8,9,0,0,1\n1,2,3,0,0,1\n", 1),
    ("probe", "1 2 3 0 0 0 0 0 0\n4 5 6 0 0 0 0 0 0\n7 8 9 0 0 0 0 0 0\n1 2 3 0 0 0 0 0 0\n", 1),
])
def test_a_measured_point_given_twice_is_refused(tmp_path, fmt, text, pairs):
    """As the tables refuse a nominal point given twice (README: duplicate points, exit code
    2): before, a point file's repeated rows were counted twice, and the repeated points
    broke the grid, so the data went to the scattered fit with a warning about a row."""
    with pytest.raises(MeasurementFileError) as err:
        read_point_file(write(tmp_path, text), fmt=fmt)
    first = 2 if fmt != "probe" else 1
    assert str(err.value).endswith("is given again; first on line %d (expected each measured "
                                   "point once; %d duplicate pair(s) in all)" % (first, pairs))
    assert err.value.line == first + 3
    # the same file without its repeated rows: read
    once = "".join(text.splitlines(True)[:4 if fmt != "probe" else 3])
    assert len(read_point_file(write(tmp_path, once, name="g.txt"), fmt=fmt)) == 3


def test_a_bad_value_in_a_plain_xyz_file_is_named_not_its_header(tmp_path):
    """Read without a format, a plain 'x,y,z' file with 'nan' on line 7 was reported as a
    table whose header names no known column (line 1)."""
    from surfcomp.io.readers import read_any

    rows = ["%d,%d,%d" % (k, k + 1, k + 2) for k in range(8)]
    rows[5] = "nan,1,2"
    with pytest.raises(MeasurementFileError) as err:
        read_any(str(write(tmp_path, "x,y,z\n" + "\n".join(rows) + "\n", name="p.csv")))
    assert str(err.value).endswith("p.csv:7:1: 'nan' in field 1 (x) is not a finite number; "
                                   "expected a finite decimal number")
