# SPDX-License-Identifier: LGPL-2.1-or-later
"""Rewrite G-code text: compensated moves written into the original lines.

Every line the compensation does not change is written back byte for byte; changed lines
keep their words, spacing, case and comments, with only the axis numbers replaced (and
motion words where an arc became G1 pieces). See :mod:`surfcomp.io.gcode`.
"""

import numpy as np

from ...errors import GCodeError
from .lexer import AXIS_LETTERS
from .result import OutputState

#: default output decimals per unit system
DEFAULT_DECIMALS = {"mm": 4, "in": 5}

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


def file_sep(pairs):
    """The separator most multi-word lines of the file use (for one-word lines).

    ``pairs`` gives ``(content, words)`` of the file's lines in order (``words`` None or
    empty for lines without words); at most the first 200 multi-word lines are read.
    """
    spaced = terse = 0
    for content, words in pairs:
        if not words or len(words) < 2:
            continue
        st = _gap_style(content, words[0], words[1])
        if st == " ":
            spaced += 1
        elif st == "":
            terse += 1
        if spaced + terse >= 200:
            break
    return "" if terse > spaced else " "


def default_eol(lines):
    """The first line ending of ``(content, ending)`` pairs (for lines a move adds after
    a last line without one), ``'\\n'`` when none has one."""
    return next((e for _c, e in lines if e), "\n")


class _TextWriter:
    """Writes the lines of a program with the compensated points of its plan.

    Numbers are held in program units (``out.held``); ``factor`` is mm per program unit.
    """

    def __init__(self, file_sep, eol_default, start, dmin_mm, dmin_in, source):
        self.source = source
        self.dmin_mm, self.dmin_in = dmin_mm, dmin_in
        self.eol_default = eol_default
        self.file_sep = file_sep
        self.state = OutputState(start)
        self.factor_prev = 1.0
        self.last_dec = [3, 3, 3]       # decimals of the last word of each axis
        self.out_motion = None          # modal motion of the output so far
        self.prog = None
        self.base = 0

    def block(self, prog, plan, base):
        """The next block: its lines (from line index ``base`` on) and the plan of their
        moves."""
        self.prog = prog
        self.plan = plan
        self.base = base
        self.listed = False
        self.few = False            # few lines are written one by one (:meth:`_lists`)

    def _lists(self):
        """The block's arrays as plain lists: indexing them is much faster than indexing
        arrays (made when the first move is written line by line; with ``few`` set, for a
        block written mostly as arrays, rows are taken from the arrays when asked for)."""
        prog, plan = self.prog, self.plan
        conv = _Rows if self.few else np.ndarray.tolist
        self.known_l = conv(prog.known)
        self.kind_l = conv(prog.kind)
        self.end_l = conv(prog.end)
        self.comp_l = conv(plan.compensated)
        self.nom_l = conv(plan.nominal)
        self.off_l = conv(plan.offsets)
        self.keep_l = conv(plan.keep)
        self.split_l = conv(plan.split)
        self.listed = True

    def line(self, idx, content, eol):
        """The output text of line ``idx`` (its ending included)."""
        info = self.prog.lines[idx - self.base]
        if info is None:
            return content + eol
        f = info.factor
        if f != self.factor_prev:
            self.state.held = [None if v is None else v * self.factor_prev / f
                               for v in self.state.held]
            self.factor_prev = f
        for a in range(3):
            k = info.axis_words[a]
            if k is not None:
                self.last_dec[a] = max(info.words[k].decimals, 1)
        if info.unknown:
            self.state.forget(info.unknown)
        if info.unknown or info.move < 0:
            if info.motion_word is not None:
                self.out_motion = info.motion
            return content + eol
        return self._move_line(idx, content, eol, info)

    def _move_line(self, idx, content, eol, info):
        if not self.listed:
            self._lists()
        j = info.move
        sep, asep = _word_sep(content, info.words, self.file_sep)
        if self.keep_l[j]:
            # arc left as programmed (compensation below the output resolution)
            self.state.hold_programmed(info)
            edits = []
            _restore_motion(content, info.words, info, self.out_motion, sep, edits)
            self.out_motion = info.motion
            self.state.record_kept(idx + 1, self.end_l[j], self.known_l[j])
            if edits:
                self.state.changed += 1
            return _apply(content, edits) + eol
        split = self.split_l[j]
        if split and info.stop:
            raise GCodeError("a move with a program stop (M0/M1/M2/M30/M60) on its line must "
                             "be split for the compensation; put the stop on its own line",
                             file=self.source, line=idx + 1)
        first = self._first_piece(idx, content, info, j, sep, asep, split)
        rest = self._further_pieces(idx, info, j, eol, asep)
        if split and self.kind_l[j] == 1:
            self.state.split += 1
        return first + rest

    def _digits(self, info, a, dmin):
        """(decimals written, decimals kept when dropping trailing zeros) for axis ``a``."""
        k = info.axis_words[a]
        dec = info.words[k].decimals if k is not None else self.last_dec[a]
        return max(dmin, dec), max(dec, 1)

    def _first_piece(self, idx, content, info, j, sep, asep, split):
        """The move's own line with its axis words rewritten (first piece of the move)."""
        off = self.off_l[j]
        pt = self.comp_l[off]
        known = self.known_l[j]
        f = info.factor
        dmin = self.dmin_mm if f == 1.0 else self.dmin_in
        new = {}
        for a in range(3):
            if known[a]:
                w = self._first_axis(info, a, pt[a] / f, dmin)
                if w is not None:
                    new[a] = w
        edits = []
        for k, s in new.values():
            if k is not None:
                w = info.words[k]
                edits.append((w.end - len(w.text), w.end, s))
        _add_words(content, info.words, info,
                   [(a, s) for a, (k, s) in sorted(new.items()) if k is None], asep, edits)
        if split and self.kind_l[j] >= 2:
            _convert_arc(content, info.words, info, sep, edits, self.out_motion)
            self.out_motion = 1
            self.state.converted += 1
        else:
            _restore_motion(content, info.words, info, self.out_motion, sep, edits)
            self.out_motion = info.motion
        self.state.record(idx + 1, self.nom_l[off], pt, known, f)
        if edits:
            self.state.changed += 1
        return _apply(content, edits)

    def _first_axis(self, info, a, v, dmin):
        """Axis ``a`` at ``v`` (program units) on the move's own line: ``(index of the
        word to replace or None to add one, number text)``, or None when nothing changes."""
        held = self.state.held
        k = info.axis_words[a]
        d, keep = self._digits(info, a, dmin)
        s_abs = _fmt(v, d, keep)
        v_abs = float(s_abs)
        if info.absolute:
            if k is not None:
                prog_v = info.words[k].value
                if v_abs != float("%.*f" % (d, prog_v)):
                    held[a] = v_abs
                    return k, s_abs
                held[a] = prog_v
            elif held[a] is None or float("%.*f" % (d, held[a])) != v_abs:
                held[a] = v_abs
                return None, s_abs
            return None
        inc = _fmt(v_abs - held[a], d, keep)
        if k is not None:
            if float(inc) != float("%.*f" % (d, info.words[k].value)):
                held[a] += float(inc)
                return k, inc
            held[a] += info.words[k].value
        elif float(inc) != 0.0:
            held[a] += float(inc)
            return None, inc
        return None

    def _further_pieces(self, idx, info, j, eol, asep):
        """New lines with the axis words of the further pieces of a split move."""
        known = self.known_l[j]
        f = info.factor
        dmin = self.dmin_mm if f == 1.0 else self.dmin_in
        extra = []
        for p in range(self.off_l[j] + 1, self.off_l[j + 1]):
            pt = self.comp_l[p]
            ws = []
            for a in range(3):
                if known[a]:
                    w = self._next_axis(info, a, pt[a] / f, dmin)
                    if w is not None:
                        ws.append(w)
            if ws:
                extra.append(asep.join(ws))
                self.state.record(idx + 1, self.nom_l[p], pt, known, f)
        if not extra:
            return eol
        self.state.added += len(extra)
        mid = eol if eol else self.eol_default
        return mid + mid.join(extra) + eol

    def _next_axis(self, info, a, v, dmin):
        """The word of axis ``a`` at ``v`` (program units) on a new line, or None when the
        machine holds that value already."""
        held = self.state.held
        d, keep = self._digits(info, a, dmin)
        s_abs = _fmt(v, d, keep)
        v_abs = float(s_abs)
        if info.absolute:
            if held[a] is None or float("%.*f" % (d, held[a])) != v_abs:
                held[a] = v_abs
                return AXIS_LETTERS[a] + s_abs
            return None
        inc = _fmt(v_abs - held[a], d, keep)
        if float(inc) != 0.0:
            held[a] += float(inc)
            return AXIS_LETTERS[a] + inc
        return None


class _Rows:
    """``rows[i]``: row ``i`` of an array as a list (or a number), as ``tolist()`` of the
    whole array would give it, without converting the rest."""

    __slots__ = ("a",)

    def __init__(self, a):
        self.a = a

    def __getitem__(self, i):
        return self.a[i].tolist()


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
