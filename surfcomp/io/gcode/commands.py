"""FreeCAD Path command lists (``(Name, Parameters)`` pairs): compensate without text.

The adaptor behind the Path dressup (:mod:`surfcomp.app.dressup_axis`); it needs no
FreeCAD itself. Path coordinates are always mm and absolute unless ``G91``.
"""

import re

import numpy as np

from ...core.moves import plan_moves
from ...errors import GCodeError
from .interpreter import interpret
from .lexer import AXIS_LETTERS, Word
from .result import CommandsResult

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
