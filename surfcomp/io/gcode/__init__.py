# SPDX-License-Identifier: LGPL-2.1-or-later
"""3-axis G-code: parse, compensate machine-axis errors, rewrite (no FreeCAD).

Modules: :mod:`.lexer` (lines and words), :mod:`.interpreter` (modal state, moves),
:mod:`.emitter` (rewriting the text), :mod:`.stream` (a program compensated a block of
lines at a time, or whole), :mod:`.plain` and :mod:`.plain_write` (runs of plain G0/G1
lines read and written as arrays inside the block path, with the same output),
:mod:`.totals` (whole-program figures added up over blocks), :mod:`.commands` (FreeCAD
Path command lists), :mod:`.result` (what a compensation returns); the arc geometry and
the move planning are compensation maths in :mod:`surfcomp.core.axis.arcs` and
:mod:`surfcomp.core.axis.moves`.

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
inside the program (``G10 G52 G92``, a second work offset after the first move; naming
none counts as G54, the power-up default), inverse
time feed ``G93``, probing ``G38.x``, threading ``G33``, splines ``G5``, lathe, polar and
rotation modes, any G code not listed above, an incremental move of an axis whose position
is not known, arcs whose end is not on the circle.

How moves are compensated
-------------------------
Each programmed point ``X`` (mm) is replaced by the command ``X'`` with ``X' + E(X') = X``
(:meth:`surfcomp.core.axis.axis_errors.AxisErrorModel.compensate`).

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

from ...core.axis.arcs import ARC_RADIUS_TOL, FULL_CIRCLE_TOL, PLANES, arc_points, arc_steps
from ...core.axis.moves import MovePlan, plan_moves
from .commands import command_words, compensate_commands
from .emitter import DEFAULT_DECIMALS, _fmt
from .interpreter import LineInfo, Program, interpret, parse_gcode, read_gcode
from .lexer import AXIS_LETTERS, Word, split_lines, tokenize
from .result import CommandsResult, CompensationResult, GCodeResult
from .stream import BLOCK_LINES, ProgramFile, compensate_gcode, compensate_stream

__all__ = [
    "ARC_RADIUS_TOL", "AXIS_LETTERS", "BLOCK_LINES", "DEFAULT_DECIMALS", "FULL_CIRCLE_TOL",
    "PLANES",
    "CommandsResult", "CompensationResult", "GCodeResult", "LineInfo", "MovePlan", "Program",
    "ProgramFile", "Word",
    "_fmt", "arc_points", "arc_steps", "command_words", "compensate_commands",
    "compensate_gcode", "compensate_stream", "interpret", "parse_gcode", "plan_moves", "read_gcode",
    "split_lines", "tokenize",
]
