# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measurement-file reader: accepted forms, every error class, checks and a large round trip."""

import hashlib
import os
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from surfcomp.errors import InputError, MeasurementFileError
from surfcomp.io import columns, measurements
from surfcomp.io.measurements import MeasurementSet, parse_measurements, read_measurements
from tests.conftest import ROOT

DATA = os.path.join(ROOT, "tests", "data", "measurements")

# the four points of the hand-made sample files (mm) and their unit normals
NOM = np.array([[0.0, 0.0, 10.0], [10.0, 0.0, 10.5], [0.0, 10.0, 10.5], [10.0, 10.0, 11.0]])
NRM = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0, 0.6, 0.8], [0.36, 0.48, 0.8]])
DEV = np.array([0.012, -0.008, 0.020, -0.015])

NND_HEADER = ["x_nom", "y_nom", "z_nom", "i", "j", "k", "dev"]


def nnd_text(sep=",", header=NND_HEADER, fmt="%r", rows=None):
    """nominal+normal+deviation text of the four sample points."""
    rows = np.column_stack([NOM, NRM, DEV]) if rows is None else rows
    body = [sep.join(fmt % v for v in r) for r in rows.tolist()]
    return "\n".join([sep.join(header)] + body) + "\n"


def parse_error(text, **kw):
    with pytest.raises(MeasurementFileError) as info:
        parse_measurements(text, source="f.csv", **kw)
    return info.value


def check_nnd(ms, dev=DEV):
    assert ms.kind() == "nominal+normal+deviation"
    assert_allclose(ms.nominal, NOM, atol=1e-12, rtol=0)
    assert_allclose(ms.normal, NRM, atol=1e-12, rtol=0)
    assert_allclose(ms.deviation, dev, atol=1e-12, rtol=0)
    assert ms.measured is None


# -- sample files -------------------------------------------------------------------------


def test_werner_report_with_comments_and_ids():
    path = os.path.join(DATA, "werner_nnd.csv")
    ms = read_measurements(path)
    check_nnd(ms)
    assert_array_equal(ms.lines, [5, 6, 8, 9])
    assert ms.ids == ["P1", "P2", "P3", "P4"]
    assert ms.columns == {"x_nom": "x_nom", "y_nom": "y_nom", "z_nom": "z_nom", "i": "cos_alpha",
                          "j": "cos_beta", "k": "cos_gamma", "dev": "dev", "id": "id"}
    assert (ms.separator, ms.decimal_comma, ms.units) == (",", False, "mm")
    assert ms.warnings == [] and ms.ignored_columns == []
    assert ms.source == path and len(ms) == 4
    with open(path, "rb") as fh:
        assert ms.sha256 == hashlib.sha256(fh.read()).hexdigest()


def test_bom_crlf_semicolon_decimal_comma_quoted_names_micrometres():
    path = os.path.join(DATA, "calypso_like.csv")
    with open(path, "rb") as fh:
        raw = fh.read()
    assert raw.startswith(b"\xef\xbb\xbf") and b"\r\n" in raw
    ms = read_measurements(path)
    check_nnd(ms, dev=[0.012, -0.0085, 0.020, -0.015])
    assert (ms.separator, ms.decimal_comma, ms.units) == (";", True, "mixed")
    assert ms.ids == ["Pt 1", "Pt 2", "Pt 3", "Pt 4"]
    assert ms.columns["x_nom"] == "X Nom [mm]" and ms.columns["dev"] == "Deviation [µm]"
    assert ms.ignored_columns == ["Remark"]
    assert ms.warnings == ["%s:1: column 9 'Remark' is ignored (not a known column name)" % path]
    assert_array_equal(ms.lines, [2, 3, 4, 5])     # the ';;;;;;;;' row counts as blank
    assert ms.sha256 == hashlib.sha256(raw).hexdigest()


def test_tab_all_four_with_grid_and_one_deviation_off_by_5um():
    path = os.path.join(DATA, "grid_all_tab.txt")
    ms = read_measurements(path)
    assert ms.kind() == "all"
    assert ms.separator == "\t"
    assert_array_equal(ms.row, [0, 0, 1, 1])
    assert_array_equal(ms.col, [0, 1, 0, 1])
    assert ms.row.dtype == np.int64
    true_dev = np.array([0.010, -0.020, 0.030, 0.025])
    assert_allclose(ms.measured, NOM + true_dev[:, None] * NRM, atol=1e-9, rtol=0)
    assert_allclose(ms.deviation, [0.010, -0.020, 0.030, 0.030], atol=1e-12, rtol=0)  # the file's
    assert len(ms.warnings) == 1
    w = ms.warnings[0]
    assert w.startswith(path + ":5: dev 0.030000 mm differs")
    assert "0.025000 mm by 5.0 um" in w


def test_inch_suffix_runs_of_blanks_nominal_measured():
    ms = read_measurements(os.path.join(DATA, "inch_spaces.txt"))
    assert ms.kind() == "nominal+measured"
    assert (ms.separator, ms.units) == (" ", "in")
    assert_allclose(ms.nominal, 25.4 * np.array([[1, 0, 0.5], [1, 1, 0.5], [2, 1, 0.75]]),
                    atol=1e-12, rtol=0)
    assert_allclose(ms.measured[:, 2], 25.4 * np.array([0.5005, 0.4990, 0.75]), atol=1e-12, rtol=0)
    assert ms.normal is None and ms.deviation is None
    assert_array_equal(ms.lines, [3, 4, 5])


def test_missing_file_is_a_measurement_file_error():
    path = os.path.join(DATA, "no_such_file.csv")
    with pytest.raises(MeasurementFileError) as info:
        read_measurements(path)
    assert info.value.file == path and "cannot read the file" in str(info.value)


# -- separators, line ends, decimal comma -----------------------------------------------


@pytest.mark.parametrize("sep", [",", ";", "\t", " ", "   ", " \t "])
def test_every_separator(sep):
    ms = parse_measurements(nnd_text(sep))
    check_nnd(ms)
    assert ms.separator == {",": ",", ";": ";"}.get(sep, "\t" if "\t" in sep else " ")


def test_comma_separated_with_blanks_around_fields():
    ms = parse_measurements(nnd_text(" , "))
    check_nnd(ms)


@pytest.mark.parametrize("eol", ["\n", "\r\n", "\r"])
def test_line_ends(eol):
    text = "# comment\n\n" + nnd_text()
    ms = parse_measurements(text.replace("\n", eol))
    check_nnd(ms)
    assert_array_equal(ms.lines, [4, 5, 6, 7])


def test_bom_in_bytes_and_str():
    text = nnd_text()
    ms = parse_measurements(b"\xef\xbb\xbf" + text.encode())
    check_nnd(ms)
    assert ms.sha256 == hashlib.sha256(b"\xef\xbb\xbf" + text.encode()).hexdigest()
    check_nnd(parse_measurements("\ufeff" + text))


@pytest.mark.parametrize("sep", [";", "\t", " "])
def test_decimal_comma(sep):
    text = nnd_text(sep, fmt="%.4f").replace(".", ",")
    ms = parse_measurements(text)
    check_nnd(ms)
    assert ms.decimal_comma


def test_decimal_comma_file_whose_ids_have_dots():
    text = "id;x_nom;y_nom;z_nom;i;j;k;dev\nP1.1;1,5;0;0;0;0;1;0,25\nP1.2;2,5;0;0;0;0;1;-0,5\n"
    ms = parse_measurements(text)
    assert ms.decimal_comma and ms.ids == ["P1.1", "P1.2"]
    assert_allclose(ms.nominal[:, 0], [1.5, 2.5], atol=1e-15, rtol=0)
    assert_allclose(ms.deviation, [0.25, -0.5], atol=1e-15, rtol=0)


def test_decimal_point_file_whose_names_have_commas():
    text = 'name;x_nom;y_nom;z_nom;i;j;k;dev\n"left, top";1.5;0;0;0;0;1;0.25\n'
    ms = parse_measurements(text)
    assert not ms.decimal_comma and ms.ids == ["left, top"]
    assert_allclose(ms.nominal[0], [1.5, 0, 0], atol=1e-15, rtol=0)


def test_integers_only_are_read_without_decimal_comma():
    ms = parse_measurements("x_nom;y_nom;z_nom;i;j;k;dev\n1;2;3;0;0;1;0\n")
    assert not ms.decimal_comma
    assert_allclose(ms.nominal, [[1, 2, 3]], atol=0)


# -- column names and units --------------------------------------------------------------


SPEC_ALIASES = {
    "x_nom": ["x_nom", "nom_x", "x_nominal", "nominal_x", "xn"],
    "x_meas": ["x_meas", "meas_x", "x_act", "act_x", "x_actual", "actual_x", "xm"],
    "i": ["i", "nx", "cos_a", "cosx", "cos_alpha"],
    "j": ["j", "ny", "cos_b", "cosy", "cos_beta"],
    "k": ["k", "nz", "cos_c", "cosz", "cos_gamma"],
    "dev": ["dev", "d", "t", "deviation", "error"],
    "row": ["row"], "col": ["col"], "id": ["id", "name"],
}


@pytest.mark.parametrize("role, name", [(r, n) for r, ns in SPEC_ALIASES.items() for n in ns])
def test_aliases_of_the_spec(role, name):
    assert columns.role_of(name.upper())[0] == role
    assert columns.role_of(name)[0] == role


def test_every_alias_in_mixed_case_reads_the_same_data():
    rng = np.random.default_rng(7)
    roles = ["x_nom", "y_nom", "z_nom", "x_meas", "y_meas", "z_meas", "i", "j", "k", "dev",
             "row", "col", "id"]
    nom = rng.uniform(-50, 50, (3, 3))
    nrm = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0, 0.8, 0.6]])
    dev = np.array([0.01, -0.02, 0.005])
    meas = nom + dev[:, None] * nrm
    rows = np.column_stack([nom, meas, nrm, dev, [0, 0, 1], [0, 1, 0]])
    longest = max(len(v) for v in columns.ALIASES.values())
    for pick in range(longest):
        names = []
        for r in roles:
            alias = columns.ALIASES[r][pick % len(columns.ALIASES[r])]
            names.append("".join(ch.upper() if q % 2 else ch for q, ch in enumerate(alias)))
        body = [",".join([repr(v) for v in r] + ["p%d" % q]) for q, r in enumerate(rows.tolist())]
        ms = parse_measurements("\n".join([",".join(names)] + body))
        assert ms.kind() == "all", names
        assert list(ms.columns) == roles and list(ms.columns.values()) == names
        assert_allclose(ms.measured, meas, atol=1e-12, rtol=0)
        assert_allclose(ms.deviation, dev, atol=1e-12, rtol=0)
        assert ms.ids == ["p0", "p1", "p2"] and ms.warnings == []


@pytest.mark.parametrize("name, role", [("X Nom", "x_nom"), ("x-nominal", "x_nom"),
                                        ("Nominal.X", "x_nom"), ("Actual X", "x_meas"),
                                        ("cos(alpha)", "i"), ("Point #", "id"), ("temp[C]", None)])
def test_name_normalisation(name, role):
    assert columns.role_of(name)[0] == role


def test_alias_table_in_docstring_matches_the_code():
    doc = measurements.__doc__
    section = doc[doc.index("Alias table"):doc.index("``x``, ``y``, ``z`` alone")]
    entries = re.findall(r"^- ``(\w+)``: (.*?)(?=^- |\Z)", section, re.M | re.S)
    table = {role: [n.strip() for n in names.split(",")] for role, names in entries}
    assert table == columns.ALIASES
    every = [n for names in table.values() for n in names]
    assert len(set(every)) == len(every), "an alias names two roles"


@pytest.mark.parametrize("suffix, factor, units", [("[mm]", 1.0, "mm"), ("[um]", 1e-3, "um"),
                                                   ("_um", 1e-3, "um"), ("(µm)", 1e-3, "um"),
                                                   ("[in]", 25.4, "in"), ("_in", 25.4, "in"),
                                                   ("_mm", 1.0, "mm")])
def test_unit_suffix_on_every_length_column(suffix, factor, units):
    header = [n + suffix if n in ("x_nom", "y_nom", "z_nom", "dev") else n for n in NND_HEADER]
    ms = parse_measurements(nnd_text(header=header))
    assert_allclose(ms.nominal, NOM * factor, atol=1e-12, rtol=0)
    assert_allclose(ms.deviation, DEV * factor, atol=1e-12, rtol=0)
    assert_allclose(ms.normal, NRM, atol=1e-12, rtol=0)
    assert ms.units == units


@pytest.mark.parametrize("units, factor", [("mm", 1.0), ("um", 1e-3), ("in", 25.4), ("IN", 25.4),
                                           (None, 1.0)])
def test_units_option_applies_to_columns_without_suffix(units, factor):
    header = ["x_nom", "y_nom", "z_nom", "i", "j", "k", "dev[um]"]
    ms = parse_measurements(nnd_text(header=header), units=units)
    assert_allclose(ms.nominal, NOM * factor, atol=1e-12, rtol=0)
    assert_allclose(ms.deviation, DEV * 1e-3, atol=1e-15, rtol=0)
    assert ms.units == ("um" if units == "um" else "mixed")


# -- combinations, checks, warnings ---------------------------------------------------------


def test_nominal_measured_normal_computes_the_deviation():
    dev = np.array([0.05, -0.03, 0.0, 0.1])
    meas = NOM + dev[:, None] * NRM + 0.2 * np.cross(NRM, [0.0, 0.0, 1.0])  # tangential part
    rows = np.column_stack([NOM, meas, NRM * 2.0])                           # normals of length 2
    text = nnd_text(header=["xn", "yn", "zn", "xm", "ym", "zm", "nx", "ny", "nz"], rows=rows)
    ms = parse_measurements(text, source="f.csv")
    assert ms.kind() == "nominal+measured+normal"
    assert_allclose(ms.deviation, dev, atol=1e-12, rtol=0)
    assert_allclose(ms.normal, NRM, atol=1e-15, rtol=0)
    assert len(ms.warnings) == 4 and "f.csv:2: the normal (0, 0, 2) has length 2" in ms.warnings[0]


def test_deviation_without_normal_is_ignored_with_a_warning():
    text = "x_nom,y_nom,z_nom,x_meas,y_meas,z_meas,dev\n1,2,3,1,2,3.5,0.5\n"
    ms = parse_measurements(text, source="f.csv")
    assert ms.kind() == "nominal+measured"
    assert ms.deviation is None and ms.normal is None
    assert ms.ignored_columns == ["dev"] and "dev" not in ms.columns
    assert ms.warnings == ["f.csv:1: column 7 'dev' is ignored (without a normal i j k the "
                           "deviation is computed from the face)"]


def _flipped_table(n_flipped, n=25):
    """A table of all four whose last ``n_flipped`` dev values have the wrong sign; dev."""
    rng = np.random.default_rng(3)
    nom = np.column_stack([np.arange(n, dtype=float), rng.uniform(0, 10, n), np.zeros(n)])
    nrm = np.tile([0.0, 0.0, 1.0], (n, 1))
    dev = rng.uniform(0.01, 0.05, n)
    given = np.r_[dev[:n - n_flipped], -dev[n - n_flipped:]] + 0.0009 * (np.arange(n) == 2)
    rows = np.column_stack([nom, nom + dev[:, None] * nrm, nrm, given])
    head = ["x_nom", "y_nom", "z_nom", "x_meas", "y_meas", "z_meas", "i", "j", "k", "dev"]
    return nnd_text(header=head, rows=rows), given


def test_deviation_cross_check_caps_the_warnings_and_spots_the_sign():
    text, given = _flipped_table(12)                          # 12 of 25 with the wrong sign
    ms = parse_measurements(text, source="f.csv")
    assert ms.kind() == "all"
    assert_allclose(ms.deviation, given, atol=1e-12, rtol=0)
    assert len(ms.warnings) == 12
    assert [w.split(":")[1] for w in ms.warnings[:10]] == [str(k) for k in range(15, 25)]
    assert ms.warnings[10] == ("f.csv: 2 more deviations differ from (measured - nominal) . "
                               "normal by more than 1 um")
    assert "12 differing deviation(s) have the opposite sign" in ms.warnings[11]


def test_a_dev_column_against_its_own_points_on_most_rows_is_refused():
    """Half the rows or more with dev flipped against their own points: refused (before: a
    warning, and the face built from the flipped column)."""
    text, given = _flipped_table(13)
    with pytest.raises(MeasurementFileError) as err:
        parse_measurements(text, source="f.csv")
    assert str(err.value) == (
        "f.csv:14: dev %.6f mm has the opposite sign of (measured - nominal) . normal = %.6f "
        "mm, as on 13 of the 25 rows (expected them to agree within 1 um: does the dev column "
        "measure along the inward normal? Correct the file, or leave out the dev column or the "
        "measured points)" % (given[12], -given[12]))


def test_normal_within_tolerance_gives_no_warning():
    rows = np.column_stack([NOM, NRM * (1 + 9e-4), DEV])
    ms = parse_measurements(nnd_text(rows=rows))
    assert ms.warnings == []
    assert_allclose(np.linalg.norm(ms.normal, axis=1), 1.0, atol=1e-15, rtol=0)


def test_ignored_columns_and_hints_are_reported():
    text = "x_nom,temp[C],y_nom,z_nom,i,j,k,dev,dx,\n1,20.5,2,3,0,0,1,0.1,0.1,\n"
    ms = parse_measurements(text, source="f.csv")
    assert ms.ignored_columns == ["temp[C]", "dx", ""]
    assert ms.warnings[0] == "f.csv:1: column 2 'temp[C]' is ignored (not a known column name)"
    assert ms.warnings[1].startswith("f.csv:1: column 9 'dx' is ignored (dx, dy, dz (deviation")
    assert ms.warnings[2] == "f.csv:1: column 10 '' is ignored (it has no name)"


def test_points_closer_than_the_tolerance_are_not_duplicates_if_1e_8_apart():
    rows = np.column_stack([NOM, NRM, DEV])
    rows[1, :3] = rows[0, :3] + [1e-8, 0, 0]
    ms = parse_measurements(nnd_text(rows=rows))
    assert len(ms) == 4


def test_hand_built_set():
    ms = MeasurementSet(nominal=NOM, normal=NRM, deviation=DEV)
    assert ms.kind() == "nominal+normal+deviation"
    assert_array_equal(ms.lines, [1, 2, 3, 4])
    assert len(ms) == 4
    with pytest.raises(InputError):
        MeasurementSet(nominal=NOM, normal=NRM).kind()
    assert MeasurementSet(measured=NOM).kind() == "measured"
    assert MeasurementSet(measured=NOM, normal=NRM).kind() == "measured+normal"
    assert MeasurementSet(nominal=NOM, measured=NOM, normal=NRM, deviation=DEV).kind() == \
        "nominal+measured+normal"
    assert MeasurementSet(nominal=NOM, measured=NOM, normal=NRM, deviation=DEV,
                          columns={"dev": "dev"}).kind() == "all"


# -- errors ------------------------------------------------------------------------------


def test_errors_are_input_errors_with_exit_code_2():
    e = parse_error("")
    assert isinstance(e, InputError) and e.exit_code == 2


@pytest.mark.parametrize("text", ["", "\n\n  \n", b""])
def test_empty_file(text):
    e = parse_error(text)
    assert e.line is None and str(e).startswith("f.csv: the file is empty (expected a header")


def test_only_comments():
    e = parse_error("# a\n// b\n\n")
    assert e.line == 2 and "only comments and blank lines (expected a header row" in e.message


def test_no_header():
    e = parse_error("# measured points\n\n1,2,3,0,0,1,0.1\n")
    assert e.line == 3
    assert "holds only numbers but no header came before it (expected a header row" in e.message
    assert "looks like the header" not in e.message
    assert str(e).startswith("f.csv:3: this row")


def test_no_header_points_at_a_commented_header():
    e = parse_error("# x_nom;y_nom;z_nom;i;j;k;dev\n1;2;3;0;0;1;0,1\n")
    assert e.line == 2 and "line 1 looks like the header but is a comment" in e.message


def test_header_with_no_known_column():
    e = parse_error("# c\nfoo,bar,x,y,z\n1,2,3,4,5\n")
    assert e.line == 2 and e.column is None
    assert "names no known column: 'foo', 'bar', 'x', 'y', 'z' (expected" in e.message
    assert "x, y, z alone are ambiguous" in e.message


def test_not_enough_columns_says_which_are_missing():
    e = parse_error("x_nom,y_nom,z_nom,dev\n1,2,3,4\n")
    assert str(e) == ("f.csv:1: the header has x_nom y_nom z_nom and dev but no normal (i j k) and "
                      "no measured point (x_meas y_meas z_meas) (expected nominal+normal+deviation "
                      "or nominal+measured)")


@pytest.mark.parametrize("header, missing", [
    ("x_nom,y_nom,z_nom,i,j,k", "no deviation (dev) and no measured point"),
    ("x_meas,y_meas,z_meas,i,j,k,dev", "no nominal point (x_nom y_nom z_nom) ("),
    ("i,j,k,dev,row,col", "has i j k and dev but no nominal point (x_nom y_nom z_nom) ("),
    ("id,x_nom,y_nom,z_nom", "no normal (i j k) and no deviation (dev) and no measured point"),
])
def test_not_enough_columns_variants(header, missing):
    e = parse_error(header + "\n")
    assert (e.line == 1 and missing in e.message
            and "(expected nominal+normal+deviation" in e.message)


def test_not_enough_columns_lists_ignored_ones():
    e = parse_error("x_nom,y_nom,z_nom,i,j,k,dev_nm,id\n")
    assert "has x_nom y_nom z_nom and i j k but no deviation (dev) and no measured" in e.message
    assert e.message.endswith("; ignored columns: 'dev_nm'")


@pytest.mark.parametrize("header, text", [
    ("x_nom,y_nom,i,j,k,dev", "has x_nom y_nom but no z_nom (expected all of x_nom y_nom z_nom"),
    ("x_nom,y_nom,z_nom,i,k,dev", "has i k but no j (expected all of i j k"),
    ("x_nom,y_nom,z_nom,x_meas,z_meas", "has x_meas z_meas but no y_meas"),
    ("x_nom,y_nom,z_nom,i,j,k,dev,col", "has col but no row (expected all of row col, or none)"),
])
def test_partial_groups(header, text):
    e = parse_error("# c\n" + header + "\n")
    assert e.line == 2 and text in e.message


def test_same_role_twice():
    e = parse_error("x_nom,y_nom,z_nom,i,j,k,dev,Deviation\n")
    assert (e.line, e.column) == (1, 8)
    assert "column 'Deviation' is dev again, already given by 'dev' in column 7" in e.message
    assert str(e).startswith("f.csv:1:8: ")


def test_unknown_unit_suffix():
    e = parse_error("x_nom,y_nom,z_nom,i,j,k,dev[nm]\n")
    assert (e.line, e.column) == (1, 7) and "unit 'nm', which is not known (expected" in e.message


def test_unit_on_a_normal():
    e = parse_error("x_nom,y_nom,z_nom,i[mm],j,k,dev\n")
    assert (e.line, e.column) == (1, 4) and "takes no unit" in e.message


def test_invalid_units_option():
    e = parse_error(nnd_text(), units="ft")
    assert e.message == "units 'ft' is not a known unit (expected mm, um or in)"
    assert e.options == ("units",)      # the command line shows --units


def test_header_without_rows():
    e = parse_error("# c\nx_nom,y_nom,z_nom,i,j,k,dev\n\n# end\n")
    assert e.line == 2 and "not followed by any data row (expected" in e.message


@pytest.mark.parametrize("field, what", [("abc", "column 'dev' holds 'abc' (expected a number)"),
                                         ("0.1.2", "holds '0.1.2' (expected a number)"),
                                         ("1_000", "holds '1_000' (expected a number)"),
                                         ("", "column 'dev' is empty (expected a number)")])
def test_text_in_a_number(field, what):
    text = nnd_text() + "# c\n1,1,1,0,0,1,%s\n2,2,2,0,0,1,x\n" % field
    e = parse_error(text)
    assert (e.line, e.column) == (7, 7) and what in e.message


def test_text_in_a_decimal_comma_number():
    e = parse_error("x_nom;y_nom;z_nom;i;j;k;dev\n1,5;2;3;0;0;1;0,1\n2,5;2;3;0;0;1;0,1,2\n")
    assert (e.line, e.column) == (3, 7) and "holds '0,1,2' (expected a number)" in e.message


@pytest.mark.parametrize("field", ["nan", "NaN", "inf", "-Infinity", "1e999"])
def test_nan_and_inf(field):
    e = parse_error(nnd_text() + "1,1,1,0,%s,1,0.1\n" % field)
    assert (e.line, e.column) == (6, 5)
    assert "column 'j' holds '%s'" % field in e.message and "finite number" in e.message


def test_duplicate_points_name_both_lines():
    rows = np.column_stack([NOM, NRM, DEV])
    rows[3, :3] = rows[1, :3] + [0, 1e-10, 0]
    e = parse_error(nnd_text(rows=rows))
    assert e.line == 5
    assert "nominal point (10, 1e-10, 10.5) mm is given again; first on line 3" in e.message
    assert "1 duplicate pair(s)" in e.message


def test_zero_normal():
    e = parse_error(nnd_text() + "5,5,5,0,0,0,0.1\n")
    assert (e.line, e.column) == (6, 4) and "the normal (0, 0, 0) has zero length" in e.message


def test_mixed_decimal_marks():
    e = parse_error("x_nom;y_nom;z_nom;i;j;k;dev\n1;2;3;0;0;1;0,1\n# c\n1;2;4.5;0;0;1;0,1\n")
    assert (e.line, e.column) == (4, 3)
    assert "'4.5' in column 'z_nom' has a decimal point but line 2 has a decimal comma ('0,1')" \
        in e.message


def test_decimal_comma_with_comma_separator_is_a_ragged_row():
    e = parse_error("x_nom,y_nom,z_nom,i,j,k,dev\n1,5,2,3,0,0,1,0\n")
    assert e.line == 2 and "has 8 fields" in e.message


def test_row_index_not_whole():
    e = parse_error("x_nom,y_nom,z_nom,x_meas,y_meas,z_meas,row,col\n1,2,3,1,2,3,0,0\n"
                    "2,2,3,2,2,3,0,1.5\n")
    assert (e.line, e.column) == (3, 8) and "holds 1.5 (expected a whole number" in e.message


def test_not_utf8():
    raw = nnd_text().encode() + "9,9,9,0,0,1,0.1 # µm\n".encode("latin-1")
    e = parse_error(raw)
    assert e.line == 6 and "not UTF-8 (expected UTF-8" in e.message


def test_utf16():
    e = parse_error(nnd_text().encode("utf-16"))
    assert e.line == 1 and "UTF-16 text (expected UTF-8" in e.message


# -- a large round trip ----------------------------------------------------------------------


def test_round_trip_200k_rows():
    rng = np.random.default_rng(20240611)
    n = 200_000
    nom = rng.uniform(-1000.0, 1000.0, (n, 3))
    nrm = rng.normal(size=(n, 3))
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    dev = rng.normal(scale=0.05, size=n)
    meas = nom + dev[:, None] * nrm
    cols = np.column_stack([nom, meas, nrm, dev])
    row = ";".join(["%.17g"] * cols.shape[1])      # (np.char.mod took 12 s)
    out = ["# written by test_round_trip_200k_rows",
           "X_NOM;Y_NOM;Z_NOM;X_MEAS;Y_MEAS;Z_MEAS;I;J;K;DEV"]
    lines = []
    for q, r in enumerate(cols.tolist()):
        if q % 1000 == 999:
            out.append("// block %d" % q)
        out.append(row % tuple(r))
        lines.append(len(out))
    ms = parse_measurements("\r\n".join(out) + "\r\n")
    assert ms.kind() == "all" and len(ms) == n and ms.warnings == []
    assert_allclose(ms.nominal, nom, atol=1e-12, rtol=0)
    assert_allclose(ms.measured, meas, atol=1e-12, rtol=0)
    assert_allclose(ms.normal, nrm, atol=1e-12, rtol=0)
    assert_allclose(ms.deviation, dev, atol=1e-12, rtol=0)
    assert_array_equal(ms.lines, lines)


@pytest.mark.parametrize("body, lines", [
    ("A\nB\n", [2, 3]),                      # plain: one scan of the text, no row tests
    ("A\nB", [2, 3]),                        # no newline at the end
    ("A\nB\n , ,\n\n  \n", [2, 3]),          # blank tails, separators only
    ("\nA\nB\n", [3, 4]),                    # a blank row first
    ("A\n ,\t,\nB\n", [2, 4]),               # a blank row inside
    ("A\n# note\nB\n", [2, 4]),              # a comment row
    ("A\n  // note\nB\n", [2, 4]),
    ("A\nB,\n", None),                       # a separator too many on the last row
    ("A\r\r\nB\r\r\n\r\r\n", [2, 3]),           # doubled CRs: rows of a lone CR are blank
    ("A\n\u00a0\nB\n", [2, 4]),               # a row of a no-break space is blank
    ("A\n#\u00a0\nB\n", [2, 4]),
])
def test_data_rows_with_and_without_blank_or_comment_rows(body, lines):
    """The rows after the header: blank rows (blanks and separators only) and comments are
    skipped whether the text is scanned once (none of them) or row by row."""
    text = "x_nom,y_nom,z_nom,x_meas,y_meas,z_meas\n" + body.replace(
        "A", "0,0,0,0,0,0.001").replace("B", "5,0,0,5,0,0.002")
    if lines is None:
        with pytest.raises(MeasurementFileError, match="has 7 fields.*ends with a separator"):
            parse_measurements(text)
        return
    ms = parse_measurements(text)
    assert ms.lines.tolist() == lines
    assert_allclose(ms.measured[:, 2], [0.001, 0.002])
