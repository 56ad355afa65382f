# SPDX-License-Identifier: LGPL-2.1-or-later
"""The STEP writer for faces bounded by their knot domain, read back by a small Part 21
reader of its own here (OCCT reads it in tests/app/test_step_face_occt.py)."""

import re

import numpy as np
import pytest

from surfcomp.core.surface.bspline import Surface
from surfcomp.io import step_face
from tests.pure.surfaces import quarter_cylinder, random_surface

ENTITY = re.compile(rb"#(\d+)\s*=\s*(.*?);\s*(?=#\d+\s*=|ENDSEC;)", re.S)


def entities(data):
    """{name: text} of a Part 21 DATA section (no strings with ';' in them here)."""
    body = data[data.index(b"DATA;") + 5:]
    found = {}
    for m in ENTITY.finditer(body):
        name = int(m.group(1))
        assert name not in found, "#%d is defined twice" % name
        found[name] = re.sub(rb"\s+", b" ", m.group(2)).decode("ascii")
    return found


def point(text):
    m = re.fullmatch(r"CARTESIAN_POINT\('',\(([^()]*)\)\)", text)
    return [float(x) for x in m.group(1).split(",")]


def read_surface(data):
    """The B_SPLINE_SURFACE_WITH_KNOTS of ``data`` as (poles, mults u, mults v, knots u,
    knots v, degrees) and the entity table."""
    ents = entities(data)
    (text,) = [t for t in ents.values() if t.startswith("B_SPLINE_SURFACE_WITH_KNOTS")]
    m = re.fullmatch(r"B_SPLINE_SURFACE_WITH_KNOTS\('',(\d+),(\d+),\((.*)\),\.UNSPECIFIED\.,"
                     r"\.F\.,\.F\.,\.F\.,\(([^()]*)\),\(([^()]*)\),\(([^()]*)\),\(([^()]*)\),"
                     r"\.UNSPECIFIED\.\)", text.replace(" ", ""))
    rows = re.findall(r"\(([^()]*)\)", m.group(3))
    poles = np.array([[point(ents[int(r[1:])]) for r in row.split(",")] for row in rows])
    ints = [[int(x) for x in m.group(k).split(",")] for k in (4, 5)]
    reals = [[float(x) for x in m.group(k).split(",")] for k in (6, 7)]
    return poles, ints, reals, (int(m.group(1)), int(m.group(2))), ents


def test_real_is_a_part21_real_that_round_trips():
    cases = {1.0: "1.", -0.5: "-0.5", 1e-05: "1.E-05", 1.5e20: "1.5E+20", 0.1: "0.1",
             -0.0: "-0.", 123456.789: "123456.789"}
    for x, text in cases.items():
        assert step_face.real(x) == text
        assert float(step_face.real(x)) == x
    with pytest.raises(ValueError):
        step_face.real(float("nan"))


def test_fixed_point_numbers_one_width_within_half_a_unit():
    rng = np.random.default_rng(4)
    x = np.r_[rng.uniform(-999.9, 999.9, 2000), 0.0, -0.0, 5e-13, -4e-13, -0.000001]
    text, rounding = step_face.fixed_point(x)
    assert 5e-13 < rounding < 7.5e-13           # 3 digits before the point, 12 after
    assert text.shape == (x.size, 17)
    back = np.array([float(bytes(r)) for r in text])
    assert np.max(np.abs(back - x)) <= rounding
    rows = [bytes(r).decode() for r in text]
    assert rows[2000:] == ["   0.000000000000", "   0.000000000000", "   0.000000000000",
                           "   0.000000000000", "  -0.000001000000"]
    # more whole digits, fewer decimals: every number exact in a double
    text, rounding = step_face.fixed_point([-12345.678, 1.0])
    assert 5e-11 < rounding < 5.5e-11
    assert [bytes(r).decode() for r in text] == ["-12345.6780000000", "     1.0000000000"]
    # numbers that round up to one more whole digit
    for top in (9.9999999999999995, 99.99999999999997, 999.9999999999999, 9999.99999999999):
        text, rounding = step_face.fixed_point([top, -top, 0.5])
        assert np.max(np.abs([float(bytes(r)) for r in text] - np.r_[top, -top, 0.5])) \
            <= rounding
    with pytest.raises(ValueError):
        step_face.fixed_point([1e16])
    with pytest.raises(ValueError):
        step_face.fixed_point([np.inf])


def test_digit_columns_at_quad_and_double_limits():
    n = np.array([0, 9999, 10000, 123456789012345, 999999999999999])
    cols = step_face._digit_columns(n, 15)
    assert [bytes(r) for r in cols] == [b"000000000000000", b"000000000009999",
                                        b"000000000010000", b"123456789012345",
                                        b"999999999999999"]


@pytest.mark.parametrize("reverse", [False, True])
def test_surface_poles_knots_and_topology_come_back(reverse):
    s = random_surface(np.random.default_rng(7), nu=23, nv=17)
    data, rounding = step_face.natural_face_step(s, reverse, 2e-7, "it's")
    poles, (mu, mv), (ku, kv), degrees, ents = read_surface(data)
    assert degrees == (3, 2)
    assert np.max(np.abs(poles - s.poles)) <= rounding < 7.5e-13
    assert np.repeat(ku, mu).tolist() == s.knots_u.tolist()
    assert np.repeat(kv, mv).tolist() == s.knots_v.tolist()
    # every reference names an entity
    names = {int(r) for t in ents.values() for r in re.findall(r"#(\d+)", t)}
    assert names <= set(ents)
    assert sorted(ents) == list(range(1, len(ents) + 1))
    # one face on the surface, its sense, four edges through the four corners
    (face,) = [t for t in ents.values() if t.startswith("ADVANCED_FACE")]
    assert face.endswith(".F.)" if reverse else ".T.)")
    (bound,) = [t for t in ents.values() if t.startswith("FACE_BOUND")]
    assert bound.endswith(".F.)" if reverse else ".T.)")
    corners = sorted(tuple(point(ents[int(re.search(r"#(\d+)", t).group(1))]))
                     for t in ents.values() if t.startswith("VERTEX_POINT"))
    assert corners == sorted(tuple(s.poles[a, b]) for a in (0, -1) for b in (0, -1))
    curves = [t for t in ents.values() if t.startswith("B_SPLINE_CURVE_WITH_KNOTS")]
    ends = sorted(len(re.findall("#", c)) for c in curves)
    assert ends == [17, 17, 23, 23]
    assert sum(t.startswith("PCURVE") for t in ents.values()) == 4
    assert "PRODUCT('it''s','it''s'" in data.decode("ascii")
    assert "LENGTH_MEASURE(2.E-07)" in data.decode("ascii")
    assert "SI_UNIT(.MILLI.,.METRE.)" in data.decode("ascii")


def test_blocks_on_threads_write_the_file_one_block_writes(monkeypatch):
    s = random_surface(np.random.default_rng(8), nu=37, nv=29)
    whole, _ = step_face.natural_face_step(s, name="x")
    monkeypatch.setattr(step_face, "BLOCK_POLES", 60)        # two rows a block, 19 blocks
    blocks, _ = step_face.natural_face_step(s, name="x")
    cut = whole.index(b"DATA;")
    assert blocks[cut:] == whole[cut:]
    assert read_surface(blocks)[0].shape == (37, 29, 3)


def test_lines_stay_short():
    s = random_surface(np.random.default_rng(3), nu=300, nv=40)
    data, _ = step_face.natural_face_step(s)
    assert max(len(line) for line in data.splitlines()) < 100


def test_only_polynomial_clamped_surfaces():
    with pytest.raises(ValueError, match="polynomial"):
        step_face.natural_face_step(quarter_cylinder())
    s = random_surface(np.random.default_rng(1))
    ku = s.knots_u.copy()
    ku[0] = -0.1                      # unclamped: the boundary is not the first pole row
    with pytest.raises(ValueError, match="clamped"):
        step_face.natural_face_step(Surface(s.poles, ku, s.knots_v, 3, 2))


def test_strings_escape_quotes_and_encode_beyond_ascii():
    assert step_face._string("it's a\\b") == r"'it''s a\\b'"
    assert step_face._string("Bl\u00e4tt\t\U0001F600") == r"'Bl\X2\00E4\X0\tt?\X4\0001F600\X0\'"


def test_write_names_the_product_after_the_file_and_reports_a_failed_write(tmp_path):
    s = random_surface(np.random.default_rng(2))
    path = tmp_path / "corrected part.step"
    step_face.write_natural_face(str(path), s)
    assert b"PRODUCT('corrected part','corrected part'" in path.read_bytes()
    # written in parts: the same bytes as the joined text
    data, _ = step_face.natural_face_step(s, name="corrected part")
    cut = data.index(b"DATA;")
    assert path.read_bytes()[cut:] == data[cut:]
    with pytest.raises(Exception, match="cannot write the STEP file"):
        step_face.write_natural_face(str(tmp_path / "missing" / "x.step"), s)
