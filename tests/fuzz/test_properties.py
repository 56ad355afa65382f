# SPDX-License-Identifier: LGPL-2.1-or-later
"""Property-based fuzzing of the readers and validators (hypothesis; no FreeCAD).

Generated measurement tables, point files (XYZ, XYZIJK, probe logs), QIF and FCStd
variants, axis error files, G-code programs and option values (finite, NaN, inf, huge,
negative, zero, text). Every reader and validator either succeeds with what its contract
promises (finite values, unit normals, options inside their documented domains) or raises
:class:`surfcomp.errors.SurfcompError`; any other exception is a defect.

The example count is fixed and the runs are derandomized, so CI is repeatable and stays
well under a minute; ``SURFCOMP_FUZZ_EXAMPLES=N`` runs N random examples per property
instead (``tools/fuzz.sh``).
"""

import functools
import io
import math
import os
import tempfile
import zipfile

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from surfcomp.errors import SurfcompError

from . import inputs as I
from .harness import EXAMPLE_STEP, ROOT

_LONG = int(os.environ.get("SURFCOMP_FUZZ_EXAMPLES", "0") or 0)


def budget(examples):
    """``examples`` derandomized examples in CI; ``SURFCOMP_FUZZ_EXAMPLES`` random ones."""
    return settings(max_examples=_LONG or examples, deadline=None, derandomize=not _LONG,
                    database=None, print_blob=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much,
                                           HealthCheck.function_scoped_fixture])


# ------------------------------------------------------------------------ strategies
SPECIAL = ["nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e308", "-1e308", "1e309",
           "1e-320", "0", "-0", "0.0", "1e400", "9" * 400, "", " ", "abc", "1,5", "1.5.5",
           "0x10", "+.5", "1e", "--1", "1_000", "\u0661", "\x00", "1e-5", "12e3"]


def _formatter(spec):
    """``spec % x`` as a named function: Hypothesis 6.67 describes the function of every
    mapped value it draws, and for a lambda it reads and parses its source each time (half
    the time of a table test)."""
    def format_number(x):
        return spec % x
    return format_number


@functools.lru_cache(maxsize=None)
def number_text(plain=4):
    """Texts a number field may hold: mostly plausible coordinates (``plain`` times as often
    as the rest), finite floats in several notations, special values, garbage."""
    finite = st.floats(allow_nan=False, allow_infinity=False)
    plausible = st.floats(-100, 100).map(_formatter("%.6f"))
    return st.one_of(
        *[plausible] * plain, finite.map(repr), finite.map(_formatter("%g")),
        finite.map(_formatter("%.17e")), st.integers(-10 ** 30, 10 ** 30).map(str),
        st.sampled_from(SPECIAL), st.text(alphabet="0123456789.-+eE ,;", max_size=12))


@functools.lru_cache(maxsize=None)
def option_value():
    """Values an option can arrive with (command line or document property)."""
    return st.one_of(st.none(), st.integers(-10 ** 6, 10 ** 6),
                     st.floats(allow_nan=True, allow_infinity=True),
                     st.sampled_from([0, 0.0, -0.0, 1e-300, 1e300, 1e308, -1e308, 1, 3, 5,
                                      201, 203, 2.5, 16, 17, 100.0, 100.0001, 1e-4, 9e-5,
                                      float("nan"), float("inf"), -float("inf")]))


def mutations(data, max_edits=4):
    """``data`` (bytes) with a few random edits: truncation, deleted, repeated or replaced
    spans, inserted number texts or bytes."""
    @st.composite
    def mutate(draw):
        out = bytearray(data)
        for _ in range(draw(st.integers(1, max_edits))):
            if not out:
                break
            i = draw(st.integers(0, len(out) - 1))
            j = min(len(out), i + draw(st.integers(0, 40)))
            kind = draw(st.sampled_from(["cut", "delete", "repeat", "number", "bytes"]))
            if kind == "cut":
                del out[i:]
            elif kind == "delete":
                del out[i:j]
            elif kind == "repeat":
                out[i:i] = out[i:j]
            elif kind == "number":
                out[i:j] = draw(number_text()).encode("utf-8")
            else:
                out[i:j] = draw(st.binary(max_size=8))
        return bytes(out)
    return mutate()


def _check_set(ms):
    """What a measurement reader promises: finite arrays in mm, unit normals, one line
    number per point."""
    n = len(ms)
    assert n > 0
    for name in ("nominal", "measured", "normal"):
        a = getattr(ms, name)
        if a is not None:
            a = np.asarray(a, dtype=float)
            assert a.shape == (n, 3) and np.isfinite(a).all(), name
    if ms.normal is not None:
        np.testing.assert_allclose(np.linalg.norm(ms.normal, axis=1), 1.0, atol=1e-9)
    if ms.deviation is not None:
        assert np.isfinite(np.asarray(ms.deviation, dtype=float)).all()
    assert len(ms.lines) == n


def _with_file(data, suffix, fn):
    with tempfile.TemporaryDirectory(prefix="surfcomp-fuzz-") as tmp:
        path = os.path.join(tmp, "f" + suffix)
        with open(path, "wb") as fh:
            fh.write(data)
        return fn(path)


def _refused_or(fn, check=None):
    """``fn()``; SurfcompError is a refusal, any other exception fails the property."""
    try:
        value = fn()
    except SurfcompError as exc:
        assert str(exc)
        return None
    if check is not None:
        check(value)
    return value


# ------------------------------------------------------------------------ measurement tables
#: column sets the reader accepts (README "Measurement files"), and names to mix in
ROLE_SETS = [["x_nom", "y_nom", "z_nom", "i", "j", "k", "dev"],
             ["x_nom", "y_nom", "z_nom", "x_meas", "y_meas", "z_meas"],
             ["X Nom", "Y Nom", "Z Nom", "x_meas", "y_meas", "z_meas", "nx", "ny", "nz"],
             ["x_nom", "y_nom", "z_nom", "x_meas", "y_meas", "z_meas", "i", "j", "k", "dev[um]"],
             ["id", "x_nom_in", "y_nom_in", "z_nom_in", "cos_a", "cos_b", "cos_c", "t"]]
OTHER_COLUMNS = ["id", "point", "row", "col", "foo", "dev(mm)", "x", "dx", "x_nom", "dev", "i"]
_VALID = I.csv().encode("utf-8")


@st.composite
def tables(draw):
    """Mostly a header the reader accepts with mostly plausible numbers (so that the
    checks after parsing are reached), else a messier one."""
    cols = list(draw(st.sampled_from(ROLE_SETS)))
    messy = draw(st.integers(0, 2)) == 0
    if messy:
        for _ in range(draw(st.integers(0, 2))):
            cols.insert(draw(st.integers(0, len(cols))), draw(st.sampled_from(OTHER_COLUMNS)))
        if draw(st.booleans()):
            del cols[draw(st.integers(0, len(cols) - 1))]
    sep = draw(st.sampled_from([",", ";", "\t", " ", "  "]))
    end = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    width = st.integers(len(cols) - 1, len(cols) + 1) if messy else st.just(len(cols))
    rows = [[draw(number_text(4 if messy else 60)) for _ in range(draw(width))]
            for _ in range(draw(st.integers(1, 8)))]
    lines = [sep.join(cols)] + [sep.join(r) for r in rows]
    if draw(st.booleans()):
        lines.insert(draw(st.integers(0, len(lines))), draw(st.sampled_from(
            ["# comment", "// comment", "", sep * 3])))
    text = end.join(lines) + draw(st.sampled_from(["", end]))
    return (b"\xef\xbb\xbf" if draw(st.booleans()) else b"") + text.encode("utf-8")


@budget(150)
@given(tables(), st.sampled_from([None, "mm", "um", "in"]))
def test_measurement_tables(data, units):
    from surfcomp.io.measurements import parse_measurements

    _refused_or(lambda: parse_measurements(data, source="<fuzz>", units=units), _check_set)


@budget(150)
@given(mutations(_VALID))
def test_measurement_table_mutations(data):
    from surfcomp.io.measurements import parse_measurements

    _refused_or(lambda: parse_measurements(data, source="<fuzz>"), _check_set)


# ------------------------------------------------------------------------ point files
@st.composite
def point_files(draw):
    kind = draw(st.sampled_from(["xyz", "xyzijk", "probe", "auto"]))
    fields = {"xyz": draw(st.sampled_from([3, 6])), "xyzijk": draw(st.sampled_from([3, 6])),
              "probe": 9, "auto": draw(st.sampled_from([3, 6, 9]))}[kind]
    sep = "," if kind == "xyzijk" else " " if kind == "probe" else \
        draw(st.sampled_from([" ", ",", ";", "\t"]))
    width = st.integers(fields - 1, fields + 1) if draw(st.integers(0, 4)) == 0 \
        else st.just(fields)
    rows = [[draw(number_text(40)) for _ in range(draw(width))]
            for _ in range(draw(st.integers(1, 8)))]
    head = []
    if kind == "xyzijk" or (kind == "auto" and draw(st.booleans())):
        head = [draw(st.sampled_from(["XYZIJK", "XYZIJK    METRIC", "xyzijk ?"]))]
    elif kind == "xyz" and draw(st.booleans()):
        head = [draw(st.sampled_from(["x y z", "x[in] y[in] z[in]", "x,y,z,i,j,k", "a b c"]))]
    text = "\n".join(head + [sep.join(r) for r in rows]) + "\n"
    return kind, text.encode("utf-8")


@budget(150)
@given(point_files(), st.sampled_from([None, "mm", "in"]))
def test_point_files(case, units):
    from surfcomp.io.pointfiles import read_point_file
    from surfcomp.io.readers import read_any

    fmt, data = case
    _with_file(data, ".txt", lambda p: _refused_or(
        lambda: read_point_file(p, fmt=fmt, units=units), _check_set))
    _with_file(data, ".txt", lambda p: _refused_or(lambda: read_any(p, units or "mm"),
                                                   _check_set))


_PROBE = "\n".join("%s %s %s 0 0 0 0 0 0" % tuple(r[1:4]) for r in I.rows()[:20]).encode()


@budget(80)
@given(mutations(_PROBE))
def test_probe_log_mutations(data):
    from surfcomp.io.readers import read_any

    _with_file(data, ".txt", lambda p: _refused_or(lambda: read_any(p), _check_set))


# ------------------------------------------------------------------------ QIF
with open(os.path.join(ROOT, "tests", "data", "pointfiles", "two_parts_inch.qif"), "rb") as _fh:
    _QIF = _fh.read()


@budget(100)
@given(mutations(_QIF, max_edits=3), st.sampled_from([None, 0, 1, "1"]))
def test_qif_mutations(data, sample):
    from surfcomp.io.qif import read_qif

    _with_file(data, ".qif", lambda p: _refused_or(lambda: read_qif(p, sample=sample),
                                                   _check_set))


# ------------------------------------------------------------------------ FCStd
@budget(60)
@given(st.one_of(
    mutations(I.BILLION_LAUGHS.encode(), max_edits=2),
    mutations(b'<?xml version="1.0"?>\n<Document SchemaVersion="4"><Objects Count="1">'
              b'<Object type="Part::Feature" name="Nominal"/></Objects><ObjectData>'
              b'<Object name="Nominal"><Properties><Property name="Proxy"><Python module='
              b'"surfcomp.app.proxies" class="Proxy"/></Property></Properties></Object>'
              b'</ObjectData></Document>\n', max_edits=3)),
       st.booleans())
def test_fcstd_document_xml(xml, as_zip):
    """``Document.xml`` is read with entities refused before FreeCAD sees it; the result
    lists only well-formed object and module names."""
    from surfcomp.io.fcstd import parse_document

    if as_zip:
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as z:
            z.writestr("Document.xml", xml)
        data = buf.getvalue()
    else:
        data = xml

    def check(info):
        assert all(isinstance(m, str) for m in info["modules"])
        assert b"<!ENTITY" not in xml and b"<!DOCTYPE" not in xml

    _with_file(data, ".FCStd", lambda p: _refused_or(lambda: parse_document(p), check))


# ------------------------------------------------------------------------ axis error files
@st.composite
def axis_files(draw):
    layout = draw(st.sampled_from(["long", "tables"]))
    rows = []
    if layout == "long":
        header = draw(st.sampled_from(["axis,position,ex,ey,ez", "axis,position,ex[um],ey,ez",
                                       "axis;position;ex;ey;ez", "axis,position,ex,ex,ez"]))
        sep = ";" if ";" in header else ","
        for _ in range(draw(st.integers(0, 8))):
            rows.append(sep.join([draw(st.sampled_from(["X", "Y", "Z", "x", "Q", ""]))]
                                 + [draw(number_text()) for _ in range(4)]))
    else:
        for ax in draw(st.lists(st.sampled_from("XYZ"), min_size=1, max_size=3)):
            rows.append("%s EX%s EY%s EZ%s" % ((ax,) * 4))
            for _ in range(draw(st.integers(0, 5))):
                rows.append(" ".join(draw(number_text()).replace(" ", "") or "0"
                                     for _ in range(4)))
        header = rows.pop(0)
    return "\n".join([header] + rows) + "\n"


@budget(150)
@given(axis_files(), st.sampled_from([None, 1.0, 1e-3]))
def test_axis_error_files(text, max_error):
    """Read and fit: a refusal, or finite positions and errors (NaN where a row did not
    measure a component, at least one finite error a row, within ``max_error``) and a model
    whose errors are finite across its travel."""
    from surfcomp.core.axis.axis_errors import fit_axis_errors
    from surfcomp.io.axis_csv import read_axis_errors

    def check_table(table):
        for pos, err in table.data.values():
            assert np.isfinite(pos).all() and not np.isinf(err).any()
            assert np.isfinite(err).any(axis=1).all()
            assert max_error is None or np.nanmax(np.abs(err)) <= max_error

    table = _refused_or(lambda: read_axis_errors("<fuzz>", text=text, max_error=max_error),
                        check_table)
    if table is None:
        return

    def check_model(model):
        lo, hi = model.travel[:, 0], model.travel[:, 1]
        lo, hi = np.where(np.isfinite(lo), lo, 0.0), np.where(np.isfinite(hi), hi, 0.0)
        assert np.isfinite(model.error(np.stack([lo, hi, (lo + hi) / 2]))).all()

    _refused_or(lambda: fit_axis_errors(table.data, model="auto", reference=(0.0, 0.0, 0.0),
                                        source="<fuzz>"), check_model)


# ------------------------------------------------------------------------ G-code
WORDS = "GGGGMXXYYZZIJKRFPSNT"
_WORD_VALUE = st.one_of(st.floats(-200, 200).map(_formatter("%.4f")),
                        st.integers(-50, 50).map(str), st.sampled_from(SPECIAL))


@st.composite
def programs(draw):
    lines = []
    for _ in range(draw(st.integers(0, 12))):
        kind = draw(st.integers(0, 9))
        if kind == 0:
            lines.append(draw(st.sampled_from(["(comment)", "; note", "%", "", "(open",
                                               "close)", "((nested))", "/G1 X1", "#1=2",
                                               "O100 sub", "G81 X1 Y1 Z-1 R1", "G41 D1",
                                               "G20", "G91", "G90", "G17", "G18", "G2 R-5",
                                               "M2", "\x00", "G1 X[1+2]"])))
            continue
        words = []
        for _ in range(draw(st.integers(1, 5))):
            letter = draw(st.sampled_from(WORDS))
            if letter == "G":
                words.append("G%s" % draw(st.sampled_from(["0", "1", "2", "3", "00", "01",
                                                           "21", "90", "91", "17", "80"])))
            else:
                words.append(letter + draw(_WORD_VALUE))
        lines.append(draw(st.sampled_from([" ", "", "\t"])).join(words))
    end = draw(st.sampled_from(["\n", "\r\n"]))
    return ("G21 G90 G17" + end if draw(st.booleans()) else "") + end.join(lines) + end


def _zero_model():
    from surfcomp.core.axis.axis_errors import AxisErrorModel

    return AxisErrorModel.from_components()


def _bent_model():
    from surfcomp.core.axis.axis_errors import AxisErrorModel

    return AxisErrorModel.from_components(
        scale={"x": 1e-4}, straightness={"y(x)": (0, 2e-6), "z(y)": (0, 1e-6)})


def _compensate(data, model, max_segments=20000):
    from surfcomp.core.axis.moves import check_segments
    from surfcomp.io.gcode import compensate_gcode, parse_gcode

    parsed = parse_gcode(data, source="<fuzz>")
    check_segments(parsed[0], 2.0, 1e-3, max_segments=max_segments, source="<fuzz>")
    return compensate_gcode(data, model, source="<fuzz>", parsed=parsed, max_error=1.0)


@budget(150)
@given(programs())
def test_gcode_programs(text):
    """Every accepted program comes back unchanged from a zero error model (lines the
    compensation leaves alone are kept byte for byte) and with finite numbers from a real
    one."""
    data = text.encode("utf-8")

    def check_zero(res):
        assert res.output == data

    def check_bent(res):
        out = res.output.decode("latin-1")
        assert "nan" not in out.lower() and "inf" not in out.lower().replace("info", "")

    if _refused_or(lambda: _compensate(data, _zero_model()), check_zero) is not None:
        _refused_or(lambda: _compensate(data, _bent_model()), check_bent)


with open(I.WAVE, "rb") as _fh:
    _WAVE_HEAD = b"".join(_fh.readlines()[:60])


@budget(80)
@given(mutations(_WAVE_HEAD, max_edits=3))
def test_gcode_mutations(data):
    _refused_or(lambda: _compensate(data, _bent_model()))


# ------------------------------------------------------------------------ options
#: README "Command line" and Options.validate: field -> (low, high, whole number)
DOMAINS = {"mask_size": (1, 201, True), "sigma": (1e-3, 201, False), "stock": (0, 10, False),
           "max_offset": (1e-4, 100, False), "refine": (1, 16, True),
           "tip_radius": (0, 50, False), "smoothing": (1e-3, 1e4, False)}
OPTIONAL = ("sigma", "stock", "smoothing")


@budget(300)
@given(st.fixed_dictionaries({name: option_value() for name in DOMAINS}),
       st.sampled_from(["raw", "filtered", "mirror", "offset", "magic"]),
       st.sampled_from(["box", "gaussian", "disc"]),
       st.sampled_from(["renormalize", "reflect", "nearest", "wrap"]),
       st.one_of(st.none(), st.sampled_from(["1 2 1; 2 4 2; 1 2 1", "nan", "1e308", "0",
                                             "1 1; 1 1", "1e300 1e300 1e300; " * 2
                                             + "1e300 1e300 1e300", "-1 2 -1; 2 -4 2; -1 2 -1"])))
def test_options_accepted_are_in_their_domains(values, method, kind, edge, weights):
    from surfcomp.core.compensation.pipeline import Options

    opts = Options(method=method, mask_kind=kind, edge=edge, weights=weights, **{
        k: (v if v is not None or k in OPTIONAL else 0) for k, v in values.items()})

    def check(o):
        for name, (lo, hi, whole) in DOMAINS.items():
            v = getattr(o, name)
            if v is None:
                assert name in OPTIONAL
                continue
            assert math.isfinite(float(v)) and lo <= float(v) <= hi, (name, v)
            if whole:
                assert float(v).is_integer() and (name != "mask_size" or int(v) % 2 == 1)
        assert o.method in ("raw", "filtered", "mirror", "offset")
        assert o.mask_kind in ("box", "gaussian") and o.edge in ("renormalize", "reflect",
                                                                  "nearest")
        assert o.method != "mirror" or o.stock is not None
        mask = o.mask()
        assert np.isfinite(mask).all() and mask.shape[0] % 2 == 1 and abs(mask.sum()) > 0

    _refused_or(opts.validate, check)


@budget(200)
@given(st.one_of(st.text(max_size=20), st.sampled_from(
    ["45x45", "3x3", "4000x4000", "4001x5", "2x9", "100000x100000", "-5x5", "1e3x5", "5*5",
     "5x5x5", "x", "nanxnan", " 7 x 7 ", "0x0"])))
def test_simulate_grid_option(text):
    from surfcomp.cli.simulate import parse_grid
    from surfcomp.core.simulation.simulate import MAX_GRID

    def check(nm):
        assert all(isinstance(k, int) and 3 <= k <= MAX_GRID for k in nm)

    _refused_or(lambda: parse_grid(text), check)


_MODEL_VALUE = option_value().filter(lambda v: v is not None)


@st.composite
def model_values(draw):
    names = ["offset", "slope_gain", "abs_slope_gain", "waviness", "wavelength", "sigma",
             "correlation_length", "probe_sigma", "stock", "semi_engagement"]
    kw = {}
    for name in draw(st.lists(st.sampled_from(names), unique=True, max_size=5)):
        kw[name] = draw(_MODEL_VALUE)
    for name, count in (("tilt", 2), ("bow", 2), ("deflection", 3), ("feed", 3),
                        ("tool_axis", 3)):
        if draw(st.booleans()):
            kw[name] = tuple(draw(_MODEL_VALUE) for _ in range(count))
    return kw


@functools.lru_cache(maxsize=None)
def _preset_grid():
    """A preset's surface (pure numpy) and its 5 x 5 CAM points and normals."""
    from surfcomp.core.simulation import presets
    from surfcomp.core.simulation.process_model import cam_grid

    surface, outward = presets.get_preset("mirror2019-s3").surface()
    us, vs = np.linspace(*surface.u_range, 5), np.linspace(*surface.v_range, 5)
    return (surface,) + tuple(cam_grid(surface, outward, us, vs))


@budget(150)
@given(model_values())
def test_machining_model_values(kw):
    """An accepted machining model machines the preset surface with finite pass errors of
    at most 100 mm (the largest deviation a compensation accepts), or refuses."""
    from surfcomp.core.simulation.process_model import MachiningModel, machine_pass

    surface, S, n = _preset_grid()

    def run():
        model = MachiningModel(**kw)
        assert np.isfinite(model.noise_floor(n.reshape(-1, 3)))
        frame = model.frame(surface, samples=9)
        rng = np.random.default_rng(0)
        e1 = machine_pass(model, frame, S, n, rng, offset=model.stock,
                          engagement=model.semi_depth)[1]
        return machine_pass(model, frame, S, n, rng, engagement=model.stock + e1)[1]

    def check(e):
        assert np.isfinite(e).all() and np.abs(e).max() <= 100.0

    _refused_or(run, check)


@budget(200)
@given(st.one_of(st.text(max_size=24), st.lists(number_text(), min_size=1, max_size=4)
                 .map(",".join)))
def test_triples_and_lengths(text):
    """``--reference``/``--work-offset``/``--start`` and simulate's vectors: three finite
    numbers or a refusal naming the option."""
    from surfcomp.cli.gcode import _triple
    from surfcomp.cli.simulate import _numbers

    def finite3(v):
        assert len(v) == 3 and np.isfinite(np.asarray(v, dtype=float)).all()

    _refused_or(lambda: _triple(text, "--reference"), finite3)
    _refused_or(lambda: _numbers(text, 3, "--feed"), finite3)



# ------------------------------------------------------------------------ the whole command
@budget(25)
@given(mutations(_VALID, max_edits=3), st.sampled_from([(), ("--layout", "scattered"),
                                                       ("--method", "raw", "--mask", "3")]))
def test_compensate_on_mutated_measurements(cad_cache, data, options):
    """``compensate`` on a damaged measurement file, in this process (FreeCAD): exit 0 with
    its output or exit 2 with a message, never a traceback or a numeric warning, nothing
    else written, the input unchanged."""
    from .harness import run_either

    with tempfile.TemporaryDirectory(prefix="surfcomp-fuzz-") as tmp:
        run_either(("compensate", "nominal.step", "m.csv", "-o", "c.step", "--quiet") + options,
                   I.setup(I.copy("nominal.step", EXAMPLE_STEP), I.put("m.csv", data)),
                   os.path.join(tmp, "case"), writes=("c.step",))
