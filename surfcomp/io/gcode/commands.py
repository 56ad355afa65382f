# SPDX-License-Identifier: LGPL-2.1-or-later
"""FreeCAD Path command lists (``(Name, Parameters)`` pairs): compensate without text.

The adaptor behind the Path dressup (:mod:`surfcomp.app.dressup_axis`); it needs no
FreeCAD itself. Path coordinates are always mm and absolute unless ``G91``.
"""

import re

from ...core.axis.moves import plan_moves
from ...errors import GCodeError
from .interpreter import interpret
from .lexer import AXIS_LETTERS, Word
from .result import CommandsResult, OutputState

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
    model : surfcomp.core.axis.axis_errors.AxisErrorModel
        In the commands' coordinates (mm).
    segment_length, tolerance, arc_tolerance, start, source
        As in :func:`surfcomp.io.gcode.compensate_gcode`.

    Returns
    -------
    CommandsResult
        Moves are rewritten with every parameter they had (feed ``F`` included, on every
        piece of a split move); arcs that need compensation become ``G1`` pieces; every
        other command is kept. A zero model keeps every command.

    Raises
    ------
    GCodeError
        What the compensation cannot handle (as :func:`compensate_gcode`), naming the
        1-based command number as the line.
    """
    line_words = [(command_words(n, p, source, k + 1), False)
                  for k, (n, p) in enumerate(commands)]
    prog = interpret(line_words, source=source, start=start, path=True)
    plan = plan_moves(prog, model, segment_length, tolerance, arc_tolerance, still=0.0)
    writer = _CommandWriter(prog, plan, start)
    out = []
    for idx, (name, params) in enumerate(commands):
        out.extend(writer.command(idx, name, params))
    res = writer.state.result(CommandsResult, out, len(commands), len(out), prog)
    res.check_bounds(model, 0.0, source)
    return res


class _CommandWriter:
    """Turns each command into its output commands (mm, like Path itself)."""

    def __init__(self, prog, plan, start):
        self.prog = prog
        self.plan = plan
        self.state = OutputState(None if start is None else prog.start_pos)
        self.comp_l = plan.compensated.tolist()
        self.nom_l = plan.nominal.tolist()
        self.off_l = plan.offsets.tolist()

    def command(self, idx, name, params):
        """The output of command ``idx``: ``[idx]`` when it is kept, else new commands."""
        info = self.prog.lines[idx]
        if info is not None and info.unknown:
            self.state.forget(info.unknown)
        if info is None or info.unknown or info.move < 0:
            return [idx]
        j = info.move
        known = self.prog.known[j].tolist()
        if self.plan.keep[j]:
            self.state.hold_programmed(info)
            self.state.record_kept(idx + 1, self.prog.end[j].tolist(), known)
            return [idx]
        convert = bool(self.prog.kind[j] >= 2)
        pieces = self._pieces(idx, info, j, params, convert, known)
        if len(pieces) == 1 and not convert and pieces[0] == dict(params):
            return [idx]
        self.state.changed += 1
        self.state.added += len(pieces) - 1
        if convert:
            self.state.converted += 1
        elif len(pieces) > 1:
            self.state.split += 1
        new_name = "G1" if convert else name
        return [(new_name, par) for par in pieces]

    def _pieces(self, idx, info, j, params, convert, known):
        """Parameters of every piece of move ``j``: the first keeps all the command's
        parameters (arc words dropped when the arc becomes G1 pieces), the others carry
        the axes that change and the feed."""
        base = dict(params)
        if convert:
            for key in list(base):
                if str(key).upper() in "IJKRP":
                    del base[key]
        keys = {str(k).upper(): k for k in base}
        held = self.state.held
        pieces = []
        for p in range(self.off_l[j], self.off_l[j + 1]):
            pt = self.comp_l[p]
            first = not pieces
            par = dict(base) if first else {}
            if not first and "F" in keys:
                par[keys["F"]] = base[keys["F"]]
            for a in range(3):
                if not known[a]:
                    continue
                letter = AXIS_LETTERS[a]
                present = first and info.axis_words[a] is not None
                value = pt[a] if info.absolute else pt[a] - held[a]
                if present or held[a] is None or held[a] != pt[a]:
                    par[keys.get(letter, letter)] = value
                held[a] = pt[a]
            pieces.append(par)
            self.state.record(idx + 1, self.nom_l[p], pt, known)
        return pieces
