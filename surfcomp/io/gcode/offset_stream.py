# SPDX-License-Identifier: LGPL-2.1-or-later
"""A ball-end program moved by a surface correction, a block of lines at a time (no FreeCAD).

The same lexer, interpreter and writer as the axis-error compensation (:mod:`.stream`): the
program is read :data:`surfcomp.io.gcode.stream.BLOCK_LINES` lines at a time, each block's
moves are planned by :func:`surfcomp.core.compensation.program_offset.plan_offset` and written into
the original lines; lines of moves nothing moves are written back byte for byte. A refusal found
in a late block (or by the contact check over the whole program) is raised before anything
is committed: the caller writes into a staged file.

Refused besides what the interpreter refuses (G41/G42 among it, anywhere): moves in inch
mode (G20) or incremental mode (G91); a program no cutting move of which comes near the
face; cutting points that cut into the nominal (a larger ball than the program's) or sit
off its ball offset (another radius, stock, or another face): see :meth:`ProgramOffset.finish`;
a program whose moves near the face would be planned at more pieces than
:data:`surfcomp.core.limits.MAX_SEGMENTS` in all, before the block that passes it is
sampled (:class:`surfcomp.core.compensation.program_limit.PieceCount`).

The moves of a block are planned beside the reading and writing of the blocks around it:
on a second thread, or, for a long program whose caller allows it (``fork``), in a fork of
this process (:class:`_Planner`), where the planning does not wait for the text's share of
Python's interpreter lock (figures in docs/direct_program.md, eighth round).
"""

import os
import pickle
import signal
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import replace

import numpy as np

from ...core.chunks import threads
from ...core.compensation.program_limit import PieceCount
from ...core.compensation.program_offset import CONTACT_TOL, fit_contact, plan_offset
from ...core.limits import MAX_SEGMENTS
from ...errors import ComputationError, GCodeError
from .. import forks
from .commands import _CommandWriter, command_words
from .emitter import DEFAULT_DECIMALS, _TextWriter
from .interpreter import _Interpreter, interpret
from .plain import read_block
from .plain_write import write_block
from .result import CommandsResult
from .stream import BLOCK_LINES, stream_program

#: programs of at least this many lines are planned in a fork of this process when the
#: caller allows it (a shorter one does not repay the fork: the example's finishing
#: program has 2 blocks)
FORK_LINES = 4 * BLOCK_LINES


class ProgramOffset:
    """Moves consecutive blocks of one program and adds up what the whole decides.

    Parameters
    ----------
    offset : surfcomp.core.compensation.program_offset.BallOffset
    tolerance, segment_length : float
        Of :func:`surfcomp.core.compensation.program_offset.plan_offset` (mm).
    decimals : int, optional
        Least decimals of rewritten numbers (default 4).
    source : str, optional
        File name for messages.
    sep, eol : str
        The file's word separator and first line ending.
    max_segments, max_memory : int, optional
        Most pieces the moves near the face are planned at in all, most bytes one
        block's pieces may take (:class:`surfcomp.core.compensation.program_limit.PieceCount`).
    fork : bool
        Plan in a fork of this process (:class:`_Planner`) rather than on a second thread
        when :meth:`run` may use two and :func:`surfcomp.io.forks.may_fork` allows it;
        for a caller that owns the process (the command line), not one whose other
        threads or GUI a fork would copy half of.
    """

    def __init__(self, offset, tolerance=5e-4, segment_length=2.0, decimals=None, source=None,
                 sep=" ", eol="\n", max_segments=MAX_SEGMENTS, max_memory=None, fork=False):
        self.offset = offset
        self.tolerance = tolerance
        self.segment_length = segment_length
        self.source = source
        self.dmin = DEFAULT_DECIMALS["mm"] if decimals is None else int(decimals)
        self.still = 0.5 * 10.0 ** -self.dmin * 0.999
        self.interp = _Interpreter(source, None, False)
        self.writer = _TextWriter(sep, eol, None, self.dmin, DEFAULT_DECIMALS["in"], source)
        self.n_lines = self.n_moves = self.moved = self.checked = 0
        self.words = False
        self.largest = 0.0
        self.start_move = None
        self.closest = (np.inf, 0)          # smallest clearance of a cutting point, line
        self.contact = []                    # (gap, tilt, interior, line) per block
        self.count = PieceCount(segment_length, max_segments, source, max_memory)
        self.fork = bool(fork)

    def lines(self, lines):
        """Read, interpret, move and write the next block of ``(content, ending)`` lines;
        its output text."""
        got = self.read(lines)
        return self.write(self.plan(got[0]), *got)

    def run(self, blocks, write):
        """:meth:`lines` of every block of ``blocks``, each output passed to ``write``;
        with more than one thread (:func:`surfcomp.core.chunks.threads`) a block's moves
        are planned on a second thread, or in a fork of this process (``fork``), while the
        next block is read and the one before written. The output, and the first refusal
        raised, are those of :meth:`lines` block after block."""
        if threads() < 2:
            for block in blocks:
                write(self.lines(block))
            return
        with self._planner() as (submit, ahead):
            pending = None
            for block in blocks:
                try:
                    got = self.read(block)
                except BaseException:
                    if pending is not None:      # what the block before raises first
                        write(self.write(pending[0].result(), *pending[1]))
                    raise
                if pending is None:
                    pending = (submit(got[0]), got)
                    continue
                op = pending[0].result()
                if ahead:
                    # the forked planner starts on this block before the block before is
                    # written (the planning needs nothing the writing changes), so it is
                    # not idle while the text is written; a thread would contend for the
                    # interpreter lock with the writing instead (more CPU on the
                    # example's finishing program: docs/benchmarks.md, eighth round)
                    done, pending = pending, (submit(got[0]), got)
                    write(self.write(op, *done[1]))
                else:
                    write(self.write(op, *pending[1]))
                    pending = (submit(got[0]), got)
            if pending is not None:
                write(self.write(pending[0].result(), *pending[1]))

    @contextmanager
    def _planner(self):
        """``(submit, ahead)``: ``submit(prog)``, whose ``result()`` is :meth:`plan` of
        ``prog``, in a fork of this process (:class:`_Planner`; ``ahead`` True: a block
        is submitted before the one before is written) or on a second thread."""
        if self.fork and forks.may_fork():
            with _Planner(self) as planner:
                yield planner.submit, True
            return
        with ThreadPoolExecutor(1, thread_name_prefix="surfcomp-plan") as pool:
            yield (lambda prog: pool.submit(self.plan, prog)), False

    def read(self, lines):
        """Read and interpret a block: ``(prog, lines, base, runs)``; a move in inch or
        incremental mode is refused."""
        base = self.n_lines
        infos, runs = read_block(self.interp, lines, base, self.source)
        prog = self.interp.take_moves(infos, self.interp.warnings)
        self.n_lines = base + len(lines)
        self.words = self.words or not prog.is_empty()
        self._check_modes(prog, base)
        self.n_moves += prog.n_moves
        return prog, lines, base, runs

    def plan(self, prog):
        """The :func:`plan_offset` of a block read by :meth:`read` (blocks in order)."""
        op = plan_offset(prog, self.offset, self.tolerance, self.segment_length, self.still,
                         self.start_move, self.count)
        if prog.n_moves:
            self.start_move = op.plan.compensated[-1] - op.plan.nominal[-1]
        return op

    def write(self, op, prog, lines, base, runs):
        """The output text of a block read by :meth:`read` and planned (``op``)."""
        self.moved += int(op.moved.sum())
        self.checked += op.checked
        self._collect(prog, op)
        w = self.writer
        w.block(prog, op.plan, base)
        out = write_block(w, lines, base, runs)
        nominal, emitted, _known, _line = w.state.take_points()
        if nominal.shape[0]:
            self.largest = max(self.largest,
                               float(np.linalg.norm(emitted - nominal, axis=1).max()))
        return out

    def _check_modes(self, prog, base):
        """Refuse a move in inch or incremental mode (naming its line)."""
        bad = np.flatnonzero((prog.factor != 1.0) | ~prog.absolute)
        if not bad.size:
            return
        j = int(bad[0])
        if prog.factor[j] != 1.0:
            raise GCodeError("move in inch mode (G20): the correction is in mm and the "
                             "program is moved in mm; expected a program in mm (G21)",
                             file=self.source, line=int(prog.line[j]) + 1)
        raise GCodeError("move in incremental mode (G91): expected absolute "
                         "positions (G90), as CAM writes finishing programs",
                         file=self.source, line=int(prog.line[j]) + 1)

    def _collect(self, prog, op):
        """The cutting moves' end points for the contact check."""
        got = contact_points(prog, op)
        if got is None:
            return
        closest, points = got
        if closest[0] < self.closest[0] or not self.closest[1]:
            self.closest = closest
        self.contact.append(points)

    def finish(self):
        """Refuse a program that does not fit the face and the tool
        (:func:`check_contact`); ``fit`` is its contact fit."""
        self.fit = check_contact(self.offset, self.closest, self.contact, self.source)

    def warnings(self):
        return self.interp.warnings + self.interp.unknown_warnings()

    def stats(self):
        st = self.writer.state
        return {"lines_in": self.n_lines, "lines_out": self.n_lines + st.added,
                "lines_changed": st.changed, "lines_added": st.added, "moves": self.n_moves,
                "moves_moved": self.moved, "arcs_converted": st.converted,
                "points_evaluated": self.checked, "largest_move_mm": self.largest}


class _Planner:
    """:meth:`ProgramOffset.plan` of the blocks submitted, in a fork of this process.

    The child gets each block's moves through a pipe (the interpreted
    :class:`surfcomp.io.gcode.Program` without its lines' details) and sends back the
    :class:`surfcomp.core.compensation.program_offset.OffsetPlan`, or the refusal the
    planning raised (the same exception, its file and line; the child then stops). The
    blocks are planned in order, one at a time, so what the planning carries from one
    block to the next (the last displacement, the piece count) stays in the child.

    The child ignores Ctrl-C, SIGTERM and SIGHUP (sent to the process group, they reach
    the parent, which ends the child) and ends by itself at the end of its pipe (the
    parent gone, even by SIGKILL); it never returns into the caller's code (``os._exit``:
    no staged file is removed or written by it, no buffer flushed twice). Leaving the
    ``with`` block ends the child: at once (SIGKILL) when an exception leaves it, else
    once it has read the end of its pipe; it is always waited for."""

    def __init__(self, worker):
        child_in, to_child = os.pipe()
        from_child, child_out = os.pipe()
        forks.flush_streams()
        pid = os.fork()
        if pid == 0:                                # the child: never returns
            code = 1
            try:
                os.close(to_child)
                os.close(from_child)
                _serve(worker, child_in, child_out)
                code = 0
            finally:
                os._exit(code)
        os.close(child_in)
        os.close(child_out)
        self.pid = pid
        self.status = None
        self.send = os.fdopen(to_child, "wb")
        self.recv = os.fdopen(from_child, "rb")
        self.broken = False

    def __enter__(self):
        return self

    def __exit__(self, kind, _exc, _tb):
        self.close(kill=kind is not None)

    def submit(self, prog):
        """Send ``prog`` to be planned; returns what gives its plan (``result()``)."""
        try:
            pickle.dump(replace(prog, lines=None, warnings=[]), self.send,
                        pickle.HIGHEST_PROTOCOL)
            self.send.flush()
        except (BrokenPipeError, ConnectionResetError):
            self.broken = True          # the child ended: result() says how
        return self

    def result(self):
        """The next plan, or the refusal the child raised planning it."""
        try:
            ok, got = pickle.load(self.recv)
        except (EOFError, pickle.UnpicklingError, OSError):
            raise self._died() from None
        if not ok:
            raise got
        return got

    def _died(self):
        self.close(kill=True)
        how = ("signal %d" % -self.status if self.status < 0 else "exit code %d" % self.status)
        return ComputationError("the process planning the program's moves ended unexpectedly "
                                "(%s)" % how)

    def close(self, kill=False):
        """End the child (``kill``: at once) and wait for it."""
        if self.status is not None:
            return
        for fh in (self.send, self.recv):
            try:
                fh.close()
            except OSError:
                pass
        if kill:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        while True:
            try:
                _pid, status = os.waitpid(self.pid, 0)
                break
            except InterruptedError:
                continue
        self.status = os.waitstatus_to_exitcode(status)


def _serve(worker, child_in, child_out):
    """The planning child's loop (:class:`_Planner`)."""
    import gc

    # Ctrl-C, SIGTERM and SIGHUP sent to the process group reach the parent too, which
    # unwinds and ends the child; a child dying of them first would make the parent report
    # its death instead of the interruption (the exit code 1, not 130/143/129)
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None:
            signal.signal(sig, signal.SIG_IGN)
    gc.freeze()         # the collector leaves the parent's objects (and their pages) alone
    with os.fdopen(child_in, "rb") as inp, os.fdopen(child_out, "wb") as out:
        while True:
            try:
                prog = pickle.load(inp)
            except EOFError:
                return
            try:
                msg = (True, worker.plan(prog))
            except Exception as exc:    # noqa: BLE001  (sent to the parent, raised there)
                msg = (False, _portable(exc))
            pickle.dump(msg, out, pickle.HIGHEST_PROTOCOL)
            out.flush()
            if not msg[0]:
                return


def _portable(exc):
    """``exc`` if it can be sent through a pipe, else a ComputationError with its text."""
    try:
        pickle.dumps(exc, pickle.HIGHEST_PROTOCOL)
        return exc
    except Exception:   # noqa: BLE001
        return ComputationError("%s: %s" % (type(exc).__name__, exc))


def contact_points(prog, op):
    """``((gap, line) of the closest cutting point, (gap, tilt, interior, line))`` of the
    cutting moves' end points of a planned block (1-based lines), or None without any."""
    cut = (prog.kind >= 1) & prog.known.all(axis=1)
    if not cut.any():
        return None
    gap, lines = op.gap[cut], prog.line[cut] + 1
    k = int(np.argmin(gap))
    return (float(gap[k]), int(lines[k])), (gap, op.tilt[cut], op.interior[cut], lines)


def check_contact(off, closest, contact, source=None):
    """Refuse a program that does not fit the face and the tool.

    Parameters
    ----------
    off : surfcomp.core.compensation.program_offset.BallOffset
    closest : (float, int)
        Smallest clearance (mm) of a cutting point and its line (the first cutting line
        when none is within reach).
    contact : list of (gap, tilt, interior, line)
        The cutting moves' end points (:func:`contact_points`).
    source : str, optional

    Returns
    -------
    surfcomp.core.compensation.program_offset.ContactFit

    Raises
    ------
    GCodeError
        No cutting move comes within the ball radius plus the blend of the face; none
        touches it inside its boundary (clearance within a quarter of the radius: the
        checks below would have nothing to check); a cutting point inside the face is
        more than :data:`surfcomp.core.compensation.program_offset.CONTACT_TOL` inside the
        nominal; the
        contact points fit another ball radius or sit off the ball's offset surface
        (:func:`surfcomp.core.compensation.program_offset.fit_contact`).
    """
    r = off.radius
    if not closest[0] < off.blend:
        where = ("the closest is %.3f mm beyond the ball's contact" % closest[0]
                 if np.isfinite(closest[0]) else
                 "every cutting point is farther than %.3f mm from it (this line has "
                 "the first)" % off.reach)
        raise GCodeError("no cutting move of the program comes near the face (the ball of "
                         "radius %g mm within blend %g mm of it): %s; expected the "
                         "finishing program of this face" % (r, off.blend, where),
                         file=source, line=closest[1] or None, options=("blend",))
    gap, tilt, interior, lines = (np.concatenate(a) for a in zip(*contact))
    fit = fit_contact(gap, tilt, interior, lines, r)
    if fit.points == 0:
        # within the blend but never touching: the stock and radius checks below have
        # nothing to check, and the program would be moved by a share of the correction
        raise GCodeError("no cutter-location point of the program touches the face inside "
                         "its boundary (the ball of radius %g mm within %g mm, a quarter of "
                         "its radius, of it): the closest cutting point is %.3f mm beyond "
                         "the ball's contact; a program with stock left, above the face, "
                         "or for another face; expected the finishing program of this face"
                         % (r, 0.25 * r, closest[0]), file=source, line=closest[1] or None)
    if fit.deepest < -CONTACT_TOL:
        raise GCodeError("the ball of radius %g mm (tool) at this cutter-location point "
                         "cuts %.4f mm into the nominal face (more than %g mm): the program "
                         "was made for a smaller ball, for another face, or cuts below this "
                         "one; expected the ball radius the program was made with and the "
                         "finishing program of this face" % (r, -fit.deepest, CONTACT_TOL),
                         file=source, line=fit.deepest_line, options=("tool",))
    if fit.radius_error is not None:
        effect = fit.radius_effect
        if effect > CONTACT_TOL:
            raise GCodeError("the program's cutter-location points fit a ball of radius "
                             "%.3f mm, not %g mm (tool; %d contact points on slopes up to "
                             "%.1f degrees, %.4f mm off): expected the ball radius the "
                             "program was made with"
                             % (r + fit.radius_error, r, fit.points, fit.max_tilt, effect),
                             file=source, line=fit.deepest_line or None, options=("tool",))
    if abs(fit.stock) > CONTACT_TOL:
        raise GCodeError("the program's contact points lie %.4f mm %s the nominal face's "
                         "ball offset on average (%d points; more than %g mm): a program "
                         "with stock left, or for another face; expected the finishing "
                         "program of this face" % (abs(fit.stock), "outside" if fit.stock > 0
                                                   else "inside", fit.points, CONTACT_TOL),
                         file=source)
    return fit


def offset_stream(program, write, offset, block_lines=None, **settings):
    """Move a ball-end program by a surface correction, a block at a time.

    Parameters
    ----------
    program : surfcomp.io.gcode.ProgramFile
    write : callable
        Called with each piece of output text (Latin-1).
    offset : surfcomp.core.compensation.program_offset.BallOffset
    block_lines : int, optional
        Lines at a time (default :data:`surfcomp.io.gcode.stream.BLOCK_LINES`).
    **settings
        Of :class:`ProgramOffset` (``tolerance``, ``segment_length``, ``decimals``,
        ``source``, ``max_segments``, ``max_memory``, ``fork``).

    Returns
    -------
    ProgramOffset
        Finished: :meth:`ProgramOffset.finish` raised nothing.
    """
    po = stream_program(program, write,
                        lambda sep, eol: ProgramOffset(offset, sep=sep, eol=eol, **settings),
                        block_lines, settings.get("source"))
    if not po.words:
        raise GCodeError("the program is empty (no G-code words, only blank lines, comments "
                         "or % lines; expected G0/G1/G2/G3 moves)", file=settings.get("source"))
    po.finish()
    return po


def offset_commands(commands, offset, tolerance=5e-4, segment_length=2.0, source=None):
    """Move a FreeCAD-Path-style command list by a surface correction (the Path dressup).

    Parameters
    ----------
    commands : sequence of (str, dict)
        ``(Name, Parameters)`` of every command (mm, absolute unless ``G91``).
    offset : surfcomp.core.compensation.program_offset.BallOffset
    tolerance, segment_length : float
        As :func:`surfcomp.core.compensation.program_offset.plan_offset` (mm).
    source : str, optional
        Label for messages (the "line" is the 1-based command number).

    Returns
    -------
    (CommandsResult, ContactFit, OffsetPlan)
        The output as :func:`surfcomp.io.gcode.compensate_commands` gives it (indices of
        commands kept, ``(name, parameters)`` of new ones), the contact check and the plan.

    Raises
    ------
    GCodeError
        What :func:`check_contact` and the interpreter refuse; a move in incremental mode;
        more pieces than :data:`surfcomp.core.limits.MAX_SEGMENTS`
        (:class:`surfcomp.core.compensation.program_limit.PieceCount`).
    """
    line_words = [(command_words(n, p, source, k + 1), False)
                  for k, (n, p) in enumerate(commands)]
    prog = interpret(line_words, source=source, path=True)
    for j in range(prog.n_moves):
        if not prog.lines[int(prog.line[j])].absolute:
            raise GCodeError("move in incremental mode (G91): expected absolute positions",
                             file=source, line=int(prog.line[j]) + 1)
    op = plan_offset(prog, offset, tolerance, segment_length, 0.5e-6,
                     count=PieceCount(segment_length, source=source))
    got = contact_points(prog, op)
    closest, points = got if got is not None else ((np.inf, 0), None)
    fit = check_contact(offset, closest, [points] if points is not None else [], source)
    writer = _CommandWriter(prog, op.plan, None)
    out = []
    for idx, (name, params) in enumerate(commands):
        out.extend(writer.command(idx, name, params))
    res = writer.state.result(CommandsResult, out, len(commands), len(out), prog)
    return res, fit, op
