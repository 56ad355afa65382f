# SPDX-License-Identifier: LGPL-2.1-or-later
"""Direct program compensation: nominal + measurements + finishing program -> moved program.

``compensate NOMINAL MEAS --program FINISH.ngc --tool ball:R -o FINISH_COMP.ngc``: the
compensation is computed as for ``-o`` (:func:`surfcomp.core.compensation.pipeline.compensate`, the
corrected surface built), and the finishing program is moved by the correction the
corrected face realises at each cutter-location point's contact
(:mod:`surfcomp.core.compensation.program_offset`, :mod:`surfcomp.io.gcode.offset_stream`) instead
of regenerating the CAM operation on the corrected face. The program is written atomically,
never over an input; nothing is written when it is refused.
"""

from dataclasses import dataclass

from ..core import budget
from ..core.command_options import PROGRAM_MOVE
from ..core.compensation.pipeline import compensate, prepare
from ..core.compensation.program_offset import CONTACT_TOL, parse_tool
from ..core.progress import report, sub
from ..io.atomic import Transaction
from ..io.gcode import ProgramFile
from ..io.gcode.offset_stream import FORK_LINES, offset_stream
from ..io.readers import read_measured
from . import cadread, fcenv
from .nominal import face_warnings, load_nominal, nominal_from_data
from .program_geometry import offset_of


@dataclass
class ProgramJob:
    """What :func:`run_program_job` moves: the compensation job's inputs and options
    (:class:`surfcomp.app.file_route.Job`), the program, the tool and the output.

    ``tolerance``, ``segment_length`` (mm) and ``decimals``: as
    :func:`surfcomp.core.compensation.program_offset.plan_offset` and
    :class:`surfcomp.io.gcode.offset_stream.ProgramOffset` take them; ``blend`` (mm): of
    :class:`surfcomp.core.compensation.program_offset.BallOffset`."""

    job: object
    program: str
    output: str
    tool: str
    blend: float = PROGRAM_MOVE["blend"].default
    tolerance: float = PROGRAM_MOVE["tolerance"].default
    segment_length: float = PROGRAM_MOVE["segment_length"].default
    decimals: int = None


def run_program_job(pj, outputs, inputs, progress=None, max_memory=None):
    """Compensate, move the program and write it; returns ``(compensation, ProgramOffset)``.

    ``outputs`` and ``inputs`` as :class:`surfcomp.io.atomic.Transaction` takes them (the
    command line's :func:`surfcomp.cli.registry.declared`)."""
    _kind, radius = parse_tool(pj.tool)
    job = pj.job
    job.options.validate()
    nominal = _nominal(job)
    ms = read_measured(job)             # a probe log joined to its plan, as -o
    budget.check_job(len(ms), True, max_memory)
    program = ProgramFile(pj.program)
    lines = program.count_lines()
    budget.check(budget.gcode_bytes(lines), max_memory, "the program's %d lines" % lines,
                 "split the program into parts")
    prepared = prepare(nominal.surface, nominal.outward, ms, job.options,
                       progress=sub(progress, 0, 0.3))
    prepared.warnings.extend(face_warnings(nominal, prepared))
    comp = compensate(nominal.surface, nominal.outward, prepared, job.options,
                      progress=sub(progress, 0.3, 0.7))
    offset = offset_of(nominal, comp.corrected, radius, pj.blend)
    report(progress, 0.7, "moving the program")
    done = []
    with Transaction(outputs, inputs) as tr:
        def put(tmp):
            with open(tmp, "wb") as fh:
                done.append(offset_stream(
                    program, lambda text: fh.write(text.encode("latin-1")), offset,
                    tolerance=pj.tolerance, segment_length=pj.segment_length,
                    decimals=pj.decimals, source=pj.program, max_memory=max_memory,
                    fork=lines >= FORK_LINES))

        tr.write(pj.output, put)
        tr.commit()
    report(progress, 1.0, "done")
    return comp, done[0]


def _nominal(job):
    """The job's :class:`surfcomp.app.nominal.Nominal`: the face the reader child sent
    (:func:`surfcomp.app.cadread.prefetch_face`; FreeCAD is not imported here), else the
    face loaded in this process."""
    data = None if job.object else cadread.take_face(job.nominal, job.face)
    if data is not None:
        return nominal_from_data(data, job.nominal)
    fcenv.import_freecad()
    return load_nominal(job.nominal, job.face, job.object)


def summary_lines(comp, po, pj):
    """What the run did, for standard output, then the program's warnings (``warning:
    FILE: ...``, for standard error)."""
    st = po.stats()
    corr = comp.statistics["correction"]
    fit = po.fit
    lines = ["Correction:   %s" % _range(corr),
             "Program:      %s (%d lines, %d moves; ball radius %g mm)"
             % (pj.program, st["lines_in"], st["moves"], po.offset.radius),
             "Moved:        %d moves (%d lines changed, %d added, %d arcs turned into lines); "
             "largest move %.2f um; the displacement computed at %d points (tolerance %g um, "
             "blend %g mm)"
             % (st["moves_moved"], st["lines_changed"], st["lines_added"],
                st["arcs_converted"], st["largest_move_mm"] * 1e3, st["points_evaluated"],
                pj.tolerance * 1e3, pj.blend),
             "Contact:      %d cutter-location points on the face, %.2f um off the ball's "
             "offset on average; %s"
             % (fit.points, fit.stock * 1e3, _radius_text(fit, po.offset.radius))]
    return lines + ["warning: " + w for w in _radius_warnings(fit, po.offset.radius, pj.program)
                    + ["%s: %s" % (pj.program, w) for w in po.warnings()]]


#: a ball radius off the one the contact points fit by more than this share of it, with an
#: effect on the slopes above :data:`RADIUS_WARN_EFFECT` (mm; a quarter of the refusal's
#: CONTACT_TOL, well above a CAM tolerance's scatter), is warned about
RADIUS_WARN_SHARE = 0.01
RADIUS_WARN_EFFECT = 0.25 * CONTACT_TOL


def _radius_text(fit, radius):
    """The radius check's result: the radius the contact points fit against the one given."""
    if fit.radius_error is None:
        return "the radius is not checked (slopes below 8 degrees)"
    return ("the points fit a ball of radius %.3f mm, %.1f um from the %g mm given (%.1f um "
            "on slopes up to %.1f degrees)" % (radius + fit.radius_error, fit.radius_error * 1e3,
                                               radius, fit.radius_effect * 1e3, fit.max_tilt))


def _radius_warnings(fit, radius, program):
    """A warning when the contact points clearly fit another ball than the one given, by
    less than the contact check refuses (on gentle slopes a radius error barely shows)."""
    if fit.radius_error is None or abs(fit.radius_error) <= RADIUS_WARN_SHARE * radius \
            or fit.radius_effect <= RADIUS_WARN_EFFECT:
        return []
    return ["%s: the program's cutter-location points fit a ball of radius %.3f mm, not the "
            "%g mm given (%.4f mm off on slopes up to %.1f degrees, within the %g mm accepted); "
            "expected the ball radius the program was made with"
            % (program, radius + fit.radius_error, radius, fit.radius_effect, fit.max_tilt,
               CONTACT_TOL)]


def _range(stats):
    return ("%.2f to %.2f um at the measured points (RMS %.2f um)"
            % (stats.min * 1e3, stats.max * 1e3, stats.rms * 1e3))
