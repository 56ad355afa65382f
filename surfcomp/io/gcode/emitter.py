"""Rewrite G-code text: compensated moves written into the original lines.

Every line the compensation does not change is written back byte for byte; changed lines
keep their words, spacing, case and comments, with only the axis numbers replaced (and
motion words where an arc became G1 pieces). See :mod:`surfcomp.io.gcode`.
"""

import numpy as np

from ...core.moves import plan_moves
from ...core.progress import report
from ...errors import GCodeError
from .interpreter import parse_gcode
from .lexer import AXIS_LETTERS, decode
from .result import GCodeResult

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
    text = decode(data)
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
