# SPDX-License-Identifier: LGPL-2.1-or-later
"""Interpreter of 3-axis G-code: modal state, positions and the moves of a program.

Turns the words of every line (:mod:`.lexer`) into a :class:`Program`: what each line does
(for rewriting it) and the moves as arrays in mm. What is understood and what is refused:
see :mod:`surfcomp.io.gcode`.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from ...core.axis.arcs import PLANES, centre_from_radius, check_centre
from ...errors import GCodeError, InputError
from ..files import clip
from .lexer import AXIS_LETTERS, decode, split_lines, tokenize

#: largest position, arc radius or centre (mm) accepted: 1 km, beyond any machine's travel
MAX_POSITION = 1e6
#: most full turns of one arc (P word)
MAX_TURNS = 1000000

# codes are round(10 * number): G1 -> 10, G90.1 -> 901
_MOTION = {0: 0, 10: 1, 20: 2, 30: 3}
_PASS_G = {40, 400, 430, 490, 540, 550, 560, 570, 580, 590, 591, 592, 593, 610, 611, 640,
           690, 940, 950, 960, 970, 980, 990, 281, 301}
_STOP_M = {0, 1, 2, 30, 60}
#: the work offset a program that names none runs in (LinuxCNC and Fanuc at power-up)
_POWER_UP_WCS = 540
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


def _code_text(code):
    return "%d" % (code // 10) if code % 10 == 0 else "%d.%d" % (code // 10, code % 10)


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
    absolute : ndarray (m,) bool
        The move was programmed in absolute mode (G90).
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
    absolute: np.ndarray = None

    @property
    def n_moves(self):
        return int(self.kind.size)

    def is_empty(self):
        """No line has a word: nothing but blank lines, comments and ``%`` lines."""
        return all(info is None for info in self.lines)

    def endpoints(self, known_only=False):
        """End points of all moves (mm), optionally only where every axis is known."""
        if known_only:
            return self.end[self.known.all(axis=1)]
        return self.end


def _arc_geometry(fn, source, line, *args):
    """``fn(*args)`` of :mod:`surfcomp.core.axis.arcs`, its refusal located at ``source:line``."""
    try:
        return fn(*args)
    except InputError as exc:
        raise GCodeError(exc.message, file=source, line=line) from None


def _column(w):
    return w.start + 1 if w.start >= 0 else None


def _classify(words, source, ln):
    """Split a line's words: G codes and M codes as ``(code, index, word)``, and the index
    of every other word by letter (one word per letter)."""
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
                                 column=_column(w))
            vals[L] = k
        elif L in "ABCUVW":
            raise GCodeError("axis word %s: only X, Y, Z programs can be compensated "
                             "(no rotary or secondary axes)" % L, file=source, line=ln,
                             column=_column(w))
        else:
            raise GCodeError("unsupported word %s%s (expected G M N X Y Z I J K R F S T H "
                             "D P Q L)" % (L, clip(w.text or "")), file=source, line=ln,
                             column=_column(w))
    return gs, ms, vals


def _program_stop(ms, source, ln):
    """Whether the M codes of a line stop the program; subprogram calls are refused."""
    stop = False
    for code, _k, w in ms:
        if code in (98, 99):
            raise GCodeError("M%d: subprograms cannot be compensated; expand the program "
                             "first" % code, file=source, line=ln, column=_column(w))
        if code in _STOP_M:
            stop = True
    return stop


class _LineCodes:
    """What the G codes of one line asked for (besides the modal state they set)."""

    __slots__ = ("motion", "motion_word", "nonmodal")

    def __init__(self):
        self.motion = None          # motion code of the line (0, 10, 20, 30, 800) or None
        self.motion_word = None     # its index in the line's words
        self.nonmodal = None        # G53, G28 or G30


#: G code -> name of the :class:`_Interpreter` method handling its group
_G_HANDLERS = {}
for _name, _codes in (("_g_pass", _PASS_G), ("_g_motion", (0, 10, 20, 30, 800)),
                      ("_g_units", (200, 210)), ("_g_distance", (900, 910)),
                      ("_g_arc_distance", (901, 911)), ("_g_plane", (170, 180, 190)),
                      ("_g_nonmodal", (530, 280, 300)),
                      ("_g_wcs", (540, 550, 560, 570, 580, 590, 591, 592, 593))):
    _G_HANDLERS.update(dict.fromkeys(_codes, _name))


class _Interpreter:
    """Modal state while walking a program, and the moves collected so far."""

    def __init__(self, source, start, path):
        self.source = source
        self.start = start
        self.path = path
        self.factor = 1.0
        self.units_set = self.dist_set = False
        self.absolute = True
        self.arc_abs = False
        self.plane = 17
        self.motion = None
        self.wcs = None
        self.moved = False
        self.known = [start is not None] * 3
        self.pos = ([0.0, 0.0, 0.0] if start is None
                    else [float(v) for v in np.reshape(start, 3)])
        self.moves = {k: [] for k in _MOVE_FIELDS}
        self.chunks = []                # the moves before those in self.moves, as arrays
        self.chunk_moves = 0
        self.warnings = []
        self.unknown_use = {}

    # ------------------------------------------------------------------ G code groups
    def _g_pass(self, code, k, w, ln, cur):
        pass

    def _g_motion(self, code, k, w, ln, cur):
        if cur.motion is not None:
            raise GCodeError("two motion codes on one line", file=self.source, line=ln,
                             column=_column(w))
        cur.motion, cur.motion_word = code, k

    def _g_units(self, code, k, w, ln, cur):
        if code == 200 and self.path:
            raise GCodeError("G20 (inch) in a FreeCAD Path: Path coordinates are always "
                             "mm; the compensation cannot tell which unit is meant",
                             file=self.source, line=ln)
        self.factor = 25.4 if code == 200 else 1.0
        self.units_set = True

    def _g_distance(self, code, k, w, ln, cur):
        self.absolute = code == 900
        self.dist_set = True

    def _g_arc_distance(self, code, k, w, ln, cur):
        self.arc_abs = code == 901

    def _g_plane(self, code, k, w, ln, cur):
        self.plane = code // 10

    def _g_nonmodal(self, code, k, w, ln, cur):
        cur.nonmodal = code

    def _g_wcs(self, code, k, w, ln, cur):
        # a program naming none runs in the controller's active offset: G54 at power-up
        active = _POWER_UP_WCS if self.wcs is None else self.wcs
        if self.moved and code != active:
            raise GCodeError("G%s selects a second work coordinate system after moves in "
                             "G%s%s: the error model's positions cannot follow; compensate "
                             "each work offset's part separately"
                             % (_code_text(code), _code_text(active),
                                "" if self.wcs is not None else
                                " (none was named before the first move, so the moves ran "
                                "in the controller's active one, G54 at power-up)"),
                             file=self.source, line=ln, column=_column(w))
        if self.moved and self.wcs is None and not self.path:
            self.warnings.append("G54 on line %d after moves with no work offset named: the "
                                 "moves before it were taken to be in G54 (the power-up "
                                 "default); if the machine may be in another work offset, "
                                 "name G54 before the first move" % ln)
        self.wcs = code

    def _g_codes(self, gs, ln):
        cur = _LineCodes()
        for code, k, w in gs:
            handler = _G_HANDLERS.get(code)
            if handler is not None:
                getattr(self, handler)(code, k, w, ln, cur)
            elif code in _REFUSED_G_MSG:
                raise GCodeError("G%s: %s" % (_code_text(code), _REFUSED_G_MSG[code]),
                                 file=self.source, line=ln, column=_column(w))
            else:
                raise GCodeError("G%s is not supported by the axis error compensation "
                                 "(see docs/axis_errors.md for the supported codes)"
                                 % _code_text(code), file=self.source, line=ln,
                                 column=_column(w))
        return cur

    # --------------------------------------------------------------------------- lines
    def line(self, idx, words, block, ln):
        """Interpret one line with words; return its :class:`LineInfo`."""
        gs, ms, vals = _classify(words, self.source, ln)
        cur = self._g_codes(gs, ln)
        stop = _program_stop(ms, self.source, ln)
        if cur.motion is not None:
            self.motion = None if cur.motion == 800 else _MOTION[cur.motion]
        axis_idx = (vals.get("X"), vals.get("Y"), vals.get("Z"))
        info = LineInfo(words, self.factor, self.absolute, self.motion, cur.motion_word,
                        stop=stop, axis_words=axis_idx)
        if cur.nonmodal is not None:
            # G53 moves in machine coordinates, G28/G30 go home: positions are lost
            lost = tuple(a for a in range(3) if axis_idx[a] is not None)
            if cur.nonmodal != 530 and not lost:
                lost = (0, 1, 2)
            for a in lost:
                self.known[a] = False
            info.unknown = lost
        else:
            self._line_move(idx, ln, words, vals, block, info)
        return info

    def _line_move(self, idx, ln, words, vals, block, info):
        """The move of a line, if it has one."""
        arc_letters = [L for L in "IJKR" if L in vals]
        is_arc = self.motion in (2, 3)
        if arc_letters and not is_arc:
            raise GCodeError("%s word on a line without G2/G3 (arc words need an arc)"
                             % arc_letters[0], file=self.source, line=ln)
        if info.axis_words == (None, None, None) and not (is_arc and arc_letters):
            return
        if self.motion is None:
            raise GCodeError("axis words but no motion mode (G0/G1/G2/G3) is active",
                             file=self.source, line=ln)
        if block:
            raise GCodeError("block delete '/' on a move: the result would depend on the "
                             "operator's switch", file=self.source, line=ln, column=1)
        self._first_move(ln)
        target = self._target(words, info.axis_words, ln)
        centre, turns = [math.nan, math.nan, math.nan], 1
        if is_arc:
            centre, turns, info.arc_words = self._arc(words, vals, target, ln)
        if self.motion != 0:
            for a in range(3):
                if not self.known[a]:
                    first, count = self.unknown_use.get(a, (ln, 0))
                    self.unknown_use[a] = (first, count + 1)
        mv = self.moves
        info.move = self.chunk_moves + len(mv["kind"])
        mv["kind"].append(self.motion)
        mv["start"].append(self.pos)
        mv["end"].append(target)
        mv["centre"].append(centre)
        mv["plane"].append(self.plane)
        mv["turns"].append(turns)
        mv["line"].append(idx)
        mv["known"].append(tuple(self.known))
        mv["factor"].append(self.factor)
        mv["absolute"].append(self.absolute)
        self.pos = target

    def _first_move(self, ln):
        """Warn about modes the program left to the controller's defaults."""
        if not self.moved and not self.path:
            if not self.units_set:
                self.warnings.append("no G20/G21 before the first move (line %d): millimetres "
                                     "assumed" % ln)
            if not self.dist_set:
                self.warnings.append("no G90/G91 before the first move (line %d): absolute "
                                     "(G90) assumed" % ln)
        self.moved = True

    def _target(self, words, axis_idx, ln):
        """End point (mm) of the move; marks the programmed axes known."""
        target = list(self.pos)
        for a in range(3):
            k = axis_idx[a]
            if k is None:
                continue
            v = words[k].value * self.factor
            if self.absolute:
                target[a] = v
                self.known[a] = True
            elif not self.known[a]:
                raise GCodeError("incremental (G91) %s move before any absolute %s position: "
                                 "the compensation needs absolute positions; program an "
                                 "absolute position first (or give the start position)"
                                 % (AXIS_LETTERS[a], AXIS_LETTERS[a]), file=self.source,
                                 line=ln, column=_column(words[k]))
            else:
                target[a] = self.pos[a] + v
            self._check_size(target[a], "position", words[k], ln)
        return target

    def _check_size(self, value, what, word, ln):
        """Refuse a position, radius or centre (mm) beyond :data:`MAX_POSITION`."""
        if not abs(value) <= MAX_POSITION:
            raise GCodeError("%s%s: %s %.6g mm is beyond any machine's travel (expected at "
                             "most %g mm)" % (word.letter, clip(word.text or ""), what, value,
                                              MAX_POSITION), file=self.source, line=ln,
                             column=_column(word))

    def _arc(self, words, vals, target, ln):
        """Centre (mm), turns and the arc words (I J K R P) of an arc move."""
        p, q, _l = PLANES[self.plane]
        off_letters = ("IJK"[p], "IJK"[q])
        arc_idx = [vals[L] for L in "IJK" if L in vals]
        if "R" in vals:
            if any(L in vals for L in off_letters):
                raise GCodeError("arc with both R and %s/%s" % off_letters, file=self.source,
                                 line=ln)
            radius = words[vals["R"]].value * self.factor
            self._check_size(radius, "arc radius", words[vals["R"]], ln)
            centre = _arc_geometry(centre_from_radius, self.source, ln, self.pos, target,
                                   radius, self.plane, self.motion == 2)
            arc_idx.append(vals["R"])
        else:
            centre = self._centre_ijk(words, vals, off_letters, (p, q), target, ln)
        turns = 1
        if "P" in vals:
            pv = words[vals["P"]].value
            if pv < 1 or pv != int(pv):
                raise GCodeError("arc turns P%s must be a positive whole number"
                                 % clip(words[vals["P"]].text), file=self.source, line=ln)
            if pv > MAX_TURNS:
                raise GCodeError("arc turns P%s: expected at most %d turns"
                                 % (clip(words[vals["P"]].text), MAX_TURNS), file=self.source,
                                 line=ln)
            turns = int(pv)
            arc_idx.append(vals["P"])
        return centre, turns, tuple(sorted(arc_idx))

    def _centre_ijk(self, words, vals, off_letters, axes, target, ln):
        """Centre of an arc given by its offsets (G91.1) or coordinates (G90.1)."""
        if not any(L in vals for L in off_letters):
            raise GCodeError("arc (G%d) in the G%d plane without %s/%s or R"
                             % (self.motion, self.plane, off_letters[0], off_letters[1]),
                             file=self.source, line=ln)
        centre = list(self.pos)
        for a, L in zip(axes, off_letters):
            if self.arc_abs:
                if L not in vals:
                    raise GCodeError("absolute arc centre (G90.1) without %s" % L,
                                     file=self.source, line=ln)
                centre[a] = words[vals[L]].value * self.factor
            elif L in vals:
                centre[a] = self.pos[a] + words[vals[L]].value * self.factor
            if L in vals:
                self._check_size(centre[a], "arc centre", words[vals[L]], ln)
        _arc_geometry(check_centre, self.source, ln, self.pos, target, centre, self.plane)
        return centre

    # -------------------------------------------------------------------------- result
    def lines(self, line_words, base=0, line_numbers=None):
        """Interpret the words of consecutive lines, the first being line index ``base``;
        their :class:`LineInfo` (None for lines without words)."""
        infos = []
        for k, (words, block) in enumerate(line_words):
            if not words:
                infos.append(None)
                continue
            idx = base + k
            ln = idx + 1 if line_numbers is None else line_numbers[k]
            infos.append(self.line(idx, words, block, ln))
        return infos

    def unknown_warnings(self):
        """Warnings about cutting moves made before an axis had a programmed position."""
        start = np.zeros(3) if self.start is None else np.asarray(self.start)
        return ["%d cutting move(s) from line %d on ran before the program gave an absolute "
                "%s position: the compensation assumed %s = %g mm there and did not write %s "
                "(give the start position if it is known)"
                % (count, first, AXIS_LETTERS[a], AXIS_LETTERS[a], start[a], AXIS_LETTERS[a])
                for a, (first, count) in sorted(self.unknown_use.items())]

    def _flush(self):
        """Turn the moves collected one by one into a chunk of arrays."""
        mv = self.moves
        m = len(mv["kind"])
        if m:
            self.chunks.append(_move_arrays(mv, m))
            self.chunk_moves += m
            for v in mv.values():
                v.clear()

    def add_moves(self, arrays):
        """Append moves given as arrays (the fields of :data:`_MOVE_FIELDS`, in order
        after those collected so far)."""
        self._flush()
        self.chunks.append(arrays)
        self.chunk_moves += int(arrays["kind"].size)

    def take_moves(self, infos, warnings):
        """The :class:`Program` of the moves collected since the last call (then
        forgotten: a program read block by block holds one block's moves at a time)."""
        start = self.start
        self._flush()
        if len(self.chunks) == 1:
            arr = self.chunks[0]
        else:
            arr = _move_arrays(self.moves, 0) if not self.chunks else {
                k: np.concatenate([c[k] for c in self.chunks]) for k in _MOVE_FIELDS}
        self.chunks = []
        self.chunk_moves = 0
        return Program(
            infos, arr["kind"], arr["start"], arr["end"], arr["centre"], arr["plane"],
            arr["turns"], arr["line"], arr["known"], arr["factor"],
            warnings, self.source, start is not None,
            np.zeros(3) if start is None else np.array(start, dtype=float).reshape(3),
            arr["absolute"])

    def program(self, infos):
        """The :class:`Program` of the lines interpreted."""
        self.warnings.extend(self.unknown_warnings())
        return self.take_moves(infos, self.warnings)


#: the arrays of a program's moves (:class:`Program`), and their element types
_MOVE_FIELDS = {"kind": int, "start": float, "end": float, "centre": float, "plane": int,
                "turns": int, "line": int, "known": bool, "factor": float, "absolute": bool}
_MOVE_WIDE = ("start", "end", "centre", "known")


def _move_arrays(mv, m):
    """The lists of ``m`` moves ``mv`` as arrays."""
    return {k: (np.array(mv[k], dtype=t).reshape(m, 3) if k in _MOVE_WIDE
                else np.array(mv[k], dtype=t)) for k, t in _MOVE_FIELDS.items()}


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
    state = _Interpreter(source, start, path)
    return state.program(state.lines(line_words, line_numbers=line_numbers))


def parse_gcode(data, source=None, start=None):
    """Parse a whole program (text or bytes).

    Returns
    -------
    (Program, list of (content, ending))
        The interpretation and the lines it refers to.
    """
    lines = split_lines(decode(data))
    toks = [tokenize(c, source, k + 1) for k, (c, _e) in enumerate(lines)]
    return interpret(toks, source=source, start=start), lines


def read_gcode(path):
    """The bytes of a G-code file (GCodeError when it cannot be read)."""
    try:
        with open(path, "rb") as fh:
            return fh.read()
    except OSError as exc:
        raise GCodeError("cannot read the G-code file: %s" % exc.strerror, file=path) from exc
