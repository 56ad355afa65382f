# SPDX-License-Identifier: LGPL-2.1-or-later
"""Compensate a G-code program a block of lines at a time (no FreeCAD).

A program of millions of lines is read, interpreted, planned and written
:data:`BLOCK_LINES` lines at a time, the modal state (units, distance mode, plane,
motion, positions, what the machine holds) carried from one block to the next, so the
memory it takes does not grow with its length (issue 25: a 2-million-line program took
5.8 GB). The same lexer, interpreter and writer handle a whole program at once
(:func:`compensate_gcode`), which is the stream in one block: the output is the same,
byte for byte, whatever the block size.

What the whole program decides is added up as the blocks go (:class:`Compensator`): the
statistics, the segment count, the bounds check and the warnings; the separator style
and the line ending new lines use come from a first look at the file's start. The segment
count is also known before the first block is planned: a first pass reads the program's
blocks and adds up their estimates without planning (:mod:`.prescan`), so a program that
needs too many is refused at once. Any other refusal found in a late block is raised
before anything is committed (the caller writes into a staged file,
:class:`surfcomp.io.atomic.Transaction`).
"""

import io
import math
import os
import stat
from itertools import repeat

import numpy as np

from ...core.axis.moves import (
    MAX_SEGMENTS,
    SegmentEstimate,
    check_lengths,
    estimate_segments,
    plan_moves,
    refuse_segments,
)
from ...core.progress import report
from ...errors import GCodeError
from .emitter import DEFAULT_DECIMALS, _TextWriter, default_eol, file_sep
from .interpreter import _Interpreter, parse_gcode
from .lexer import BOM, decode, tokenize
from .plain import read_block
from .plain_write import write_block
from .prescan import check_program_segments
from .result import GCodeResult
from .totals import BoundsCheck, PointTotals

#: lines compensated at a time (a few tens of MB of lines, words and moves;
#: :data:`surfcomp.core.budget.GCODE_BLOCK_LINES` estimates with it)
BLOCK_LINES = 10_000
_BOM_BYTES = BOM.encode("latin-1")


def iter_lines(fh, chunk=1 << 14):
    """``(content, ending)`` of every line of the binary file ``fh`` as Latin-1 text
    (as :func:`surfcomp.io.gcode.split_lines` of the whole text), without a UTF-8
    byte-order mark at the start; read ``chunk`` bytes at a time."""
    for part in iter_line_lists(fh, chunk):
        yield from part


def iter_line_lists(fh, chunk=1 << 14):
    """The lines of :func:`iter_lines` in lists (those of each ``chunk`` read)."""
    rest = ""
    first = True
    pending = []            # pieces of a line longer than a chunk (joined once)
    while True:
        data = fh.read(chunk)
        if not data:
            break
        if not first and b"\n" not in data:
            pending.append(data.decode("latin-1"))
            continue
        text = "".join([rest] + pending + [data.decode("latin-1")])
        pending = []
        if first:
            if len(text) < len(BOM) and BOM.startswith(text):
                rest = text         # too short to tell yet
                continue
            first = False
            if text.startswith(BOM):
                text = text[len(BOM):]
        parts = text.split("\n")
        rest = parts.pop()
        if "\r" in text:
            yield [(p[:-1], "\r\n") if p.endswith("\r") else (p, "\n") for p in parts]
        else:
            yield list(zip(parts, repeat("\n")))
    rest = "".join([rest] + pending)
    if rest:
        yield [(rest, "")]


class ProgramFile:
    """A G-code file read in passes: a regular file is opened again for each pass, anything
    else (a pipe, ``/dev/stdin``) is read once, into memory."""

    def __init__(self, path, data=None):
        self.path = path
        self.data = data
        if data is not None:
            return
        try:
            with open(path, "rb") as fh:
                if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                    self.data = fh.read()
        except OSError as exc:
            raise self.error(exc) from exc

    def error(self, exc):
        return GCodeError("cannot read the G-code file: %s" % exc.strerror, file=self.path)

    def open(self):
        """The file from its start (binary)."""
        if self.data is not None:
            return io.BytesIO(self.data)
        try:
            return open(self.path, "rb")
        except OSError as exc:
            raise self.error(exc) from exc

    def lines(self, fh, raw=False):
        """:func:`iter_lines` of ``fh`` (the raw byte lines with ``raw``); a read error
        names the program (errors of whoever consumes the lines are theirs)."""
        try:
            yield from (fh if raw else iter_lines(fh))
        except OSError as exc:
            raise self.error(exc) from exc

    def line_lists(self, fh, chunk=1 << 14):
        """:func:`iter_line_lists` of ``fh``; a read error names the program."""
        try:
            yield from iter_line_lists(fh, chunk)
        except OSError as exc:
            raise self.error(exc) from exc

    def count_lines(self):
        """Newlines plus one (without reading the lines themselves)."""
        n = 0
        try:
            with self.open() as fh:
                for chunk in iter(lambda: fh.read(1 << 20), b""):
                    n += chunk.count(b"\n")
        except OSError as exc:
            raise self.error(exc) from exc
        return n + 1


class Compensator:
    """Compensates consecutive blocks of one program and adds up what the whole decides.

    Parameters are those of :func:`compensate_gcode`, plus ``sep`` and ``eol`` (the
    file's word separator and first line ending, :func:`file_sep`, :func:`default_eol`),
    ``keep_points`` (keep every output point for a :class:`GCodeResult`), ``names`` (of the
    segment length and arc tolerance in messages) and ``visit`` (called with each block's
    output points as ``visit(nominal (n, 3) mm, known (n,) bool)``: the programmed points
    of every command written, pieces of split moves and arcs included, as the bounds check
    sees them).
    """

    def __init__(self, model, segment_length=2.0, tolerance=1e-4, arc_tolerance=1e-3,
                 decimals=None, start=None, source=None, max_error=None, sep=" ", eol="\n",
                 keep_points=False, names=("segment length", "arc tolerance"), visit=None,
                 max_segments=MAX_SEGMENTS):
        check_lengths(segment_length, tolerance, arc_tolerance)
        self.model = model
        self.lengths = (segment_length, tolerance, arc_tolerance)
        self.source = source
        self.names = names
        self.visit = visit
        self.max_segments = max_segments
        self.dmin_mm = DEFAULT_DECIMALS["mm"] if decimals is None else int(decimals)
        self.dmin_in = DEFAULT_DECIMALS["in"] if decimals is None else int(decimals)
        self.start = start
        self.interp = _Interpreter(source, start, False)
        self.writer = _TextWriter(sep, eol, None if start is None
                                  else np.array(start, dtype=float).reshape(3),
                                  self.dmin_mm, self.dmin_in, source)
        self.totals = PointTotals(model)
        self.bounds = BoundsCheck(model, max_error)
        self.est = SegmentEstimate(0.0, 0.0, 0.0)
        self.n_lines = self.n_moves = self.n_points = 0
        self.inch = False
        self.words = False          # some line has a word
        self.points = [] if keep_points else None

    def lines(self, lines):
        """Read, interpret and compensate the next block of ``(content, ending)`` lines;
        its output text."""
        base = self.n_lines
        infos, runs = read_block(self.interp, lines, base, self.source)
        return self.program(self.interp.take_moves(infos, self.interp.warnings), lines, base,
                            runs)

    def prescan(self, blocks):
        """Refuse the program whose lines come in ``blocks`` (all of them, read before
        :meth:`lines` reads any) when it needs more than ``max_segments`` segments: the
        refusal :meth:`finish` would raise, without planning anything
        (:func:`.prescan.check_program_segments`)."""
        check_program_segments(blocks, self.lengths[0], self.lengths[2], self.max_segments,
                               self.names, self.start, self.source)

    def program(self, prog, lines, base, runs=()):
        """Compensate the interpreted block ``prog`` of ``lines`` (from line index ``base``
        on; ``runs`` of plain lines read as arrays, :func:`.plain.read_block`); its output
        text. Past the segment limit the rest is only counted."""
        self.n_lines = base + len(lines)
        self.words = self.words or not prog.is_empty()
        self.n_moves += prog.n_moves
        seg, tol, arc_tol = self.lengths
        self.est = self.est + estimate_segments(prog, seg, arc_tol)
        if self.est.total > self.max_segments:
            return ""
        self.inch = self.inch or bool((prog.factor != 1.0).any())
        still = np.where(prog.factor == 1.0, 0.5 * 10.0 ** -self.dmin_mm,
                         0.5 * 10.0 ** -self.dmin_in * prog.factor) * 0.999
        plan = plan_moves(prog, self.model, seg, tol, arc_tol, still,
                          max_segments=self.max_segments)
        w = self.writer
        w.block(prog, plan, base)
        out = write_block(w, lines, base, runs)
        nominal, emitted, known, line = w.state.take_points()
        self.n_points += line.size
        self.totals.add(nominal, emitted, known)
        if self.visit is not None:
            self.visit(nominal, known)
        self.bounds.add(nominal, emitted, line, self.resolution(False))
        if self.points is not None:
            self.points.append((nominal, emitted, known, line))
        return out

    def resolution(self, inch):
        """Largest rounding (mm) of a point written in mm (and inch)."""
        rounding = max(0.5 * 10.0 ** -self.dmin_mm,
                       25.4 * 0.5 * 10.0 ** -self.dmin_in if inch else 0.0)
        return math.sqrt(3.0) * rounding

    def finish(self):
        """Raise what the whole program is refused for: too many segments, a point out of
        bounds (:meth:`surfcomp.io.gcode.result.CompensationResult.check_bounds`)."""
        if self.est.total > self.max_segments:
            refuse_segments(self.est, self.n_moves, self.lengths[0], self.lengths[2],
                            self.max_segments, self.names, self.source)
        self.bounds.finish(self.resolution(self.inch), self.source)
        self.check_gain()

    def check_gain(self):
        """Refuse an output the model predicts to land farther from the programmed points
        than the input (numbers rounded more coarsely than the corrections they carry)."""
        before, after = self.totals.before.max, self.totals.after.max
        if not after > before + 1e-9:
            return
        dmin = self.dmin_in if self.inch else self.dmin_mm
        need = next((d for d in range(dmin + 1, 10) if self.resolution(self.inch)
                     * 10.0 ** (dmin - d) <= 0.1 * before), 9)
        raise GCodeError("the compensated program would be worse than the input: the error "
                         "model predicts up to %.4g um at the program's points after "
                         "compensation against %.4g um before, as its numbers are rounded to "
                         "%d decimal place(s) (up to %.4g um per point), too coarse for "
                         "corrections of up to %.4g um; nothing was written (expected a "
                         "rounding finer than the corrections: decimals %d or more)"
                         % (after * 1e3, before * 1e3, dmin, self.resolution(self.inch) * 1e3,
                            self.totals.max_correction * 1e3, need),
                         file=self.source, options=("decimals",))

    def warnings(self):
        """The warnings of the program read by :meth:`lines`."""
        return self.interp.warnings + self.interp.unknown_warnings()

    def stats(self):
        st = self.writer.state
        return st.stats(self.n_lines, self.n_lines + st.added, self.n_moves, self.n_points)

    def result(self, output, warnings, prog=None):
        """The :class:`GCodeResult` (``keep_points``)."""
        parts = self.points or [(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=bool),
                                 np.zeros(0, dtype=int))]
        nominal, emitted, known, line = (np.concatenate(p) for p in zip(*parts))
        return GCodeResult(output, self.stats(), nominal, emitted, known, list(warnings), prog,
                           line)


def compensate_stream(program, write, model, block_lines=None, **settings):
    """Compensate the program a block at a time, writing its output as it goes.

    Parameters
    ----------
    program : ProgramFile
        The program (read from its start for the separator style, the byte-order mark,
        the line ending, then the lines).
    write : callable
        Called with each piece of output text (Latin-1: one character per byte).
    model : surfcomp.core.axis.axis_errors.AxisErrorModel
    block_lines : int, optional
        Lines compensated at a time (default :data:`BLOCK_LINES`).
    **settings
        Of :class:`Compensator` (``source``, ``start`` ...).

    Returns
    -------
    Compensator
        Finished (:meth:`Compensator.finish` raised nothing); its ``words`` tell whether
        the program had any word, :meth:`Compensator.stats` and ``totals`` what was done.
    """
    def make(sep, eol):
        comp = Compensator(model, sep=sep, eol=eol, **settings)
        # the whole program's segment count first (no planning): a program that needs
        # too many is refused before any block is compensated or anything written
        comp.prescan(program_blocks(program, block_lines))
        return comp

    comp = stream_program(program, write, make, block_lines, settings.get("source"))
    comp.finish()
    return comp


def stream_program(program, write, make, block_lines=None, source=None):
    """Feed a :class:`ProgramFile` a block at a time to the worker ``make(sep, eol)``
    returns (its ``lines(block)`` gives each block's output text, passed to ``write``; or
    its ``run(blocks, write)`` does so), the byte-order mark first when the file has one;
    returns the worker."""
    sep, bom, eol = program_style(program, source)
    worker = make(sep, eol)
    if bom:
        write(BOM)
    run = getattr(worker, "run", None)      # a worker that drives the blocks itself
    if run is not None:
        run(program_blocks(program, block_lines), write)
        return worker
    for block in program_blocks(program, block_lines):
        write(worker.lines(block))
    return worker


def program_style(program, source=None):
    """``(sep, bom, eol)`` of a :class:`ProgramFile`: the word separator most lines use
    (:func:`file_sep`), whether it starts with a UTF-8 byte-order mark, and its first line
    ending (:func:`default_eol`)."""
    with program.open() as fh:
        sep = file_sep((c, tokenize(c, source, k + 1)[0])
                       for k, (c, _e) in enumerate(program.lines(fh)))
    with program.open() as fh:
        bom = next(program.lines(fh, raw=True), b"").startswith(_BOM_BYTES)
    with program.open() as fh:
        eol = default_eol(program.lines(fh))
    return sep, bom, eol


def program_blocks(program, block_lines=None):
    """The ``(content, ending)`` lines of a :class:`ProgramFile` in blocks of
    ``block_lines`` (default :data:`BLOCK_LINES`)."""
    block_lines = BLOCK_LINES if block_lines is None else max(1, int(block_lines))
    with program.open() as fh:
        block = []
        for part in program.line_lists(fh):
            block.extend(part)
            while len(block) >= block_lines:
                yield block[:block_lines]
                block = block[block_lines:]
        if block:
            yield block


def compensate_gcode(data, model, segment_length=2.0, tolerance=1e-4, arc_tolerance=1e-3,
                     decimals=None, start=None, source=None, progress=None, parsed=None,
                     max_error=None, block_lines=None):
    """Compensate a G-code program for a machine's axis errors.

    Parameters
    ----------
    data : bytes or str
        The program.
    model : surfcomp.core.axis.axis_errors.AxisErrorModel
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
    parsed : (Program, list), optional
        What :func:`surfcomp.io.gcode.parse_gcode` returned for the same ``data``,
        ``source`` and ``start``, when the caller has parsed the program already.
    max_error : float, optional
        Largest plausible machine error (mm): a programmed point where the model predicts
        more is refused (default no limit).
    block_lines : int, optional
        Compensate this many lines at a time (:func:`compensate_stream`; the result has no
        ``program``); default the whole program at once. The output is the same.

    Returns
    -------
    GCodeResult
        ``output`` (``data``) is the input unchanged, byte for byte, when the model is zero.

    Raises
    ------
    GCodeError
        For anything the compensation cannot handle correctly (see :mod:`surfcomp.io.gcode`),
        and for an output that moves a point farther than the model explains
        (:meth:`CompensationResult.check_bounds`): then nothing should be written.
    InputError
        Settings outside their domain, or more segments than
        :data:`surfcomp.core.axis.moves.MAX_SEGMENTS` (:func:`surfcomp.core.axis.moves.plan_moves`).
    """
    text = decode(data)
    bom = (data.decode("latin-1") if isinstance(data, (bytes, bytearray))
           else data).startswith(BOM)
    settings = dict(segment_length=segment_length, tolerance=tolerance,
                    arc_tolerance=arc_tolerance, decimals=decimals, start=start,
                    source=source, max_error=max_error, keep_points=True)
    report(progress, 0.0, "parsing")
    out = []
    if block_lines is not None:
        program = ProgramFile(source, (BOM if bom else "").encode("latin-1")
                              + text.encode("latin-1"))
        comp = compensate_stream(program, out.append, model, block_lines, **settings)
        report(progress, 1.0, "done")
        return comp.result("".join(out).encode("latin-1"), comp.warnings())
    if parsed is None:
        parsed = parse_gcode(text, source=source, start=start)
    prog, lines = parsed
    comp = Compensator(model, sep=file_sep((c, None if info is None else info.words)
                                           for (c, _e), info in zip(lines, prog.lines)),
                       eol=default_eol(lines), **settings)
    if bom:
        out.append(BOM)
    report(progress, 0.5, "writing")
    out.append(comp.program(prog, lines, 0))
    comp.finish()
    report(progress, 1.0, "done")
    return comp.result("".join(out).encode("latin-1"), prog.warnings, prog)
