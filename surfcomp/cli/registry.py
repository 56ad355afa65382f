# SPDX-License-Identifier: LGPL-2.1-or-later
"""The command line's file options in one table: what each command reads and writes.

Every option naming a file is defined here once, with its role (``input`` or ``output``)
and the name messages use for it. The commands add their options from this table
(:func:`add_options`) and :func:`declared` turns a parsed command line into the outputs and
inputs :func:`surfcomp.io.atomic.check_outputs` compares, so an input option added here is
guarded against every output without further code. Options that name no file may be added
with the role ``option``: :func:`add_plain_options` adds them to each command's parser after
the command's own options, so one entry here is all such an option needs.
"""

from dataclasses import dataclass, field

from ..core.option_tables import ALIGN, INPUTS
from .options import kwargs


@dataclass(frozen=True)
class Entry:
    """One command-line option of one or more commands.

    ``flags``: argparse's names (a positional's name alone); ``role``: ``input``,
    ``output`` or ``option``; ``label``: the name in messages (``NOMINAL``, ``-o``);
    ``kwargs``: argparse's keyword arguments; ``group``: the title of the argument group it
    is listed under (None: the command's own options); ``waiver``: the option (dest) that
    lets ``waived_for`` outputs replace this input, with ``waiver_label`` naming it then."""

    commands: tuple
    flags: tuple
    role: str
    label: str
    kwargs: dict = field(default_factory=dict)
    group: str = None
    waiver: str = None
    waived_for: tuple = ()
    waiver_label: str = None

    @property
    def dest(self):
        if "dest" in self.kwargs:
            return self.kwargs["dest"]
        name = next((f for f in self.flags if f.startswith("--")), self.flags[0])
        return name.lstrip("-").replace("-", "_")


def _memory_size(text):
    """argparse type of ``--max-memory``: bytes (:func:`surfcomp.core.budget.parse_size`)."""
    import argparse

    from ..core.budget import parse_size
    from ..errors import InputError

    try:
        return parse_size(text)
    except InputError as exc:
        raise argparse.ArgumentTypeError(exc.message.split(": ", 1)[1]) from None


def _kw(name, table=ALIGN):
    """argparse's keywords of a registry option (:mod:`surfcomp.core.option_tables`)."""
    return kwargs(name, table)


JOB = ("compensate", "inspect")
DOCUMENT = "shop document (NOMINAL is an .FCStd)"
SIM_MODEL = "machining-process model (mm)"
PROGRAM = "direct program compensation (ball-end finishing program)"
SIM_OUTPUT = "output"
PROBE_PROGRAM = "probing program"
_NOMINAL_HELP = "nominal face: STEP/IGES/BREP file or FreeCAD document (.FCStd)"

ENTRIES = (
    # ------------------------------------------------------------------ compensate, inspect
    Entry(JOB, ("nominal",), "input", "NOMINAL", dict(metavar="NOMINAL", help=_NOMINAL_HELP),
          waiver="overwrite_input", waived_for=("--save",),
          waiver_label="document (--overwrite-input allows it)"),
    Entry(JOB, ("measurements",), "input", "MEASUREMENTS",
          dict(metavar="MEASUREMENTS",
               help="measurement file (CSV/text; see README 'Measurement files')")),
    Entry(JOB, ("--plan",), "input", "--plan",
          dict(metavar="PLAN.csv",
               help="the measurement plan MEASUREMENTS (a probe log) was probed from: the "
                    "log's lines are its points in order, each tip centre taken back by "
                    "--tip-radius along the plan's normal (README 'On-machine probing')")),
    Entry(("compensate",), ("-o", "--output"), "output", "-o",
          dict(metavar="OUT.step",
               help="the nominal's shape with the face replaced by the corrected face (its "
                    "neighbours re-trimmed), or the corrected face when the nominal is a "
                    "lone face (STEP; .iges/.brep by extension); with --program the moved "
                    "program (OUT.ngc)")),
    Entry(("compensate",), ("--program",), "input", "--program",
          dict(metavar="FINISH.ngc",
               help="move this ball-end finishing program (G-code, mm, absolute) by the "
                    "correction instead of writing the corrected face; -o names the moved "
                    "program"), group=PROGRAM),
    Entry(JOB, ("--report",), "output", "--report",
          dict(metavar="OUT.json", help="write the JSON report (- for standard output)")),
    Entry(("compensate",), ("--points",), "output", "--points",
          dict(metavar="OUT.csv", help="also write the corrected points (CSV)")),
    Entry(("compensate",), ("--curves",), "output", "--curves",
          dict(metavar="OUT.step",
               help="also write the curve net through the corrected points (Werner Fig. 3b)")),
    Entry(JOB, ("--html",), "output", "--html",
          dict(metavar="OUT.html", help="also write the self-contained HTML inspection report")),
    Entry(("compensate",), ("--save",), "output", "--save",
          dict(metavar="OUT.FCStd", help="save the updated document here"), group=DOCUMENT),
    Entry(("compensate",), ("--gcode",), "output", "--gcode",
          dict(metavar="OUT.ngc",
               help="post the regenerated program of the Job using the compensation"),
          group=DOCUMENT),
    # ------------------------------------------------------------------ alignment (job commands)
    # (flags, defaults, choices and help from the option registry's ALIGN table)
    Entry(JOB + ("simulate",), ("--transform",), "input", "--transform", _kw("transform")),
    Entry(JOB + ("simulate",), ("--align",), "option", "--align", _kw("align")),
    Entry(JOB, ("--align-faces",), "option", "--align-faces", _kw("align_faces")),
    Entry(JOB + ("simulate",), ("--align-dof",), "option", "--align-dof", _kw("align_dof")),
    Entry(JOB + ("simulate",), ("--rps",), "option", "--rps", _kw("rps")),
    # ------------------------------------------------------------------ simulate
    Entry(("simulate",), ("nominal",), "input", "NOMINAL",
          dict(metavar="NOMINAL", nargs="?",
               help=_NOMINAL_HELP + "; optional with --preset (the preset's own surface)")),
    Entry(("simulate",), ("--axis-errors",), "input", "--axis-errors",
          dict(metavar="ERR.csv",
               help="per-axis error measurements (as for the gcode command); the fitted "
                    "Dobariya 2015 model adds its error along the normal"), group=SIM_MODEL),
    Entry(("simulate",), ("--plan",), "input", "--plan",
          dict(metavar="PLAN.csv",
               help="measure the simulated parts at this plan's points (python3 -m surfcomp "
                    "plan)"), group="measurement plan (instead of the --grid nodes)"),
    Entry(("simulate",), ("--json",), "output", "--json",
          dict(metavar="OUT.json", help="write every replica's statistics (JSON)"),
          group=SIM_OUTPUT),
    Entry(("simulate",), ("--html",), "output", "--html",
          dict(metavar="OUT.html",
               help="write the HTML report of the first replica's compensation with the "
                    "--report-method, the before/after table, the paper's table beside the "
                    "simulated one (--preset) and the simulated parts' maps"),
          group=SIM_OUTPUT),
    # ------------------------------------------------------------------ plan
    Entry(("plan",), ("nominal",), "input", "NOMINAL",
          dict(metavar="NOMINAL", help=_NOMINAL_HELP)),
    Entry(("plan",), ("-o", "--output"), "output", "-o",
          dict(required=True, metavar="PLAN.csv",
               help="the plan: id, nominal XYZ, outward normal IJK (mm), in visiting order")),
    Entry(("plan",), ("--dropped",), "output", "--dropped",
          dict(metavar="OUT.csv", help="also write every dropped point with its reason")),
    Entry(("plan",), ("--program",), "output", "--program",
          dict(metavar="PROBE.ngc",
               help="also write the probing program of the plan (tip-centre positions, in "
                    "the plan's order; README 'On-machine probing')"), group=PROBE_PROGRAM),
    # ------------------------------------------------------------------ gcode
    Entry(("gcode",), ("program",), "input", "IN.ngc",
          dict(metavar="IN.ngc", help="G-code program (G0/G1/G2/G3, 3 axes)")),
    Entry(("gcode",), ("--axis-errors",), "input", "--axis-errors",
          dict(required=True, metavar="ERR.csv",
               help="per-axis error measurements: 'axis,position,ex,ey,ez' rows or "
                    "'X EXX EYX EZX' tables (docs/axis_errors.md)")),
    Entry(("gcode",), ("-o", "--output"), "output", "-o",
          dict(required=True, metavar="OUT.ngc",
               help="compensated program (written atomically; - for standard output)")),
    Entry(("gcode",), ("--report",), "output", "--report",
          dict(metavar="OUT.json", help="write the JSON report")),
    Entry(JOB, ("--touches",), "option", "--touches", _kw("touches", INPUTS)),
    # ------------------------------------------------------------------ every command
    Entry(("compensate", "inspect", "simulate", "gcode"), ("--max-memory",), "option",
          "--max-memory",
          dict(type=_memory_size, default=None, metavar="SIZE",
               help="refuse the run, before the work, when its estimated peak memory is "
                    "larger than SIZE (e.g. 4G, 512M; default: the machine's memory)")),
)


def entries(command, role=None):
    """The entries of ``command`` (with ``role`` only, when given), in table order."""
    return [e for e in ENTRIES if command in e.commands and role in (None, e.role)]


def add_options(parser, command, groups=None, flags=None):
    """Add ``command``'s file options of the table to ``parser`` (``groups``: argument groups
    by title; ``flags``: only the entries whose first flag is among them)."""
    groups = groups or {}
    for e in entries(command):
        if e.role == "option" or flags is not None and e.flags[0] not in flags:
            continue
        groups.get(e.group, parser).add_argument(*e.flags, **e.kwargs)


def add_plain_options(parser, command):
    """Add ``command``'s entries with the role ``option`` (no file) to its parser."""
    for e in entries(command, "option"):
        parser.add_argument(*e.flags, **e.kwargs)


def declared(args, command=None):
    """``(outputs, inputs)`` of a parsed command line for
    :func:`surfcomp.io.atomic.check_outputs`: ``(option, path)`` of every output given and
    ``(what, path, options allowed to replace it)`` of every input."""
    command = command or args.command
    outputs = [(e.label, getattr(args, e.dest, None)) for e in entries(command, "output")]
    given = {label for label, path in outputs if path is not None}
    inputs = []
    for e in entries(command, "input"):
        what, allowed = e.label, ()
        if e.waiver and given & set(e.waived_for):
            if getattr(args, e.waiver, False):
                allowed = e.waived_for
            else:
                what = e.waiver_label
        inputs.append((what, getattr(args, e.dest, None), allowed))
    return [o for o in outputs if o[1] is not None], inputs


def wants_stdout(args, command=None):
    """Whether an output of the command line is ``-`` (standard output)."""
    return any(path == "-" for _opt, path in declared(args, command)[0])
