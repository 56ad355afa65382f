"""3-axis G-code: parse, compensate machine-axis errors, rewrite (no FreeCAD).

Every line the compensation does not change is written back byte for byte (the file is
handled as Latin-1 text, which maps every byte to one character and back); a zero error
model therefore returns the input unchanged.

What is understood
------------------
- Words ``G M N X Y Z I J K R F S T H D P Q L`` (upper or lower case, blanks between a
  letter and its number allowed), comments ``( ... )`` and ``;`` to the end of the line,
  ``%`` lines, block delete ``/`` on lines without motion.
- Motion ``G0 G1 G2 G3`` (modal; axis words alone continue the current motion), ``G80``.
- ``G17 G18 G19`` planes for arcs (I/J/K offsets of the plane's two axes; the third offset
  word is ignored, as Path writes ``K0`` on G17 arcs), arc centres by ``I J K``
  (``G91.1`` incremental, the default, or ``G90.1`` absolute) or by ``R`` (negative R: the
  arc longer than 180 degrees), helical arcs, full circles, ``P`` turns.
- ``G20 G21`` units, ``G90 G91`` distance mode (an incremental move needs every moved
  axis' absolute position to be known: the increments are rewritten as differences of
  compensated absolute positions, so no rounding error accumulates).
- Passed through unchanged: ``G4 G40 G43 G49 G54-G59.3 G61 G61.1 G64 G69 G94 G95 G96 G97
  G98 G99 G28.1 G30.1``, every M code but ``M98/M99``, ``F S T H D P Q L`` words.
- ``G53`` and ``G28/G30`` moves are left unchanged (machine coordinates / home); the axes
  they move have no known program position afterwards.

What is refused (:class:`surfcomp.errors.GCodeError` naming ``file:line:column``)
-----------------------------------------------------------------------------------
Parameters and expressions (``#1``, ``#<name>``, ``[...]``), ``O`` words (subroutines,
loops), ``M98/M99``, other axes (``A B C U V W``), ``E`` words, canned cycles
(``G73 G76 G81-G89``), cutter radius compensation (``G41 G42``), coordinate system changes
inside the program (``G10 G52 G92``, a second work offset after the first move), inverse
time feed ``G93``, probing ``G38.x``, threading ``G33``, splines ``G5``, lathe, polar and
rotation modes, any G code not listed above, an incremental move of an axis whose position
is not known, arcs whose end is not on the circle.

How moves are compensated
-------------------------
Each programmed point ``X`` (mm) is replaced by the command ``X'`` with ``X' + E(X') = X``
(:meth:`surfcomp.core.axis_errors.AxisErrorModel.compensate`).

- ``G0``: only the end point is compensated (rapid moves do not cut).
- ``G1``: a move longer than ``segment_length`` is split into equal pieces no longer than
  ``segment_length`` when the compensated points along it leave the straight line between
  its compensated ends by more than ``tolerance`` (default 0.1 um); otherwise it stays one
  move. A purely linear error model is an affine map, which keeps straight lines straight,
  so it never splits a move.
- ``G2/G3``: an arc whose compensation is below half the output resolution everywhere is
  left unchanged; otherwise it is replaced by ``G1`` segments whose chords are at most
  ``segment_length`` long and deviate at most ``arc_tolerance`` (default 1 um) from the arc,
  each end point compensated. (Keeping the arc and moving its end and centre is only exact
  for a similarity transform; a general error map turns a circle into a non-circle.)
- The first piece of a split move is written on the original line, which keeps its line
  number, feed, spindle, tool and M words and comments; the further pieces follow on new
  lines that hold only axis words (the modal ``G1`` and feed carry over). A move with a
  program stop (``M0 M1 M2 M30 M60``) on its line is not split (refused).
- Axis words are written for every axis whose compensated value differs from the value
  the machine holds, including axes the original line did not name (``X..Z..`` on a
  terse line may gain a ``Y`` word). An axis is never written before the program has
  given its position: until then the compensation assumes it at ``start`` (default the
  program zero, with a warning); pass ``start`` when the machine's start position is known.
- Output numbers: at least 4 decimals in mm and 5 in inch (``decimals``), or more if the
  input word had more; trailing zeros are dropped down to the input word's own decimals.
"""

import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..core.progress import report
from ..errors import GCodeError

AXIS_LETTERS = "XYZ"
#: default output decimals per unit system
DEFAULT_DECIMALS = {"mm": 4, "in": 5}
#: absolute and relative tolerance on the two radii of an arc (mm, fraction)
ARC_RADIUS_TOL = (0.005, 1e-3)
#: in-plane distance (mm) under which an arc's end equals its start: a full circle
FULL_CIRCLE_TOL = 1e-9

_WORD = re.compile(r"([A-Za-z])[ \t]*([+-]?(?:\d+(?:\.\d*)?|\.\d+))")
_LINE = re.compile(r"[^\n]*\n|[^\n]+$")

# codes are round(10 * number): G1 -> 10, G90.1 -> 901
_MOTION = {0: 0, 10: 1, 20: 2, 30: 3}
_PASS_G = {40, 400, 430, 490, 540, 550, 560, 570, 580, 590, 591, 592, 593, 610, 611, 640,
           690, 940, 950, 960, 970, 980, 990, 281, 301}
_STOP_M = {0, 1, 2, 30, 60}
_REFUSED_G = {
    (730, 760, 810, 820, 830, 840, 850, 860, 870, 880, 890):
        "canned cycles cannot be compensated (the plunge would need X/Y corrections along "
        "Z); let the CAM post-processor expand them into G0/G1 moves",
    (410, 420, 411, 421):
        "cutter radius compensation: the controller would offset the compensated path; "
        "output the tool-centre path (G40) instead",
    (100, 520, 920, 921, 922, 923):
        "the program changes its coordinate system, so the error model's positions no "
        "longer match the program's",
    (930,): "inverse time feed: splitting moves would change the feed rates",
    (382, 383, 384, 385): "probing moves cannot be compensated",
    (330, 331, 761): "threading cannot be compensated",
    (50, 51, 52, 53): "spline moves cannot be compensated",
    (70, 80, 150, 160, 680, 510, 500, 431, 432, 120, 130):
        "this mode (diameter/radius, polar coordinates, rotation, scaling, dynamic tool "
        "length, circle pockets) is not supported",
}
_REFUSED_G_MSG = {c: msg for codes, msg in _REFUSED_G.items() for c in codes}
#: plane code -> (first axis, second axis, linear axis)
PLANES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}


def _code_text(code):
    return "%d" % (code // 10) if code % 10 == 0 else "%d.%d" % (code // 10, code % 10)


class Word:
    """One word of a line: ``letter`` (upper case), ``value``, its ``text`` and span."""

    __slots__ = ("letter", "value", "text", "start", "end")

    def __init__(self, letter, value, text=None, start=-1, end=-1):
        self.letter = letter
        self.value = value
        self.text = text
        self.start = start
        self.end = end

    @property
    def decimals(self):
        t = self.text
        if t is None:
            return 0
        k = t.find(".")
        return 0 if k < 0 else len(t) - k - 1

    def __repr__(self):
        return "Word(%s%s)" % (self.letter, self.text if self.text is not None else self.value)


def tokenize(content, source=None, line=None):
    """Split the code of one line into words.

    Parameters
    ----------
    content : str
        The line without its line ending.

    Returns
    -------
    (list of Word, bool)
        The words in order and whether the line starts with block delete ``/``.

    Raises
    ------
    GCodeError
        Parameters, expressions, O words, malformed words, unclosed comments.
    """
    words = []
    block = False
    i, n = 0, len(content)
    while i < n:
        c = content[i]
        if c in " \t\r":
            i += 1
            continue
        if c == "(":
            j = content.find(")", i + 1)
            if j < 0:
                raise GCodeError("comment opened with '(' is not closed", file=source,
                                 line=line, column=i + 1)
            k = content.find("(", i + 1, j)
            if k >= 0:
                raise GCodeError("nested '(' inside a comment", file=source, line=line,
                                 column=k + 1)
            i = j + 1
            continue
        if c == ";":
            break
        if c == "/" and not words and not block:
            block = True
            i += 1
            continue
        if c == "%" and not words and content.strip() == "%":
            break
        m = _WORD.match(content, i)
        if m:
            letter = m.group(1).upper()
            if letter == "O":
                raise GCodeError("O word %r: subroutines and flow control (O-words) cannot be "
                                 "compensated; expand the program first"
                                 % content[i:m.end()], file=source, line=line, column=i + 1)
            text = m.group(2)
            end = m.end()
            if end < n and (content[end] == "." or content[end].isdigit()):
                raise GCodeError("malformed number in %r" % content[i:end + 1], file=source,
                                 line=line, column=i + 1)
            words.append(Word(letter, float(text), text, i, end))
            i = end
            continue
        if c == "#" or c == "[":
            raise GCodeError("LinuxCNC parameter or expression %r: parameters and expressions "
                             "cannot be compensated; expand them to plain numbers first"
                             % content[i:i + 16].strip(), file=source, line=line, column=i + 1)
        if c.isalpha():
            rest = content[i + 1:].lstrip(" \t")
            if rest[:1] in ("#", "["):
                raise GCodeError("LinuxCNC parameter or expression in %r: parameters and "
                                 "expressions cannot be compensated; expand them to plain "
                                 "numbers first" % content[i:i + 16].strip(), file=source,
                                 line=line, column=i + 1)
            if c.upper() == "O":
                raise GCodeError("O word %r: subroutines and flow control (O-words) cannot be "
                                 "compensated; expand the program first"
                                 % content[i:i + 16].strip(), file=source, line=line,
                                 column=i + 1)
            raise GCodeError("word %r without a number" % c, file=source, line=line,
                             column=i + 1)
        raise GCodeError("unexpected character %r (expected G-code words, comments in "
                         "parentheses or after ';')" % c, file=source, line=line, column=i + 1)
    return words, block


def split_lines(text):
    """Lines of ``text`` as ``(content, ending)`` pairs; ``''.join`` of them gives ``text``.

    The ending is ``'\\n'``, ``'\\r\\n'`` or ``''`` (last line without one).
    """
    out = []
    for m in _LINE.finditer(text):
        s = m.group(0)
        if s.endswith("\r\n"):
            out.append((s[:-2], "\r\n"))
        elif s.endswith("\n"):
            out.append((s[:-1], "\n"))
        else:
            out.append((s, ""))
    return out


# ----------------------------------------------------------------------- interpretation
@dataclass
class LineInfo:
    """What one line does (for rewriting it)."""

    words: list
    factor: float               # mm per program unit at this line
    absolute: bool              # G90 (True) or G91
    motion: object              # effective motion 0/1/2/3 or None
    motion_word: object         # index into words of this line's motion G word, or None
    move: int = -1              # index of its move, or -1
    unknown: tuple = ()         # axes whose program position is lost after this line
    stop: bool = False
    arc_words: tuple = ()       # indices of I J K R (and P turns) words of an arc
    axis_words: tuple = (None, None, None)  # index of the X, Y, Z word or None


@dataclass
class Program:
    """A parsed program: per-line info and the moves as arrays (mm, program coordinates).

    Attributes
    ----------
    lines : list of LineInfo or None
        One entry per line (None: nothing but comments/blank).
    kind : ndarray (m,) int
        0 rapid (G0), 1 line (G1), 2 clockwise arc (G2), 3 counter-clockwise arc (G3).
    start, end : ndarray (m, 3)
        Move start and end (mm). Axes whose position is not known yet hold the assumed
        ``start`` value.
    centre : ndarray (m, 3)
        Arc centre (mm; NaN for lines); only the plane's two coordinates matter.
    plane : ndarray (m,) int
        17, 18 or 19.
    turns : ndarray (m,) int
        Full turns of an arc (``P``; 1 when absent).
    line : ndarray (m,) int
        0-based index of the line of each move.
    known : ndarray (m, 3) bool
        Axis positions known (programmed) after each move.
    factor : ndarray (m,)
        mm per program unit at each move.
    """

    lines: list
    kind: np.ndarray
    start: np.ndarray
    end: np.ndarray
    centre: np.ndarray
    plane: np.ndarray
    turns: np.ndarray
    line: np.ndarray
    known: np.ndarray
    factor: np.ndarray
    warnings: list = field(default_factory=list)
    source: str = None
    start_known: bool = False
    start_pos: np.ndarray = None

    @property
    def n_moves(self):
        return int(self.kind.size)

    def endpoints(self, known_only=False):
        """End points of all moves (mm), optionally only where every axis is known."""
        if known_only:
            return self.end[self.known.all(axis=1)]
        return self.end


def _arc_centre_r(s, e, r, p, q, clockwise, source, line):
    """Centre of an R-format arc in the plane (p, q); negative R: the long arc."""
    dx, dy = e[p] - s[p], e[q] - s[q]
    chord = math.hypot(dx, dy)
    if chord < FULL_CIRCLE_TOL:
        raise GCodeError("R-format arc with coinciding start and end (a full circle needs "
                         "I/J/K)", file=source, line=line)
    half = chord / 2.0
    rr = abs(r)
    if rr < half - max(ARC_RADIUS_TOL[0], ARC_RADIUS_TOL[1] * rr):
        raise GCodeError("arc radius R%g is smaller than half the distance to the end point "
                         "(%.4f mm)" % (r, half), file=source, line=line)
    h = math.sqrt(max(rr * rr - half * half, 0.0))
    # unit vector to the right of the chord direction
    rx, ry = dy / chord, -dx / chord
    side = 1.0 if clockwise else -1.0
    if r < 0:
        side = -side
    c = list(s)
    c[p] = (s[p] + e[p]) / 2.0 + side * h * rx
    c[q] = (s[q] + e[q]) / 2.0 + side * h * ry
    return c


def interpret(line_words, source=None, start=None, line_numbers=None, path=False):
    """Interpret the words of every line; collect the moves.

    Parameters
    ----------
    line_words : list of (list of Word, bool)
        Per line: its words and its block-delete flag (:func:`tokenize`).
    source : str, optional
        File name (or object label) for messages.
    start : array_like (3,), optional
        Known machine position (mm, program coordinates) at the program start; default
        unknown (assumed at the program zero, axes not written until programmed).
    line_numbers : sequence of int, optional
        1-based numbers to report (default ``index + 1``).
    path : bool
        FreeCAD Path semantics: always mm (``G20`` is refused) and absolute unless
        ``G91`` is given, so no warnings about missing G20/G21/G90.

    Returns
    -------
    Program
    """
    factor = 1.0
    units_set = dist_set = False
    absolute = True
    arc_abs = False
    plane = 17
    motion = None
    wcs = None
    moved = False
    known = [start is not None] * 3
    pos = [0.0, 0.0, 0.0] if start is None else [float(v) for v in np.reshape(start, 3)]
    infos = []
    mv = {k: [] for k in ("kind", "start", "end", "centre", "plane", "turns", "line", "known",
                          "factor")}
    warnings = []
    unknown_use = {}
    for idx, (words, block) in enumerate(line_words):
        if not words:
            infos.append(None)
            continue
        ln = idx + 1 if line_numbers is None else line_numbers[idx]
        gs, ms, vals = [], [], {}
        for k, w in enumerate(words):
            L = w.letter
            if L == "G":
                gs.append((int(round(w.value * 10)), k, w))
            elif L == "M":
                ms.append((int(round(w.value)), k, w))
            elif L in "XYZIJKRFSTHDPQLN":
                if L in vals:
                    raise GCodeError("two %s words on one line" % L, file=source, line=ln,
                                     column=w.start + 1 if w.start >= 0 else None)
                vals[L] = k
            elif L in "ABCUVW":
                raise GCodeError("axis word %s: only X, Y, Z programs can be compensated "
                                 "(no rotary or secondary axes)" % L, file=source, line=ln,
                                 column=w.start + 1 if w.start >= 0 else None)
            else:
                raise GCodeError("unsupported word %s%s (expected G M N X Y Z I J K R F S T H "
                                 "D P Q L)" % (L, w.text or ""), file=source, line=ln,
                                 column=w.start + 1 if w.start >= 0 else None)
        motion_here = motion_word = None
        nonmodal = None
        for code, k, w in gs:
            col = w.start + 1 if w.start >= 0 else None
            if code in _MOTION or code == 800:
                if motion_here is not None:
                    raise GCodeError("two motion codes on one line", file=source, line=ln,
                                     column=col)
                motion_here, motion_word = code, k
            elif code in (200, 210):
                if code == 200 and path:
                    raise GCodeError("G20 (inch) in a FreeCAD Path: Path coordinates are always "
                                     "mm; the compensation cannot tell which unit is meant",
                                     file=source, line=ln)
                factor = 25.4 if code == 200 else 1.0
                units_set = True
            elif code in (900, 910):
                absolute = code == 900
                dist_set = True
            elif code in (901, 911):
                arc_abs = code == 901
            elif code in (170, 180, 190):
                plane = code // 10
            elif code in (530, 280, 300):
                nonmodal = code
            elif code in (540, 550, 560, 570, 580, 590, 591, 592, 593):
                if wcs is not None and code != wcs and moved:
                    raise GCodeError("G%s selects a second work coordinate system after moves "
                                     "in G%s: the error model's positions cannot follow; "
                                     "compensate each work offset's part separately"
                                     % (_code_text(code), _code_text(wcs)), file=source,
                                     line=ln, column=col)
                wcs = code
            elif code in _PASS_G:
                pass
            elif code in _REFUSED_G_MSG:
                raise GCodeError("G%s: %s" % (_code_text(code), _REFUSED_G_MSG[code]),
                                 file=source, line=ln, column=col)
            else:
                raise GCodeError("G%s is not supported by the axis error compensation "
                                 "(see docs/axis_errors.md for the supported codes)"
                                 % _code_text(code), file=source, line=ln, column=col)
        stop = False
        for code, _k, w in ms:
            if code in (98, 99):
                raise GCodeError("M%d: subprograms cannot be compensated; expand the program "
                                 "first" % code, file=source, line=ln,
                                 column=w.start + 1 if w.start >= 0 else None)
            if code in _STOP_M:
                stop = True
        if motion_here is not None:
            motion = None if motion_here == 800 else _MOTION[motion_here]
        axis_idx = tuple(vals.get(a) for a in AXIS_LETTERS)
        has_axis = any(k is not None for k in axis_idx)
        info = LineInfo(words, factor, absolute, motion, motion_word, stop=stop,
                        axis_words=axis_idx)
        infos.append(info)
        if nonmodal is not None:
            lost = tuple(a for a in range(3) if axis_idx[a] is not None)
            if nonmodal != 530 and not lost:
                lost = (0, 1, 2)
            for a in lost:
                known[a] = False
            info.unknown = lost
            continue
        arc_letters = [L for L in "IJKR" if L in vals]
        is_arc = motion in (2, 3)
        if arc_letters and not is_arc:
            raise GCodeError("%s word on a line without G2/G3 (arc words need an arc)"
                             % arc_letters[0], file=source, line=ln)
        if not has_axis and not (is_arc and arc_letters):
            continue
        if motion is None:
            raise GCodeError("axis words but no motion mode (G0/G1/G2/G3) is active",
                             file=source, line=ln)
        if block:
            raise GCodeError("block delete '/' on a move: the result would depend on the "
                             "operator's switch", file=source, line=ln, column=1)
        if not moved and not path:
            if not units_set:
                warnings.append("no G20/G21 before the first move (line %d): millimetres "
                                "assumed" % ln)
            if not dist_set:
                warnings.append("no G90/G91 before the first move (line %d): absolute (G90) "
                                "assumed" % ln)
        moved = True
        target = list(pos)
        for a in range(3):
            k = axis_idx[a]
            if k is None:
                continue
            v = words[k].value * factor
            if absolute:
                target[a] = v
                known[a] = True
            else:
                if not known[a]:
                    raise GCodeError("incremental (G91) %s move before any absolute %s "
                                     "position: the compensation needs absolute positions; "
                                     "program an absolute position first (or give the start "
                                     "position)" % (AXIS_LETTERS[a], AXIS_LETTERS[a]),
                                     file=source, line=ln,
                                     column=words[k].start + 1 if words[k].start >= 0 else None)
                target[a] = pos[a] + v
        centre = [math.nan, math.nan, math.nan]
        turns = 1
        if is_arc:
            p, q, _l = PLANES[plane]
            clockwise = motion == 2
            off_letters = ("IJK"[p], "IJK"[q])
            arc_idx = [vals[L] for L in "IJK" if L in vals]
            if "R" in vals:
                if any(L in vals for L in off_letters):
                    raise GCodeError("arc with both R and %s/%s" % off_letters, file=source,
                                     line=ln)
                centre = _arc_centre_r(pos, target, words[vals["R"]].value * factor, p, q,
                                       clockwise, source, ln)
                arc_idx.append(vals["R"])
            else:
                if not any(L in vals for L in off_letters):
                    raise GCodeError("arc (G%d) in the G%d plane without %s/%s or R"
                                     % (motion, plane, off_letters[0], off_letters[1]),
                                     file=source, line=ln)
                centre = list(pos)
                for a, L in ((p, off_letters[0]), (q, off_letters[1])):
                    if arc_abs:
                        if L not in vals:
                            raise GCodeError("absolute arc centre (G90.1) without %s" % L,
                                             file=source, line=ln)
                        centre[a] = words[vals[L]].value * factor
                    elif L in vals:
                        centre[a] = pos[a] + words[vals[L]].value * factor
                r0 = math.hypot(pos[p] - centre[p], pos[q] - centre[q])
                r1 = math.hypot(target[p] - centre[p], target[q] - centre[q])
                if abs(r0 - r1) > max(ARC_RADIUS_TOL[0], ARC_RADIUS_TOL[1] * max(r0, r1)):
                    raise GCodeError("arc end point is not on the circle: radius %.4f mm at "
                                     "the start, %.4f mm at the end" % (r0, r1), file=source,
                                     line=ln)
                if r0 < FULL_CIRCLE_TOL:
                    raise GCodeError("arc with zero radius", file=source, line=ln)
            if "P" in vals:
                pv = words[vals["P"]].value
                if pv < 1 or pv != int(pv):
                    raise GCodeError("arc turns P%s must be a positive whole number"
                                     % words[vals["P"]].text, file=source, line=ln)
                turns = int(pv)
                arc_idx.append(vals["P"])
            info.arc_words = tuple(sorted(arc_idx))
        if motion != 0:
            for a in range(3):
                if not known[a]:
                    first, count = unknown_use.get(a, (ln, 0))
                    unknown_use[a] = (first, count + 1)
        info.move = len(mv["kind"])
        mv["kind"].append(motion)
        mv["start"].append(pos)
        mv["end"].append(target)
        mv["centre"].append(centre)
        mv["plane"].append(plane)
        mv["turns"].append(turns)
        mv["line"].append(idx)
        mv["known"].append(tuple(known))
        mv["factor"].append(factor)
        pos = target
    for a, (first, count) in sorted(unknown_use.items()):
        warnings.append("%d cutting move(s) from line %d on ran before the program gave an "
                        "absolute %s position: the compensation assumed %s = %g mm there and "
                        "did not write %s (give the start position if it is known)"
                        % (count, first, AXIS_LETTERS[a], AXIS_LETTERS[a],
                           (np.zeros(3) if start is None else np.asarray(start))[a],
                           AXIS_LETTERS[a]))
    m = len(mv["kind"])
    return Program(
        infos,
        np.array(mv["kind"], dtype=int),
        np.array(mv["start"], dtype=float).reshape(m, 3),
        np.array(mv["end"], dtype=float).reshape(m, 3),
        np.array(mv["centre"], dtype=float).reshape(m, 3),
        np.array(mv["plane"], dtype=int),
        np.array(mv["turns"], dtype=int),
        np.array(mv["line"], dtype=int),
        np.array(mv["known"], dtype=bool).reshape(m, 3),
        np.array(mv["factor"], dtype=float),
        warnings, source, start is not None,
        np.zeros(3) if start is None else np.array(start, dtype=float).reshape(3))


def _decode(data):
    return data.decode("latin-1") if isinstance(data, (bytes, bytearray)) else data


def parse_gcode(data, source=None, start=None):
    """Parse a whole program (text or bytes).

    Returns
    -------
    (Program, list of (content, ending))
        The interpretation and the lines it refers to.
    """
    lines = split_lines(_decode(data))
    toks = [tokenize(c, source, k + 1) for k, (c, _e) in enumerate(lines)]
    return interpret(toks, source=source, start=start), lines


def read_gcode(path):
    """The bytes of a G-code file (GCodeError when it cannot be read)."""
    try:
        with open(path, "rb") as fh:
            return fh.read()
    except OSError as exc:
        raise GCodeError("cannot read the G-code file: %s" % exc.strerror, file=path) from exc


# ------------------------------------------------------------------------ the planner
def arc_points(start, end, centre, plane, clockwise, turns, n):
    """Points on an arc (helix) at ``n`` equal angle steps, the last one ``end``.

    Parameters
    ----------
    start, end, centre : array_like (3,)
        mm; only the plane's two coordinates of ``centre`` are used.
    plane : {17, 18, 19}
    clockwise : bool
        G2 (True) or G3, seen from the positive end of the plane normal.
    turns : int
        Full turns (P word; 1 = less than one turn, or one full circle if start = end).
    n : int
        Number of steps.

    Returns
    -------
    ndarray (n, 3)
        The radius changes linearly with the angle from the start radius to the end radius
        (as controllers interpolate slightly inconsistent arcs); the linear axis moves
        linearly with the angle (helix).
    """
    s, e, c = (np.asarray(v, dtype=float) for v in (start, end, centre))
    theta, r0, r1, a0 = _arc_params(s, e, c, plane, clockwise, turns)
    p, q, w = PLANES[int(plane)]
    f = np.arange(1, n + 1) / n
    ang = a0 + theta * f
    r = r0 + (r1 - r0) * f
    out = np.empty((n, 3))
    out[:, p] = c[p] + r * np.cos(ang)
    out[:, q] = c[q] + r * np.sin(ang)
    out[:, w] = s[w] + (e[w] - s[w]) * f
    out[-1] = e
    return out


def _arc_params(s, e, c, plane, clockwise, turns):
    p, q, _l = PLANES[int(plane)]
    a0 = math.atan2(s[q] - c[q], s[p] - c[p])
    a1 = math.atan2(e[q] - c[q], e[p] - c[p])
    r0 = math.hypot(s[p] - c[p], s[q] - c[q])
    r1 = math.hypot(e[p] - c[p], e[q] - c[q])
    full = math.hypot(e[p] - s[p], e[q] - s[q]) < FULL_CIRCLE_TOL
    if clockwise:
        theta = -((a0 - a1) % (2 * math.pi))
        if full or theta == 0.0:
            theta = -2 * math.pi
        theta -= 2 * math.pi * (turns - 1)
    else:
        theta = (a1 - a0) % (2 * math.pi)
        if full or theta == 0.0:
            theta = 2 * math.pi
        theta += 2 * math.pi * (turns - 1)
    return theta, r0, r1, a0


def arc_steps(start, end, centre, plane, clockwise, turns, segment_length, arc_tolerance):
    """Number of chords for an arc: each at most ``segment_length`` long and deviating at
    most ``arc_tolerance`` (mm) from the arc (sagitta ``r (1 - cos(dphi / 2))``), and at
    least 4 per full turn."""
    s, e, c = (np.asarray(v, dtype=float) for v in (start, end, centre))
    theta, r0, r1, _a0 = _arc_params(s, e, c, plane, clockwise, turns)
    _p, _q, w = PLANES[int(plane)]
    r = max(r0, r1)
    length = math.hypot(0.5 * (r0 + r1) * theta, e[w] - s[w])
    dphi = math.pi / 2
    if arc_tolerance < r:
        dphi = min(dphi, 2.0 * math.acos(1.0 - arc_tolerance / r))
    return max(1, int(math.ceil(length / segment_length - 1e-9)),
               int(math.ceil(abs(theta) / dphi - 1e-9)))


@dataclass
class MovePlan:
    """Compensated output points of every move.

    Attributes
    ----------
    offsets : ndarray (m + 1,) int
        Points of move ``j`` are ``[offsets[j], offsets[j + 1])``; the last is its end.
    nominal, compensated : ndarray (N, 3)
        Programmed points on the path (mm) and the commands that make the tool land there.
    split : ndarray (m,) bool
        The move is written as more than one piece (a split line or a converted arc).
    keep : ndarray (m,) bool
        The move is left exactly as programmed (an arc whose compensation is below
        ``still`` everywhere).
    chord_deviation : ndarray (m,)
        For G1 moves longer than the segment length: largest distance (mm) of the
        compensated intermediate points from the compensated chord (0 otherwise).
    """

    offsets: np.ndarray
    nominal: np.ndarray
    compensated: np.ndarray
    split: np.ndarray
    keep: np.ndarray
    chord_deviation: np.ndarray

    def points(self, j):
        return self.compensated[self.offsets[j]:self.offsets[j + 1]]


def plan_moves(prog, model, segment_length=2.0, tolerance=1e-4, arc_tolerance=1e-3,
               still=0.0, progress=None):
    """Sample, compensate and split the moves of a program (vectorised).

    Parameters
    ----------
    prog : Program
    model : surfcomp.core.axis_errors.AxisErrorModel
        In program coordinates (mm).
    segment_length : float
        Longest piece (mm) a G1 move or an arc chord is split into.
    tolerance : float
        A G1 move is split only if its compensated points leave the compensated chord by
        more than this (mm).
    arc_tolerance : float
        Largest chord-to-arc deviation (mm) of a converted arc.
    still : float or ndarray (m,)
        An arc whose compensation is at most this (mm) at every sample stays unchanged.

    Returns
    -------
    MovePlan
    """
    if not segment_length > 0:
        raise ValueError("segment length must be positive (got %r)" % (segment_length,))
    if not (tolerance >= 0 and arc_tolerance > 0):
        raise ValueError("tolerances must be positive")
    m = prog.n_moves
    kind = prog.kind
    report(progress, 0.0, "sampling %d moves" % m)
    nseg = np.ones(m, dtype=int)
    lines = kind == 1
    length = np.linalg.norm(prog.end - prog.start, axis=1)
    nseg[lines] = np.maximum(1, np.ceil(length[lines] / segment_length - 1e-9)).astype(int)
    arcs = np.flatnonzero(kind >= 2)
    for j in arcs:
        nseg[j] = arc_steps(prog.start[j], prog.end[j], prog.centre[j], prog.plane[j],
                            kind[j] == 2, prog.turns[j], segment_length, arc_tolerance)
    offsets = np.zeros(m + 1, dtype=int)
    np.cumsum(nseg, out=offsets[1:])
    total = int(offsets[-1])
    owner = np.repeat(np.arange(m), nseg)
    step = np.arange(total) - offsets[owner] + 1
    frac = step / nseg[owner]
    nominal = prog.start[owner] + (prog.end - prog.start)[owner] * frac[:, None]
    for j in arcs:
        nominal[offsets[j]:offsets[j + 1]] = arc_points(
            prog.start[j], prog.end[j], prog.centre[j], prog.plane[j], kind[j] == 2,
            prog.turns[j], nseg[j])
    last = offsets[1:] - 1
    nominal[last] = prog.end
    report(progress, 0.3, "compensating %d points" % total)
    comp = model.compensate(nominal)
    comp_start = model.compensate(prog.start)
    report(progress, 0.8, "splitting")
    dev = np.zeros(m)
    keep = np.zeros(m, dtype=bool)
    multi = np.flatnonzero(lines & (nseg > 1))
    if multi.size:
        sel = np.isin(owner, multi)
        own = owner[sel]
        chord = comp_start[own] + (comp[last[own]] - comp_start[own]) * frac[sel][:, None]
        d = np.linalg.norm(comp[sel] - chord, axis=1)
        np.maximum.at(dev, own, d)
    split_line = lines & (nseg > 1) & (dev > tolerance)
    still = np.broadcast_to(np.asarray(still, dtype=float), (m,))
    if arcs.size:
        moved = np.abs(comp - nominal).max(axis=1)
        worst = np.zeros(m)
        np.maximum.at(worst, owner, moved)
        worst = np.maximum(worst, np.abs(comp_start - prog.start).max(axis=1))
        keep[arcs] = worst[arcs] <= still[arcs]
    is_arc = kind >= 2
    split = split_line | (is_arc & ~keep & (nseg > 1))
    take = np.repeat(split, nseg) | np.isin(np.arange(total), last)
    new_n = np.where(split, nseg, 1)
    new_off = np.zeros(m + 1, dtype=int)
    np.cumsum(new_n, out=new_off[1:])
    report(progress, 1.0, "planned")
    return MovePlan(new_off, nominal[take], comp[take], split, keep, dev)


# --------------------------------------------------------------------------- rewriting
@dataclass
class GCodeResult:
    """The rewritten program and what was done.

    Attributes
    ----------
    data : bytes
        The output program.
    stats : dict
        ``lines_in``, ``lines_out``, ``lines_changed`` (input lines rewritten),
        ``lines_added``, ``moves``, ``moves_split`` (G1 moves split), ``arcs_converted``,
        ``points`` (output move end points).
    nominal, emitted : ndarray (N, 3)
        For every output move end point: the programmed point on the path (mm) and the
        command written (mm, after rounding). Axes not yet known hold the assumed value.
    known : ndarray (N,) bool
        Every axis of the point had a known program position.
    warnings : list of str
    """

    data: bytes
    stats: dict
    nominal: np.ndarray
    emitted: np.ndarray
    known: np.ndarray
    warnings: list
    program: Program = None

    def predicted(self, model):
        """Predicted positional error at the output points (known ones), before/after.

        ``before`` = ``|E(X)|`` for the programmed points; ``after`` = ``|X' + E(X') - X|``
        for the commands written (rounding and chord effects included).
        """
        from ..core.axis_errors import error_stats
        k = self.known
        before = model.error(self.nominal[k])
        after = model.actual(self.emitted[k]) - self.nominal[k]
        return {"before": error_stats(before), "after": error_stats(after),
                "points_unknown_axes": int((~k).sum())}


def _fmt(v, d, keep):
    """``v`` with ``d`` decimals; trailing zeros dropped down to ``keep`` (>= 1) decimals."""
    s = "%.*f" % (d, v)
    if d > keep:
        cut = len(s)
        stop = len(s) - (d - keep)
        while cut > stop and s[cut - 1] == "0":
            cut -= 1
        s = s[:cut]
    if s.startswith("-") and float(s) == 0.0:
        s = s[1:]
    return s


def _gap_style(content, a, b):
    """``' '`` or ``''`` when only blanks separate words ``a`` and ``b``, else None."""
    gap = content[a.end:b.start]
    if gap.strip(" \t") != "":
        return None
    return " " if gap else ""


def _word_sep(content, words, default):
    """Separator style of a line: (between any words, between axis words)."""
    general = axis = None
    ordered = sorted(words, key=lambda w: w.start)
    for a, b in zip(ordered, ordered[1:]):
        st = _gap_style(content, a, b)
        if st is None:
            continue
        if general is None:
            general = st
        if axis is None and a.letter in AXIS_LETTERS and b.letter in AXIS_LETTERS:
            axis = st
    general = default if general is None else general
    return general, general if axis is None else axis


def _file_sep(lines, prog):
    """The separator most multi-word lines of the file use (for one-word lines)."""
    spaced = terse = 0
    for (content, _e), info in zip(lines, prog.lines):
        if info is None or len(info.words) < 2:
            continue
        st = _gap_style(content, info.words[0], info.words[1])
        if st == " ":
            spaced += 1
        elif st == "":
            terse += 1
        if spaced + terse >= 200:
            break
    return "" if terse > spaced else " "


def compensate_gcode(data, model, segment_length=2.0, tolerance=1e-4, arc_tolerance=1e-3,
                     decimals=None, start=None, source=None, progress=None):
    """Compensate a G-code program for a machine's axis errors.

    Parameters
    ----------
    data : bytes or str
        The program.
    model : surfcomp.core.axis_errors.AxisErrorModel
        Error model in program coordinates (mm).
    segment_length : float
        Longest piece (mm) of a split G1 move or converted arc.
    tolerance : float
        Chord tolerance (mm) deciding whether a long G1 move is split.
    arc_tolerance : float
        Chord-to-arc deviation (mm) of converted arcs.
    decimals : int, optional
        Least decimals written (default 4 in mm, 5 in inch).
    start : array_like (3,), optional
        Known start position (mm, program coordinates).
    source : str, optional
        File name for messages.

    Returns
    -------
    GCodeResult
        ``data`` is the input unchanged, byte for byte, when the model is zero.

    Raises
    ------
    GCodeError
        For anything the compensation cannot handle correctly (module docstring).
    """
    raw = data
    text = _decode(data)
    report(progress, 0.0, "parsing")
    prog, lines = parse_gcode(text, source=source, start=start)
    dmin_mm = DEFAULT_DECIMALS["mm"] if decimals is None else int(decimals)
    dmin_in = DEFAULT_DECIMALS["in"] if decimals is None else int(decimals)
    still = np.where(prog.factor == 1.0, 0.5 * 10.0 ** -dmin_mm,
                     0.5 * 10.0 ** -dmin_in * prog.factor) * 0.999
    plan = plan_moves(prog, model, segment_length, tolerance, arc_tolerance, still,
                      progress=None)
    report(progress, 0.5, "writing")
    out, stats, nominal, emitted, known = _emit(lines, prog, plan, dmin_mm, dmin_in, source)
    text_out = "".join(out)
    if text_out == text:
        data_out = bytes(raw) if isinstance(raw, (bytes, bytearray)) else text.encode("latin-1")
    else:
        data_out = text_out.encode("latin-1")
    report(progress, 1.0, "done")
    return GCodeResult(data_out, stats, nominal, emitted, known, list(prog.warnings), prog)


def _emit(lines, prog, plan, dmin_mm, dmin_in, source):
    eol_default = next((e for _c, e in lines if e), "\n")
    file_sep = _file_sep(lines, prog)
    out = []
    out_val = [None, None, None]     # value the machine holds, program units
    if prog.start_known:
        out_val = [float(v) for v in prog.start_pos]
    factor_prev = 1.0
    last_dec = [3, 3, 3]
    out_motion = None
    n_changed = n_added = n_split = n_conv = 0
    nominal, emitted, known_pts = [], [], []
    known_l = prog.known.tolist()
    kind_l = prog.kind.tolist()
    end_l = prog.end.tolist()
    comp_l = plan.compensated.tolist()
    nom_l = plan.nominal.tolist()
    off_l = plan.offsets.tolist()
    keep_l = plan.keep.tolist()
    split_l = plan.split.tolist()
    for idx, (content, eol) in enumerate(lines):
        info = prog.lines[idx]
        if info is None:
            out.append(content + eol)
            continue
        f = info.factor
        if f != factor_prev:
            out_val = [None if v is None else v * factor_prev / f for v in out_val]
            factor_prev = f
        dmin = dmin_mm if f == 1.0 else dmin_in
        words = info.words
        for a in range(3):
            k = info.axis_words[a]
            if k is not None:
                last_dec[a] = max(words[k].decimals, 1)
        if info.unknown:
            for a in info.unknown:
                out_val[a] = None
            if info.motion_word is not None:
                out_motion = info.motion
            out.append(content + eol)
            continue
        j = info.move
        if j < 0:
            if info.motion_word is not None:
                out_motion = info.motion
            out.append(content + eol)
            continue
        ln = idx + 1
        known = known_l[j]
        all_known = known[0] and known[1] and known[2]
        pts = comp_l[off_l[j]:off_l[j + 1]]
        noms = nom_l[off_l[j]:off_l[j + 1]]
        kind = kind_l[j]
        edits = []
        sep, asep = _word_sep(content, words, file_sep)
        if keep_l[j]:
            # arc left as programmed (compensation below the output resolution)
            for a in range(3):
                k = info.axis_words[a]
                if k is not None:
                    v = words[k].value
                    out_val[a] = v if info.absolute else out_val[a] + v
            _restore_motion(content, words, info, out_motion, sep, edits)
            out_motion = info.motion
            nominal.append(end_l[j])
            emitted.append(end_l[j])
            known_pts.append(all_known)
            if edits:
                n_changed += 1
            out.append(_apply(content, edits) + eol)
            continue
        if split_l[j] and info.stop:
            raise GCodeError("a move with a program stop (M0/M1/M2/M30/M60) on its line must "
                             "be split for the compensation; put the stop on its own line",
                             file=source, line=ln)
        convert = kind >= 2
        # ---- first point: on the original line
        vals = [v / f for v in pts[0]]
        first_words = {}
        for a in range(3):
            if not known[a]:
                continue
            k = info.axis_words[a]
            d = max(dmin, words[k].decimals if k is not None else last_dec[a])
            keepd = words[k].decimals if k is not None else last_dec[a]
            s_abs = _fmt(vals[a], d, max(keepd, 1))
            v_abs = float(s_abs)
            if info.absolute:
                if k is not None:
                    if v_abs != float("%.*f" % (d, words[k].value)):
                        first_words[a] = (k, s_abs)
                    out_val[a] = v_abs if v_abs != float("%.*f" % (d, words[k].value)) \
                        else words[k].value
                elif out_val[a] is None or float("%.*f" % (d, out_val[a])) != v_abs:
                    first_words[a] = (None, s_abs)
                    out_val[a] = v_abs
            else:
                inc = _fmt(v_abs - out_val[a], d, max(keepd, 1))
                if k is not None:
                    if float(inc) != float("%.*f" % (d, words[k].value)):
                        first_words[a] = (k, inc)
                        out_val[a] += float(inc)
                    else:
                        out_val[a] += words[k].value
                elif float(inc) != 0.0:
                    first_words[a] = (None, inc)
                    out_val[a] += float(inc)
        for _a, (k, s) in first_words.items():
            if k is not None:
                w = words[k]
                edits.append((w.end - len(w.text), w.end, s))
        _add_words(content, words, info, [(a, s) for a, (k, s) in sorted(first_words.items())
                                          if k is None], asep, edits)
        if convert and split_l[j]:
            _convert_arc(content, words, info, sep, edits, out_motion)
            out_motion = 1
            n_conv += 1
        else:
            _restore_motion(content, words, info, out_motion, sep, edits)
            out_motion = info.motion
        nominal.append(noms[0])
        emitted.append(_abs_mm(out_val, known, pts[0], f))
        known_pts.append(all_known)
        if edits:
            n_changed += 1
        out.append(_apply(content, edits))
        # ---- further pieces: new lines with axis words only
        extra = []
        for p_idx in range(1, len(pts)):
            vals = [v / f for v in pts[p_idx]]
            ws = []
            for a in range(3):
                if not known[a]:
                    continue
                k = info.axis_words[a]
                d = max(dmin, words[k].decimals if k is not None else last_dec[a])
                keepd = max(words[k].decimals if k is not None else last_dec[a], 1)
                s_abs = _fmt(vals[a], d, keepd)
                v_abs = float(s_abs)
                if info.absolute:
                    if out_val[a] is None or float("%.*f" % (d, out_val[a])) != v_abs:
                        ws.append(AXIS_LETTERS[a] + s_abs)
                        out_val[a] = v_abs
                else:
                    inc = _fmt(v_abs - out_val[a], d, keepd)
                    if float(inc) != 0.0:
                        ws.append(AXIS_LETTERS[a] + inc)
                        out_val[a] += float(inc)
            if ws:
                extra.append(asep.join(ws))
                nominal.append(noms[p_idx])
                emitted.append(_abs_mm(out_val, known, pts[p_idx], f))
                known_pts.append(all_known)
        if split_l[j] and kind == 1:
            n_split += 1
        if extra:
            n_added += len(extra)
            mid = eol if eol else eol_default
            out.append(mid + mid.join(extra[:-1]) + (mid if len(extra) > 1 else "")
                       + extra[-1] + eol)
        else:
            out.append(eol)
    stats = {"lines_in": len(lines), "lines_out": len(lines) + n_added,
             "lines_changed": n_changed, "lines_added": n_added, "moves": prog.n_moves,
             "moves_split": n_split, "arcs_converted": n_conv, "points": len(nominal)}
    return (out, stats, np.array(nominal, dtype=float).reshape(-1, 3),
            np.array(emitted, dtype=float).reshape(-1, 3), np.array(known_pts, dtype=bool))


def _abs_mm(out_val, known, comp_mm, f):
    """The commanded point after a line (mm): written values, compensation where unknown."""
    return [out_val[a] * f if (known[a] and out_val[a] is not None) else comp_mm[a]
            for a in range(3)]


def _apply(content, edits):
    if not edits:
        return content
    s = content
    for start, end, rep in sorted(edits, key=lambda e: (e[0], e[1]), reverse=True):
        s = s[:start] + rep + s[end:]
    return s


def _insert_pos(content, words, info):
    """Where to insert a motion word: before the first word that is not N."""
    for w in words:
        if w.letter != "N":
            return w.start
    return len(content.rstrip())


def _add_words(content, words, info, adds, sep, edits):
    """Insert new axis words next to the line's axis words (in X, Y, Z order)."""
    after_anchor, before_anchor = {}, {}
    for a, s in adds:
        word = AXIS_LETTERS[a] + s
        before = [info.axis_words[b] for b in range(a - 1, -1, -1)
                  if info.axis_words[b] is not None]
        after = [info.axis_words[b] for b in range(a + 1, 3) if info.axis_words[b] is not None]
        if before:
            after_anchor.setdefault(words[before[0]].end, []).append(word)
        elif after:
            before_anchor.setdefault(words[after[0]].start, []).append(word)
        else:
            # no axis word at all: after the last word of the line
            after_anchor.setdefault(max(w.end for w in words), []).append(word)
    for pos, ws in after_anchor.items():
        edits.append((pos, pos, "".join(sep + w for w in ws)))
    for pos, ws in before_anchor.items():
        edits.append((pos, pos, "".join(w + sep for w in ws)))


def _motion_text(w, code):
    """``G2`` -> ``G1``, ``G02`` -> ``G01``, ``g3`` -> ``g1`` (the word's own style)."""
    digits = w.text.lstrip("+")
    width = len(digits.split(".")[0])
    return "%0*d" % (width, code)


def _convert_arc(content, words, info, sep, edits, out_motion):
    """Turn an arc line into the first G1 piece: motion word G1, arc words removed."""
    if info.motion_word is not None:
        w = words[info.motion_word]
        edits.append((w.end - len(w.text), w.end, _motion_text(w, 1)))
    elif out_motion != 1:
        pos = _insert_pos(content, words, info)
        edits.append((pos, pos, "G1" + sep))
    for k in info.arc_words:
        w = words[k]
        start = w.start
        # take the blanks before the word with it
        while start > 0 and content[start - 1] in " \t":
            start -= 1
        if start == 0:
            end = w.end
            while end < len(content) and content[end] in " \t":
                end += 1
            edits.append((w.start, end, ""))
        else:
            edits.append((start, w.end, ""))


def _restore_motion(content, words, info, out_motion, sep, edits):
    """A line that relies on the modal motion gets it written when the output's modal
    motion differs (after an arc was turned into G1 pieces)."""
    if info.motion_word is None and info.motion is not None and out_motion != info.motion \
            and out_motion is not None:
        pos = _insert_pos(content, words, info)
        edits.append((pos, pos, "G%d" % info.motion + sep))


# ------------------------------------------------------------- command lists (FreeCAD Path)
_NAME = re.compile(r"^\s*([A-Za-z])\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+))\s*$")


def command_words(name, params, source=None, index=None):
    """Words of one FreeCAD Path command: its name (``G1``, ``M6``) and its parameters.

    A name starting with ``(`` (a comment) or empty gives no words.
    """
    name = (name or "").strip()
    if not name or name.startswith("(") or name.startswith(";"):
        return []
    m = _NAME.match(name)
    if not m:
        raise GCodeError("command %r is not understood (expected a G or M code, or a "
                         "comment in parentheses)" % name, file=source, line=index)
    words = [Word(m.group(1).upper(), float(m.group(2)), m.group(2))]
    for key, value in params.items():
        letter = str(key).strip().upper()
        if len(letter) != 1 or not letter.isalpha():
            raise GCodeError("command %r has a parameter %r that is not a G-code word"
                             % (name, key), file=source, line=index)
        words.append(Word(letter, float(value)))
    return words


@dataclass
class CommandsResult:
    """Compensated command list.

    Attributes
    ----------
    commands : list
        Per output command either an ``int`` (index of an input command kept unchanged)
        or a ``(name, parameters)`` pair.
    stats, nominal, emitted, known, warnings
        As in :class:`GCodeResult` (``lines_*`` count commands).
    """

    commands: list
    stats: dict
    nominal: np.ndarray
    emitted: np.ndarray
    known: np.ndarray
    warnings: list
    program: Program = None

    predicted = GCodeResult.predicted


def compensate_commands(commands, model, segment_length=2.0, tolerance=1e-4,
                        arc_tolerance=1e-3, start=None, source=None):
    """Compensate a FreeCAD-Path-style command list (absolute or incremental, always mm).

    Parameters
    ----------
    commands : sequence of (str, dict)
        ``(Name, Parameters)`` of every command, e.g. ``('G1', {'X': 1.0, 'F': 5.0})``.
    model : surfcomp.core.axis_errors.AxisErrorModel
        In the commands' coordinates (mm).
    segment_length, tolerance, arc_tolerance, start, source
        As in :func:`compensate_gcode`.

    Returns
    -------
    CommandsResult
        Moves are rewritten with every parameter they had (feed ``F`` included, on every
        piece of a split move); arcs that need compensation become ``G1`` pieces; every
        other command is kept. A zero model keeps every command.
    """
    line_words = [(command_words(n, p, source, k + 1), False)
                  for k, (n, p) in enumerate(commands)]
    prog = interpret(line_words, source=source, start=start, path=True)
    plan = plan_moves(prog, model, segment_length, tolerance, arc_tolerance, still=0.0)
    out = []
    out_val = [None, None, None] if start is None else [float(v) for v in prog.start_pos]
    nominal, emitted, known_pts = [], [], []
    n_changed = n_added = n_split = n_conv = 0
    comp_l = plan.compensated.tolist()
    nom_l = plan.nominal.tolist()
    off_l = plan.offsets.tolist()
    for idx, (name, params) in enumerate(commands):
        info = prog.lines[idx]
        if info is None:
            out.append(idx)
            continue
        if info.unknown:
            for a in info.unknown:
                out_val[a] = None
            out.append(idx)
            continue
        j = info.move
        if j < 0:
            out.append(idx)
            continue
        known = prog.known[j].tolist()
        all_known = all(known)
        pts = comp_l[off_l[j]:off_l[j + 1]]
        noms = nom_l[off_l[j]:off_l[j + 1]]
        if plan.keep[j]:
            for a in range(3):
                k = info.axis_words[a]
                if k is not None:
                    v = info.words[k].value
                    out_val[a] = v if info.absolute else out_val[a] + v
            out.append(idx)
            nominal.append(prog.end[j].tolist())
            emitted.append(prog.end[j].tolist())
            known_pts.append(all_known)
            continue
        convert = prog.kind[j] >= 2
        base = dict(params)
        if convert:
            for key in list(base):
                if str(key).upper() in "IJKRP":
                    del base[key]
        keys = {str(k).upper(): k for k in base}
        pieces = []
        for p_idx, pt in enumerate(pts):
            par = dict(base) if p_idx == 0 else {}
            if p_idx > 0 and "F" in keys:
                par[keys["F"]] = base[keys["F"]]
            for a in range(3):
                if not known[a]:
                    continue
                L = AXIS_LETTERS[a]
                present = info.axis_words[a] is not None and p_idx == 0
                if info.absolute:
                    if present or out_val[a] is None or out_val[a] != pt[a]:
                        par[keys.get(L, L)] = pt[a]
                    out_val[a] = pt[a]
                else:
                    inc = pt[a] - out_val[a]
                    if present or inc != 0.0:
                        par[keys.get(L, L)] = inc
                    out_val[a] = pt[a]
            pieces.append(par)
            nominal.append(noms[p_idx])
            emitted.append([out_val[a] if (known[a] and out_val[a] is not None) else pt[a]
                            for a in range(3)])
            known_pts.append(all_known)
        if len(pieces) == 1 and not convert and pieces[0] == dict(params):
            out.append(idx)
            continue
        new_name = "G1" if convert else name
        out.append((new_name, pieces[0]))
        out.extend(("G1" if convert else name, par) for par in pieces[1:])
        n_changed += 1
        n_added += len(pieces) - 1
        if convert:
            n_conv += 1
        elif len(pieces) > 1:
            n_split += 1
    stats = {"lines_in": len(commands), "lines_out": len(out), "lines_changed": n_changed,
             "lines_added": n_added, "moves": prog.n_moves, "moves_split": n_split,
             "arcs_converted": n_conv, "points": len(nominal)}
    return CommandsResult(out, stats, np.array(nominal, dtype=float).reshape(-1, 3),
                          np.array(emitted, dtype=float).reshape(-1, 3),
                          np.array(known_pts, dtype=bool), list(prog.warnings), prog)
