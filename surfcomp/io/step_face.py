# SPDX-License-Identifier: LGPL-2.1-or-later
"""STEP file (ISO 10303-21, AP214) of one B-spline face bounded by its surface's parameter
range, written from the pole net directly.

OpenCASCADE's writer makes an object per pole and formats each number on its own, which
takes seconds for pole nets of a million poles (bench/run.py measures both writers). Here
the poles are formatted as fixed-point numbers by array operations. The file has the
entities OpenCASCADE writes for such a face, in its layout (an open shell of one
ADVANCED_FACE, its four boundary iso-curves with their parameter lines as PCURVEs,
millimetres, the uncertainty as the edge tolerance), so that a reader sees the same face.
Faces of any other shape go through OpenCASCADE (:func:`surfcomp.app.file_route.write_face`).

Numbers: the poles with 10^-12 mm resolution in fixed point (12 decimals while the largest
coordinate is below 1000 mm, one fewer for each further digit, so that every number stays
exact in a double); knots, corners and edge poles with Python's shortest round-trip form.
Spaces pad the pole numbers and entity names to a fixed width, which Part 21 allows
between tokens.
"""

import datetime
import os

import numpy as np

from ..core.chunks import for_chunks
from ..core.surface.bspline import clamped, compress_knots
from ..errors import InputError

#: poles per line of a B_SPLINE_SURFACE_WITH_KNOTS list of references
REFS_PER_LINE = 8
#: the fixed-point numbers keep at most this many significant digits (all exact in a double)
DIGITS = 15
#: and at most this many decimals (10^-12 mm)
DECIMALS = 12


def real(x):
    """A STEP REAL for ``x``: Python's shortest round-trip digits with the decimal point
    Part 21 requires (``1.``, ``1.E-05``)."""
    x = float(x)
    if not np.isfinite(x):
        raise ValueError("a STEP file cannot hold %r" % x)
    text = repr(x).upper()
    mantissa, _, exponent = text.partition("E")
    if "." not in mantissa:
        mantissa += "."
    elif mantissa.endswith(".0"):
        mantissa = mantissa[:-1]
    return mantissa + ("E" + exponent if exponent else "")


#: the four ASCII digits of 0 ... 9999 (made by array arithmetic: a list of 10 000 byte
#: strings cost every start more, docs/benchmarks.md, "Costs behind choices in the code")
_QUADS = (np.arange(10000)[:, None] // np.array([1000, 100, 10, 1]) % 10 + ord("0")) \
    .astype(np.uint8)


def _digit_columns(n, width):
    """``n`` (non-negative integers below 10^15) as ASCII digit columns, shape (len(n),
    width)."""
    quads = -(-width // 4)
    out = np.empty((n.size, 4 * quads), dtype=np.uint8)
    # in doubles, which are exact below 2^53 and divide in vector registers
    rest = n.astype(float)
    for k in range(quads - 1, -1, -1):
        high = np.floor(rest / 10000.0)
        out[:, 4 * k:4 * k + 4] = _QUADS[(rest - high * 10000.0).astype(np.intp)]
        rest = high
    return out[:, 4 * quads - width:]


def _right_aligned(digits, keep, mark):
    """Replace the leading zeros of ``digits`` (all but the last ``keep`` columns may go) by
    spaces and put ``mark[i]`` (a byte, or 32 for none) just before the first digit kept;
    returns an array one column wider."""
    n, width = digits.shape
    out = np.full((n, width + 1), 32, dtype=np.uint8)
    out[:, 1:] = digits
    lead = np.logical_and.accumulate(digits[:, :width - keep] == 48, axis=1)
    out[:, 1:width - keep + 1][lead] = 32
    count = lead.sum(axis=1)
    out[np.arange(n), count] = mark
    return out


def _layout(top):
    """(whole digits, decimals) of the fixed-point numbers up to ``top`` in magnitude."""
    whole = len("%d" % top) if top >= 1 else 1
    while whole <= DIGITS:
        decimals = max(0, min(DECIMALS, DIGITS - whole))
        if np.rint(top * 10.0 ** decimals) < 10.0 ** (whole + decimals):
            return whole, decimals
        whole += 1          # top rounds up to one more whole digit
    raise ValueError("coordinates of %g are too large for a STEP file in mm" % top)


def _fixed(x, whole, decimals):
    """The ASCII array (len(x), whole + decimals + 2) of :func:`fixed_point`."""
    scaled = np.rint(np.abs(x) * 10.0 ** decimals)
    digits = _digit_columns(scaled, whole + decimals)
    sign = np.where(np.signbit(x) & (scaled > 0), 45, 32).astype(np.uint8)
    head = _right_aligned(digits[:, :whole], 1, sign)
    point = np.full((x.size, 1), 46, dtype=np.uint8)
    return np.hstack([head, point, digits[:, whole:]])


def _finite_top(x):
    if x.size and not np.all(np.isfinite(x)):
        raise ValueError("a STEP file cannot hold non-finite coordinates")
    return float(np.max(np.abs(x), initial=0.0))


def _rounding(top, decimals):
    """Half a unit of the last decimal, and the doubles' own rounding of x * 10^decimals."""
    return 0.5 * 10.0 ** -decimals + 2 * float(np.spacing(top))


def fixed_point(x):
    """Fixed-width fixed-point STEP REALs for the array ``x``: (ASCII array (len(x), width),
    a bound on the rounding error in units of ``x``). As many decimals as keep 15
    significant digits for the largest number, at most 12."""
    x = np.ravel(np.asarray(x, dtype=float))
    top = _finite_top(x)
    whole, decimals = _layout(top)
    return _fixed(x, whole, decimals), _rounding(top, decimals)


def _names(ids, width):
    """Entity names ``#id`` right-aligned to ``width`` digits, as an ASCII array."""
    ids = np.asarray(ids, dtype=np.int64)
    return _right_aligned(_digit_columns(ids, width), 1, 35)


def _text(*parts):
    """Join ASCII arrays (n, w_k) and constant byte strings row by row into bytes."""
    n = next(p.shape[0] for p in parts if isinstance(p, np.ndarray))
    cols = [p if isinstance(p, np.ndarray) else
            np.broadcast_to(np.frombuffer(p, dtype=np.uint8), (n, len(p))) for p in parts]
    return np.hstack(cols).tobytes()


def _compact(text):
    """``text`` without its spaces (the padding of the fixed-width columns)."""
    a = np.frombuffer(text, dtype=np.uint8)
    return a[a != 32].tobytes()


class _Entities:
    """Entity text with the names given out in order."""

    def __init__(self):
        self.lines = []
        self.next = 1

    def reserve(self, count=1):
        first = self.next
        self.next += count
        return first

    def add(self, text, name=None):
        name = self.reserve() if name is None else name
        self.lines.append(("#%d = %s;\n" % (name, text)).encode("ascii"))
        return name

    def point(self, p):
        return self.add("CARTESIAN_POINT('',(%s))" % ",".join(real(c) for c in p))


def _list(items, per_line=REFS_PER_LINE):
    """A STEP list, a line break after every ``per_line`` items."""
    items = list(items)
    return ",\n".join(",".join(items[k:k + per_line]) for k in range(0, len(items), per_line))


def _ints(values):
    return _list("%d" % v for v in values)


def _reals(values):
    return _list((real(v) for v in values), 4)


def _curve(ent, poles, knots, degree):
    """A B_SPLINE_CURVE_WITH_KNOTS through ``poles`` (m, 3) on the flat ``knots``."""
    refs = [ent.point(p) for p in poles]
    k, m = compress_knots(knots)
    return ent.add("B_SPLINE_CURVE_WITH_KNOTS('',%d,(%s),.UNSPECIFIED.,.F.,.F.,(%s),(%s),"
                   ".UNSPECIFIED.)" % (degree, _list("#%d" % r for r in refs), _ints(m),
                                       _reals(k)))


def natural_face_step(surface, reversed_face=False, tolerance=1e-7, name="surfcomp"):
    """The STEP text (bytes) of the face bounded by ``surface``'s knot domain and the
    largest rounding of a pole (mm); see :func:`natural_face_parts`."""
    parts, rounding = natural_face_parts(surface, reversed_face, tolerance, name)
    return b"".join(parts), rounding


def natural_face_parts(surface, reversed_face=False, tolerance=1e-7, name="surfcomp"):
    """The STEP text of the face bounded by ``surface``'s knot domain, in parts (the pole
    text is most of a large file: no joined copy of it).

    Parameters
    ----------
    surface : surfcomp.core.surface.bspline.Surface
        Polynomial and clamped (each end knot ``degree + 1`` times), in mm.
    reversed_face : bool
        The face's normal opposes the surface's ``Su x Sv``.
    tolerance : float
        The edges' tolerance (mm): the file's uncertainty measure.
    name : str
        The product's name.

    Returns
    -------
    (list of bytes, float)
        The file's parts in order and the largest rounding of a pole (mm).
    """
    s = surface
    p, q = s.degree_u, s.degree_v
    P = np.asarray(s.poles, dtype=float)
    nu, nv = P.shape[:2]
    if s.weights is not None:
        raise ValueError("natural_face_step writes polynomial surfaces only")
    ku, kv = np.asarray(s.knots_u), np.asarray(s.knots_v)
    if not clamped(s):
        raise ValueError("natural_face_step writes clamped surfaces only")
    u0, u1, v0, v1 = ku[0], ku[-1], kv[0], kv[-1]
    ent = _Entities()
    same = ".F." if reversed_face else ".T."
    head = [
        "APPLICATION_PROTOCOL_DEFINITION('international standard',\n'automotive_design',2000,#2)",
        "APPLICATION_CONTEXT('core data for automotive mechanical design processes')",
        "SHAPE_DEFINITION_REPRESENTATION(#4,#10)",
        "PRODUCT_DEFINITION_SHAPE('','',#5)",
        "PRODUCT_DEFINITION('design','',#6,#9)",
        "PRODUCT_DEFINITION_FORMATION('','',#7)",
        "PRODUCT(%s,%s,'',(#8))" % (_string(name), _string(name)),
        "PRODUCT_CONTEXT('',#2,'mechanical')",
        "PRODUCT_DEFINITION_CONTEXT('part definition',#2,'design')",
    ]
    for text in head:
        ent.add(text)
    rep, context, surf = ent.reserve(), ent.reserve(), ent.reserve()
    axes = ent.add("AXIS2_PLACEMENT_3D('',#%d,#%d,#%d)" % (
        ent.point((0.0, 0.0, 0.0)), ent.add("DIRECTION('',(0.,0.,1.))"),
        ent.add("DIRECTION('',(1.,0.,0.))")))
    face, bound, loop = ent.reserve(), ent.reserve(), ent.reserve()
    shell = ent.add("OPEN_SHELL('',(#%d))" % face)
    model = ent.add("SHELL_BASED_SURFACE_MODEL('',(#%d))" % shell)
    ent.add("MANIFOLD_SURFACE_SHAPE_REPRESENTATION('',(#%d,#%d),#%d)" % (axes, model, context),
            rep)
    ent.add("ADVANCED_FACE('',(#%d),#%d,%s)" % (bound, surf, same), face)
    ent.add("FACE_BOUND('',#%d,%s)" % (loop, same), bound)
    corner = {(a, b): ent.add("VERTEX_POINT('',#%d)" % ent.point(P[a, b]))
              for a, b in ((0, 0), (-1, 0), (-1, -1), (0, -1))}
    ctx2 = ent.add("( GEOMETRIC_REPRESENTATION_CONTEXT(2)\nPARAMETRIC_REPRESENTATION_CONTEXT() "
                   "REPRESENTATION_CONTEXT('2D SPACE','') )")
    # OpenCASCADE's loop: u = u0 downwards, v = v0, u = u1, v = v1 backwards; each edge's
    # curve runs with its parameter, its PCURVE is the parameter line
    edges = [((0, 0), (0, -1), P[0, :], kv, q, (u0, 0.0), (0, 1), ".F."),
             ((0, 0), (-1, 0), P[:, 0], ku, p, (0.0, v0), (1, 0), ".T."),
             ((-1, 0), (-1, -1), P[-1, :], kv, q, (u1, 0.0), (0, 1), ".T."),
             ((0, -1), (-1, -1), P[:, -1], ku, p, (0.0, v1), (1, 0), ".F.")]
    oriented = []
    for start, end, poles, knots, degree, origin, direction, sense in edges:
        curve = _curve(ent, poles, knots, degree)
        line = ent.add("LINE('',#%d,#%d)" % (
            ent.add("CARTESIAN_POINT('',(%s))" % _reals(origin)),
            ent.add("VECTOR('',#%d,1.)" % ent.add("DIRECTION('',(%s))" % _reals(direction)))))
        pcurve = ent.add("PCURVE('',#%d,#%d)" % (
            surf, ent.add("DEFINITIONAL_REPRESENTATION('',(#%d),#%d)" % (line, ctx2))))
        along = ent.add("SURFACE_CURVE('',#%d,(#%d),.PCURVE_S1.)" % (curve, pcurve))
        edge = ent.add("EDGE_CURVE('',#%d,#%d,#%d,.T.)" % (corner[start], corner[end], along))
        oriented.append(ent.add("ORIENTED_EDGE('',*,*,#%d,%s)" % (edge, sense)))
    ent.add("EDGE_LOOP('',(%s))" % ",".join("#%d" % e for e in oriented), loop)
    mm = ent.add("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )")
    rad = ent.add("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )")
    sr = ent.add("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )")
    unc = ent.add("UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(%s),#%d,\n"
                  "'distance_accuracy_value','confusion accuracy')" % (real(tolerance), mm))
    ent.add("( GEOMETRIC_REPRESENTATION_CONTEXT(3)\nGLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#%d))\n"
            "GLOBAL_UNIT_ASSIGNED_CONTEXT((#%d,#%d,#%d))\nREPRESENTATION_CONTEXT('Context #1',"
            "'3D Context with UNIT and UNCERTAINTY') )" % (unc, mm, rad, sr), context)
    ent.add("PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(#7))")
    # the surface: its list of pole references, then the poles, row by row along u
    first = ent.reserve(nu * nv)
    top = _finite_top(P)
    whole, decimals = _layout(top)
    refs, poles = _pole_texts(P.reshape(-1, 3), first, nv, whole, decimals)
    ku_k, ku_m = compress_knots(ku)
    kv_k, kv_m = compress_knots(kv)
    surface_head = ("#%d = B_SPLINE_SURFACE_WITH_KNOTS('',%d,%d,(\n" % (surf, p, q))
    surface_tail = ("),.UNSPECIFIED.,.F.,.F.,.F.,\n(%s),\n(%s),\n(%s),\n(%s),\n"
                    ".UNSPECIFIED.);\n" % (_ints(ku_m), _ints(kv_m), _reals(ku_k), _reals(kv_k)))
    return [_header(name), *ent.lines, surface_head.encode("ascii"), *refs,
            surface_tail.encode("ascii"), *poles, b"ENDSEC;\nEND-ISO-10303-21;\n"], \
        _rounding(top, decimals)


#: pole rows formatted per block (one block per thread at a time)
BLOCK_POLES = 1 << 18


def _pole_texts(P, first, nv, whole, decimals):
    """The surface's nested list of pole references and the poles' CARTESIAN_POINT
    entities (names from ``first`` on, numbers in the :func:`_layout` ``whole``,
    ``decimals``) for the poles ``P`` (nu * nv, 3), in blocks of whole rows on the cores:
    (list of bytes, list of bytes)."""
    rows = P.shape[0] // nv
    per = max(1, BLOCK_POLES // nv)
    blocks = [slice(k, min(k + per, rows)) for k in range(0, rows, per)]
    refs, poles = [None] * len(blocks), [None] * len(blocks)

    def block(k):
        a, b = blocks[k].start * nv, blocks[k].stop * nv
        ids = np.arange(first + a, first + b)
        names = _names(ids, len(str(first + P.shape[0])))   # right-aligned by spaces
        col = np.arange(ids.size) % nv
        sep = np.where(col == nv - 1, 41, 44).astype(np.uint8)[:, None]     # ')' ends a row
        brk = np.where(col % REFS_PER_LINE == REFS_PER_LINE - 1, 10, 32).astype(np.uint8)
        brk[col == nv - 1] = 44                                            # '),' between rows
        if b == P.shape[0]:
            brk[-1] = 32
        lead = np.full((ids.size, 2), 32, dtype=np.uint8)
        lead[col == 0, 1] = 40                                             # '(' opens a row
        lead[col == 0, 0] = 10                                             # on its own line
        if a == 0:
            lead[0, 0] = 32
        refs[k] = _compact(_text(lead, names, sep, brk[:, None]))
        coords = _fixed(P[a:b].reshape(-1), whole, decimals).reshape(b - a, -1)
        w = coords.shape[1] // 3
        poles[k] = _compact(_text(names, b"=CARTESIAN_POINT('',(", coords[:, :w], b",",
                                  coords[:, w:2 * w], b",", coords[:, 2 * w:], b"));\n"))

    for_chunks(lambda sl: [block(k) for k in range(sl.start, sl.stop)], len(blocks), 1)
    return refs, poles


def _string(text):
    """A STEP string: quotes and backslashes doubled, characters beyond ASCII as Part 21's
    ``\\X2\\hhhh\\X0\\`` (``\\X4\\`` with eight digits beyond the first plane),
    control characters as ``?``."""
    out = []
    for ch in str(text):
        if ch in "'\\":
            out.append(ch * 2)
        elif ord(ch) < 32 or ord(ch) == 127:
            out.append("?")
        elif ord(ch) < 127:
            out.append(ch)
        elif ord(ch) <= 0xFFFF:
            out.append("\\X2\\%04X\\X0\\" % ord(ch))
        else:
            out.append("\\X4\\%08X\\X0\\" % ord(ch))
    return "'%s'" % "".join(out)


def _header(name):
    from .. import __version__

    stamp = datetime.datetime.now().replace(microsecond=0).isoformat()
    return ("ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('surfcomp corrected face'),'2;1');\n"
            "FILE_NAME(%s,'%s',(''),(''),'surfcomp %s','surfcomp','');\n"
            "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n"
            % (_string(name), stamp, __version__)).encode("ascii")


def write_natural_face(path, surface, reversed_face=False, tolerance=1e-7, name=None):
    """Write :func:`natural_face_step` to ``path``; the product is ``name``, by default
    the file's name without its extension."""
    name = name or os.path.splitext(os.path.basename(path))[0]
    parts, _ = natural_face_parts(surface, reversed_face, tolerance, name)
    try:
        with open(path, "wb") as fh:
            fh.writelines(parts)
    except OSError as exc:
        raise InputError("cannot write the STEP file: %s" % exc, file=path) from exc
