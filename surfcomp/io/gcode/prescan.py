# SPDX-License-Identifier: LGPL-2.1-or-later
"""The segment count of a whole program before any block of it is planned (no FreeCAD).

A program compensated a block at a time (:mod:`.stream`) knows how many segments it
needs only at its end; a program that needs more than the limit
(:data:`surfcomp.core.axis.moves.MAX_SEGMENTS`) would be planned up to the limit first, for
nothing but time (tens of seconds at 10 million segments). This first pass reads the
program's blocks with the same reader and interpreter (:func:`.plain.read_block`, modal
state carried from block to block) and adds up the estimate of
:func:`surfcomp.core.axis.moves.estimate_segments` of every block's moves, the one
:class:`surfcomp.io.gcode.stream.Compensator` adds up, without sampling or planning
anything; one block's moves are held at a time. A refusal is that of
:func:`surfcomp.core.axis.moves.refuse_segments`: the same message, option names and
suggested segment length as a refusal found by the compensation itself.
"""

from ...core.axis.moves import MAX_SEGMENTS, SegmentEstimate, estimate_segments, refuse_segments
from .interpreter import _Interpreter
from .plain import read_block


def count_segments(blocks, segment_length, arc_tolerance, start=None, source=None):
    """``(SegmentEstimate, moves)`` of the whole program whose ``(content, ending)`` lines
    come in ``blocks`` (:func:`surfcomp.io.gcode.stream.program_blocks`); ``start``: known
    start position (mm, as the compensation takes it). Raises what the interpreter refuses
    (:class:`surfcomp.errors.GCodeError`, naming the line)."""
    interp = _Interpreter(source, start, False)
    est = SegmentEstimate(0.0, 0.0, 0.0)
    n_moves = base = 0
    for lines in blocks:
        infos, _runs = read_block(interp, lines, base, source)
        prog = interp.take_moves(infos, interp.warnings)
        base += len(lines)
        est = est + estimate_segments(prog, segment_length, arc_tolerance)
        n_moves += prog.n_moves
    return est, n_moves


def check_program_segments(blocks, segment_length, arc_tolerance, max_segments=MAX_SEGMENTS,
                           names=("segment length", "arc tolerance"), start=None,
                           source=None):
    """Refuse a program (its ``blocks``, :func:`count_segments`) that would be split into
    more than ``max_segments`` points (the :class:`surfcomp.errors.InputError` of
    :func:`surfcomp.core.axis.moves.check_segments`); its estimate otherwise."""
    est, n_moves = count_segments(blocks, segment_length, arc_tolerance, start, source)
    if est.total > max_segments:
        refuse_segments(est, n_moves, segment_length, arc_tolerance, max_segments, names,
                        source)
    return est
