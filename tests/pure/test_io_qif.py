# SPDX-License-Identifier: LGPL-2.1-or-later
"""QIF 3.0 results: real samples (qif-community, Boost licence, read by path) and a
hand-made two-part inch file with malformed variants.

Numbers quoted from the real files name the file, line and element they come from.
"""

import os
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from surfcomp.errors import InputError, MeasurementFileError
from surfcomp.io.pointfiles import detect_format, read_point_file
from surfcomp.io.qif import qif_samples, read_qif
from tests.conftest import REALDATA, ROOT

QIF_DIR = os.path.join(REALDATA, "measurement", "qif-community")
ONE = os.path.join(QIF_DIR, "SheetMetal_QIF_Results_sample_1.QIF")
SIX = os.path.join(QIF_DIR, "SheetMetal_QIF_Results_6_samples.QIF")
PLAN = os.path.join(QIF_DIR, "sheetMetalPlan.QIF")
HAND = os.path.join(ROOT, "tests", "data", "pointfiles", "two_parts_inch.qif")

#: the 13 surface points (PointFeature*) of the sheet-metal samples, in file order
SURFACE_IDS = ["W1RFSMRA05", "W1RHSMRA06", "W1RISMRA09", "W1RFSMRA11", "W1RISMRA14",
               "W1RISMRA15", "W1RISMRA10", "W1RFSMRA12", "W1RISMRA13", "W1RISMRA16",
               "W1RISMRA07", "W1RFSMRA04", "W1RISMRA08"]


def file_line(path, number):
    with open(path, encoding="utf-8") as fh:
        return fh.read().split("\n")[number - 1]


# ----------------------------------------------------------------------------- real data

def test_real_sample_1_surface_points():
    ms = read_point_file(ONE)               # detected as QIF
    assert detect_format(ONE) == "qif"
    assert len(ms) == 13 and ms.ids == SURFACE_IDS
    assert ms.units == "mm" and ms.kind() == "all"
    assert ms.nominal.shape == ms.measured.shape == ms.normal.shape == (13, 3)
    # W1RFSMRA05: <PointFeatureNominal id="20"> line 228-231 of the file
    assert_allclose(ms.nominal[0], [2466.72924804688, 774.269897460938, 945.002746582031],
                    rtol=0, atol=1e-12)
    assert_allclose(ms.normal[0], [0.731520704665006, 0.146124942551001, -0.665976696147005],
                    rtol=0, atol=1e-15)
    # <PointFeatureMeasurement id="22"> line 1031, <Location> line 1033
    assert_allclose(ms.measured[0], [2466.93, 774.31, 944.82], rtol=0, atol=1e-12)
    assert ms.lines[0] == 1031
    assert 'PointFeatureMeasurement id="22"' in file_line(ONE, ms.lines[0])
    # <PointProfileCharacteristicMeasurement id="26"> line 1141: Value 0.274419156362484
    assert ms.deviation[0] == 0.274419156362484
    # W1RFSMRA11 (id 49, line 1043): Value -0.900290333727268 (id 53, line 1201)
    assert ms.lines[3] == 1043 and ms.deviation[3] == -0.900290333727268
    # W1RISMRA08: Value 0.027216451921572
    assert ms.deviation[12] == 0.027216451921572
    every_line = [file_line(ONE, n) for n in ms.lines]
    assert all("<PointFeatureMeasurement id=" in t for t in every_line)


def test_real_sample_1_deviations_agree_with_geometry():
    """The file's point-profile values equal (actual - nominal) . normal (to 5e-12 mm)."""
    ms = read_point_file(ONE)
    computed = np.einsum("ij,ij->i", ms.measured - ms.nominal, ms.normal)
    assert_allclose(ms.deviation, computed, rtol=0, atol=1e-9)
    assert_allclose(np.linalg.norm(ms.normal, axis=1), 1.0, rtol=0, atol=1e-15)
    assert not any("differs" in w for w in ms.warnings)
    # edge points and holes are skipped and counted; the duplicate 0 values are reported
    assert any("8 measured feature(s) are not surface points and were skipped: 4 Circle, "
               "4 EdgePoint" in w for w in ms.warnings)
    assert any("13 point(s) carry more than one PointProfileCharacteristicMeasurement" in w
               and "0.274419156 used, 0 not" in w for w in ms.warnings)


def test_real_six_samples_listing_and_selection():
    samples = qif_samples(SIX)
    assert [s.serial for s in samples] == ["SN580280%d" % k for k in range(1, 7)]
    assert [s.id for s in samples] == ["199", "260", "321", "382", "443", "504"]
    assert [s.line for s in samples] == [1015, 1501, 1987, 2473, 2959, 3445]
    assert all(s.features == 21 for s in samples)

    first = read_point_file(SIX)
    assert any("the file holds 6 measured parts" in w and "5: SN5802806 (MeasurementResults "
               "id 504, line 3445)" in w for w in first.warnings)
    # sample 0 of the six is the part of the one-sample file
    one = read_point_file(ONE)
    for a in ("nominal", "measured", "normal", "deviation"):
        assert_allclose(getattr(first, a), getattr(one, a), rtol=0, atol=0)

    last = read_point_file(SIX, sample=5)
    # <PointFeatureMeasurement id="448"> line 3461: 2466.98 774.32 944.77; Value line 3579
    assert last.ids[0] == "W1RFSMRA05" and last.lines[0] == 3461
    assert_allclose(last.measured[0], [2466.98, 774.32, 944.77], rtol=0, atol=1e-12)
    assert last.deviation[0] == 0.345755275828788
    assert_allclose(last.nominal, one.nominal, rtol=0, atol=0)
    for key in ("SN5802806", "504", "5", np.int64(5)):
        again = read_qif(SIX, sample=key)
        assert_allclose(again.measured, last.measured, rtol=0, atol=0)
        assert not any("measured parts" in w for w in again.warnings)
    assert np.abs(last.measured - first.measured).max() > 0.05      # a different part


@pytest.mark.parametrize("key, match", [
    (6, r"sample 6 does not exist: the file holds 6 measured part\(s\)"),
    (-1, "sample -1 does not exist"),
    ("SN5802807", "no measured part has the serial number or MeasurementResults id 'SN5802807'"),
    ("17", "sample 17 does not exist"),
])
def test_real_six_samples_bad_selection_lists_the_parts(key, match):
    with pytest.raises(MeasurementFileError) as exc:
        read_qif(SIX, sample=key)
    assert re.search(match, exc.value.message)
    assert "0: SN5802801 (MeasurementResults id 199, line 1015)" in exc.value.message


def test_bad_sample_types():
    for key in (True, 1.0, [1]):
        with pytest.raises(InputError, match="expected a 0-based index"):
            read_qif(SIX, sample=key)


def test_real_plan_has_no_results():
    assert qif_samples(PLAN) == []
    with pytest.raises(MeasurementFileError) as exc:
        read_point_file(PLAN)
    # <QIFDocument ...> starts on line 7 of sheetMetalPlan.QIF
    assert exc.value.line == 7
    assert "no <MeasurementResults> (21 feature nominals" in exc.value.message


# ------------------------------------------------------------------------ hand-made file

def test_hand_made_inch_two_parts():
    ms = read_point_file(HAND)
    assert ms.units == "in" and ms.ids == ["P1", "P2"]
    assert_array_equal(ms.lines, [73, 77])
    # nominal P1 1 2 3 in, P2 1.5 2 3.1 in; actual P1 1 2 3.01, P2 1.512 2 3.116
    assert_allclose(ms.nominal, [[25.4, 50.8, 76.2], [38.1, 50.8, 78.74]], rtol=0, atol=1e-12)
    assert_allclose(ms.measured, [[25.4, 50.8, 76.454], [38.4048, 50.8, 79.1464]],
                    rtol=0, atol=1e-12)
    assert_allclose(ms.normal, [[0, 0, 1], [0.6, 0, 0.8]], rtol=0, atol=0)
    # Value 0.01 (inch) -> 0.254 mm; Value linearUnit="mm" 0.5 -> 0.5 mm
    assert_allclose(ms.deviation, [0.254, 0.5], rtol=0, atol=1e-12)
    # P2: (actual - nominal) . normal = 0.02 in = 0.508 mm, 8 um away from the file's 0.5
    assert ms.warnings.count(HAND + ":77: P2: the file's deviation 0.500000 mm differs from "
                             "(actual - nominal) . normal = 0.508000 mm by 8.0 um (expected "
                             "at most 1 um)") == 1
    assert any(":71: 2 measured feature(s) are not surface points and were skipped: 1 Circle, "
               "1 EdgePoint" in w for w in ms.warnings)
    assert any(":71: 1 point feature(s) have no nominal <Normal> and were skipped: P3" in w
               for w in ms.warnings)
    loose = read_qif(HAND, deviation_tol=0.01)
    assert not any("differs" in w for w in loose.warnings)


def test_hand_made_second_part_without_profile_values():
    ms = read_qif(HAND, sample="SN-B")
    assert_array_equal(ms.lines, [116, 120])
    assert_allclose(ms.deviation, [-0.254, 0.0], rtol=0, atol=1e-12)
    assert "dev" not in ms.columns and ms.kind() == "nominal+measured+normal"
    assert any("2 point(s) carry no point-profile value" in w for w in ms.warnings)


def test_hand_made_units_argument_does_not_override_file_units():
    inch = read_point_file(HAND)
    for units in ("mm", "in"):
        again = read_point_file(HAND, units=units)
        assert again.units == "in"
        assert_allclose(again.nominal, inch.nominal, rtol=0, atol=0)
        assert_allclose(again.deviation, inch.deviation, rtol=0, atol=0)


# --------------------------------------------------------------------- malformed variants

def variant(tmp_path, old, new, count=1, src=HAND):
    with open(src, encoding="utf-8") as fh:
        text = fh.read()
    assert text.count(old) >= count, old
    p = tmp_path / "variant.qif"
    p.write_text(text.replace(old, new, count), encoding="utf-8")
    return str(p)


def qif_error(path, **kw):
    with pytest.raises(MeasurementFileError) as exc:
        read_qif(path, **kw)
    return exc.value


@pytest.mark.parametrize("old, new, line, column, match", [
    ("<Location>1 2 3.01</Location>", "<Location>1 2 3.01</Locaton>", 75, 33,
     "not well-formed XML: mismatched tag"),
    ("</QIFDocument>", "", 142, 1, "not well-formed XML: no element found"),
    ("<FeatureItemId>5</FeatureItemId>", "<FeatureItemId>99</FeatureItemId>", 77, None,
     "refers to FeatureItemId 99, which is no feature item"),
    ("<FeatureNominalId>4</FeatureNominalId>", "<FeatureNominalId>404</FeatureNominalId>", 51,
     None, "<PointFeatureItem id='5'> refers to FeatureNominalId 404"),
    ("<Id>23</Id>", "<Id>230</Id>", 102, None, "refers to feature measurement 230"),
    ("<Location>1.512 2 3.116</Location>", "<Location>1.512 2</Location>", 79, None,
     "holds 2 numbers; expected 3"),
    ("<Location>1.512 2 3.116</Location>", "<Location>1.512 2 3.1x</Location>", 79, None,
     "'3.1x', which is not a number"),
    ("<Normal>0.6 0 0.8</Normal>", "<Normal>0 0 0</Normal>", 31, None, "is zero"),
    ("<Value>0.01</Value>", "<Value>NaN</Value>", 100, None, "expected finite numbers"),
    ('<Value linearUnit="mm">', '<Value linearUnit="furlong">', 106, None,
     "linearUnit='furlong' names no LinearUnit"),
    ("<Factor>0.0254</Factor>", "<Factor>0.001</Factor>", 10, None,
     "named 'inch' but its <Factor> is 0.001 m"),
    ("QIFDocument xmlns", "QIFDocumen xmlns", 141, 3, "mismatched tag"),
    ('xmlns="http://qifstandards.org/xsd/qif3"', 'xmlns="urn:other"', 3, None,
     "in the namespace 'urn:other'"),
])
def test_hand_made_malformed(tmp_path, old, new, line, column, match):
    err = qif_error(variant(tmp_path, old, new))
    assert re.search(match, err.message), err.message
    if line is not None:
        assert (err.line, err.column) == (line, column), str(err)


def test_root_must_be_qif_document(tmp_path):
    p = tmp_path / "x.qif"
    p.write_text('<?xml version="1.0"?>\n\n<Report xmlns="http://qifstandards.org/xsd/qif3"/>\n')
    err = qif_error(str(p))
    assert err.line == 3 and "root element is <Report>" in err.message


def test_empty_and_entity_files(tmp_path):
    p = tmp_path / "e.qif"
    p.write_text("\n  \n")
    assert "empty" in qif_error(str(p)).message
    p.write_text('<?xml version="1.0"?>\n<!DOCTYPE q [\n<!ENTITY a "aaaa">\n]>\n'
                 '<QIFDocument xmlns="http://qifstandards.org/xsd/qif3"/>\n')
    err = qif_error(str(p))
    assert err.line == 3 and "declares entities" in err.message


def test_missing_file_units_means_metres_unless_units_given(tmp_path):
    start = open(HAND, encoding="utf-8").read()
    a, b = start.index("  <FileUnits>"), start.index("  <Features>")
    p = tmp_path / "nounits.qif"
    p.write_text(start[:a] + start[b:].replace(' linearUnit="mm"', ""), encoding="utf-8")
    ms = read_qif(str(p))
    assert ms.units == "m"
    assert_allclose(ms.nominal[0], [1000.0, 2000.0, 3000.0], rtol=0, atol=1e-9)
    assert any("no FileUnits/PrimaryUnits/LinearUnit" in w for w in ms.warnings)
    mm = read_qif(str(p), units="mm")
    assert mm.units == "mm"
    assert_allclose(mm.nominal[0], [1.0, 2.0, 3.0], rtol=0, atol=0)
    assert_allclose(mm.deviation, [0.01, 0.5], rtol=0, atol=0)
    assert any("lengths are read in mm as units='mm' says" in w for w in mm.warnings)


def test_profile_value_found_through_characteristic_item(tmp_path):
    """Without FeatureMeasurementIds the link runs CharacteristicItem -> FeatureItemIds."""
    text = open(HAND, encoding="utf-8").read()
    text = text.replace("""              <FeatureMeasurementIds n="1">
                <Id>22</Id>
              </FeatureMeasurementIds>
""", "              <CharacteristicItemId>60</CharacteristicItemId>\n")
    text = text.replace("  <Results>", """  <Characteristics>
    <CharacteristicItems n="1">
      <PointProfileCharacteristicItem id="60">
        <FeatureItemIds n="1">
          <Id>3</Id>
        </FeatureItemIds>
      </PointProfileCharacteristicItem>
    </CharacteristicItems>
  </Characteristics>
  <Results>""")
    p = tmp_path / "via_item.qif"
    p.write_text(text, encoding="utf-8")
    ms = read_qif(str(p))
    assert_allclose(ms.deviation, [0.254, 0.5], rtol=0, atol=1e-12)
    bad = tmp_path / "bad_item.qif"
    bad.write_text(text.replace("<CharacteristicItemId>60<", "<CharacteristicItemId>61<"),
                   encoding="utf-8")
    err = qif_error(str(bad))
    assert "CharacteristicItemId 61, which is no characteristic item" in err.message


def test_no_surface_points(tmp_path):
    text = open(HAND, encoding="utf-8").read()
    for fid in ("3", "5", "11"):      # point items -> the edge nominal 6
        text = text.replace("<FeatureItemId>%s</FeatureItemId>" % fid,
                            "<FeatureItemId>7</FeatureItemId>")
    p = tmp_path / "edges.qif"
    p.write_text(text, encoding="utf-8")
    err = qif_error(str(p))
    assert err.line == 71
    assert "holds no surface points" in err.message and "4 EdgePoint" in err.message


def test_values_against_their_own_points_on_most_points_are_refused(tmp_path):
    """As a table's dev column: the real sample with every point-profile value's sign
    turned over was read with a warning per point, and compensated the wrong way."""
    with open(ONE, encoding="utf-8") as fh:
        text = fh.read()
    p = tmp_path / "flipped.qif"
    p.write_text(re.sub(r"<Value>(-?)([^<]*)</Value>",
                        lambda m: "<Value>%s%s</Value>" % ("" if m.group(1) else "-", m.group(2)),
                        text), encoding="utf-8")
    err = qif_error(str(p))
    assert str(err) == (
        "%s:1031: W1RFSMRA05: the file's deviation -0.274419 mm has the opposite sign of "
        "(actual - nominal) . normal = 0.274419 mm, as on 13 of the 13 point-profile values "
        "(expected them to agree within 1 um: do the values measure along the inward normal? "
        "Correct the values or the nominal normals)" % p)
    # one value turned over of two, the other off by 8 um: reported, not refused
    ms = read_qif(variant(tmp_path, "<Value>0.01</Value>", "<Value>-0.01</Value>"))
    assert_allclose(ms.deviation, [-0.254, 0.5], rtol=0, atol=1e-12)
    assert sum("differs from (actual - nominal)" in w for w in ms.warnings) == 2


def test_a_nominal_point_measured_twice_is_refused(tmp_path):
    """As in a table: the second measurement of P1 made two rows of one nominal point, which
    the grid search read as a fold."""
    path = variant(tmp_path, "<FeatureItemId>5</FeatureItemId>",
                   "<FeatureItemId>3</FeatureItemId>")
    err = qif_error(path)
    assert str(err) == ("%s:77: nominal point (25.4, 50.8, 76.2) mm is given again; first on "
                        "line 73 (expected each nominal point once; 1 duplicate pair(s) in all)"
                        % path)
