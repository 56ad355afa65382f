# SPDX-License-Identifier: LGPL-2.1-or-later
"""One batch job: nominal face + measurement file -> corrected face (STEP), report (JSON).

Shared by ``python3 -m surfcomp compensate|inspect`` and the ``freecadcmd`` job macro.
All outputs of a job are written together or not at all.
"""

import json
import os
from dataclasses import dataclass, field, fields

import numpy as np

from ..core import budget
from ..core.compensation.pipeline import Options, compensate, prepare
from ..core.memory import return_free_memory
from ..core.progress import report as report_progress
from ..core.progress import sub
from ..errors import InputError, note
from ..io import report as report_io
from ..io.atomic import Transaction, check_outputs
from ..io.hashing import sha256_file
from ..io.outpath import shown
from ..io.readers import read_measured
from ..io.step_face import write_natural_face
from . import fcenv


@dataclass
class Job:
    """A compensation job (paths and options). ``output``/``report``/``points``/``curves``
    are optional outputs: corrected face (STEP/IGES/BREP by extension), JSON report,
    corrected points (CSV) and the papers' curve net through them (STEP).

    ``plan``: the measurement plan the probe log ``measurements`` was probed from, joined
    to it in order with ``touches`` log lines per point (:mod:`surfcomp.io.plan_join`).

    ``output`` holds the nominal's whole shape with the face replaced when the face sits in
    a solid or shell, the corrected face alone when it is a lone face or ``face_only``.

    The whole command-line job in one call (``surfcomp.Job``, ``surfcomp.run_job``; README
    "Scripting"): the fields are the job file's keys (README "freecadcmd"), ``options`` an
    :class:`Options` (``surfcomp.options(method="mirror", stock=0.2)``); ``face``,
    ``object``, ``units``, ``deviation_units``, ``fmt`` and ``sample`` pick the face and
    read the measurements as ``--face`` ... ``--sample`` do; ``align``, ``align_faces``,
    ``align_dof``, ``rps`` and ``transform`` align the points first (README "Alignment").
    :func:`run_job` returns ``(compensation, report)``.

    Example::

        job = Job(nominal="examples/nominal.step",
                  measurements="examples/measurements.csv",
                  output="out/corrected.step", report="out/report.json")
        comp, report = run_job(job)
    """

    nominal: str
    measurements: str
    command: str = "compensate"
    output: str = None
    report: str = None
    points: str = None
    curves: str = None
    html: str = None
    face: str = None
    object: str = None
    units: str = None
    deviation_units: str = None
    fmt: str = "auto"
    sample: str = None
    face_only: bool = False
    plan: str = None
    touches: int = 1
    align: str = "none"
    align_faces: str = None
    align_dof: str = None
    rps: str = None
    transform: str = None
    options: Options = field(default_factory=Options)

    @classmethod
    def from_dict(cls, data, base_dir="."):
        """A job from a JSON job file's dict; relative paths are relative to ``base_dir``.

        Unknown keys and commands, and keys that do nothing for the job's command, are
        refused."""
        known, opt_names = job_keys()
        unknown = set(data) - known - opt_names
        if unknown:
            raise InputError("unknown job file keys: %s (expected some of %s)"
                             % (", ".join(sorted(unknown)), ", ".join(sorted(known | opt_names))))
        command = data.get("command", "compensate")
        if command not in JOB_COMMANDS:
            raise InputError("\"command\": %s: a job file runs %s (simulate and gcode are "
                             "command-line only)" % (json.dumps(command), " or ".join(
                                 '"%s"' % c for c in JOB_COMMANDS)))
        inert = sorted(set(data) & set(INERT_KEYS.get(command, ())))
        if inert:
            raise InputError("%s: does nothing for \"command\": \"%s\" (it builds no face); "
                             "remove %s or use \"command\": \"compensate\""
                             % (", ".join('"%s"' % k for k in inert), command,
                                "it" if len(inert) == 1 else "them"))
        for key in ("nominal", "measurements"):
            if key not in data:
                raise InputError("the job file needs %r" % key)
        kw = {k: data[k] for k in known if k in data}
        for k, _role, _label in JOB_FILES:
            if kw.get(k) and kw[k] != "-":
                kw[k] = os.path.join(base_dir, kw[k])
        if kw.get("rps") and os.path.isfile(os.path.join(base_dir, kw["rps"])):
            kw["rps"] = os.path.join(base_dir, kw["rps"])     # a file, not inline ids
        kw["options"] = Options(**{k: data[k] for k in opt_names if k in data})
        return cls(**kw)


def job_keys():
    """``(job keys, option keys)`` a job file may hold: :class:`Job`'s fields and the
    :class:`Options` fields a user sets (not ``context``, which says who reads messages).
    Each has a type in :data:`surfcomp.io.jobfile.KEY_TYPES` (a test checks it)."""
    return ({f.name for f in fields(Job)} - {"options"},
            {f.name for f in fields(Options)} - {"context"})


#: the commands a job file runs
JOB_COMMANDS = ("compensate", "inspect")
#: the files of a job: (attribute of :class:`Job`, role, name in messages). Messages name
#: each as its job key (a script's ``Job`` field, a job file's key), which the command line
#: shows as its flag or argument (``-o``, ``NOMINAL``; :mod:`surfcomp.cli.option_flags`)
JOB_FILES = tuple((attr, role, note((attr,))) for attr, role in (
    ("nominal", "input"), ("measurements", "input"), ("plan", "input"),
    ("output", "output"), ("report", "output"), ("points", "output"), ("curves", "output"),
    ("html", "output"), ("transform", "input")))
#: ignored measurement columns named in the report (the rest are counted)
IGNORED_LISTED = 100

#: the outputs of a job: (attribute of :class:`Job`, command-line option)
OUTPUT_OPTIONS = tuple((attr, label) for attr, role, label in JOB_FILES if role == "output")
#: job keys that do nothing for a command (refused)
INERT_KEYS = {"inspect": ("output", "points", "curves", "face_only", "refine", "lean")}


def declared_outputs(job):
    """``(option, path)`` of every output the job writes."""
    return [(option, getattr(job, attr)) for attr, option in OUTPUT_OPTIONS
            if getattr(job, attr) is not None]


def declared_inputs(job):
    return [(label, getattr(job, attr)) for attr, role, label in JOB_FILES if role == "input"]


def run_job(job, progress=None, inputs=(), max_memory=None):
    """Run ``job``; return ``(compensation, report_dict)``. Writes the requested outputs.

    The outputs are checked against the inputs (the job's and ``inputs``, e.g. the job
    file) and each other before anything is read, and written together at the end
    (:class:`surfcomp.io.atomic.Transaction`). A job whose estimated peak memory (from its
    number of points) is above ``max_memory`` (bytes; None: the machine's memory) is
    refused once the points are read, before the work (:mod:`surfcomp.core.budget`).
    """
    outputs, inputs = declared_outputs(job), declared_inputs(job) + list(inputs)
    check_outputs(outputs, inputs)
    job.options.validate()
    for attr in ("output", "curves"):
        if getattr(job, attr):
            cad_format(getattr(job, attr), dict(OUTPUT_OPTIONS)[attr])
    fcenv.import_freecad()
    from .nominal import load_nominal

    nominal = load_nominal(job.nominal, job.face, job.object)
    if job.command == "compensate" and job.output:
        from .shapes import check_rebuildable

        check_rebuildable(nominal.bspline_face, job.nominal)
    ms = read_measured(job)
    budget.check_job(len(ms), job.command == "compensate", max_memory)
    alignment, read = None, ms          # the report counts the file's points
    if job.align not in (None, "none") or job.transform or job.rps or job.align_faces \
            or job.align_dof:
        from .alignment import align_measurements

        ms, alignment = align_measurements(job, nominal, ms, progress=sub(progress, 0, 0.1))
    prepared = prepare(nominal.surface, nominal.outward, ms, job.options,
                       progress=sub(progress, 0, 0.3))
    _face_warnings(nominal, prepared)
    if alignment is not None:
        prepared.warnings.extend(alignment.warnings)
    build = job.command == "compensate"
    comp = compensate(nominal.surface, nominal.outward, prepared, job.options, build=build,
                      progress=sub(progress, 0.3, 0.9))
    # everything is computed before the first file is staged
    shapes, output = {}, None
    if build and job.output:
        from .shapes import corrected_shape

        report_progress(progress, 0.9, "building the output shape")
        output = corrected_shape(nominal, comp.corrected, "face" if job.face_only else "solid",
                                 nominal.face_name)
        prepared.warnings.extend(output.warnings(nominal.face_name))
        shapes["output"] = output.shape
    rep = report_io.build_report(job.command, _inputs_record(job, nominal, read), comp,
                                 prepared.warnings,
                                 {attr: shown(getattr(job, attr))
                                  for attr, _opt in OUTPUT_OPTIONS if getattr(job, attr)},
                                 points=bool(job.report or job.html),
                                 output_shape=output.as_dict() if output else None)
    rep["alignment"] = alignment.as_dict() if alignment is not None else None
    if build and job.curves:
        shapes["curves"] = curve_net(comp)
    return_free_memory()    # the shape's conversions, before the CAD writer's gigabyte
    with Transaction(outputs, inputs) as tx:
        for attr, shape in shapes.items():
            path = getattr(job, attr)
            name = os.path.splitext(os.path.basename(path))[0]     # not the staged file's
            tmp = tx.write(path, lambda tmp, shape=shape, attr=attr, name=name:
                           write_face(tmp, shape, output if attr == "output" else None, name))
            if attr == "output":        # the report states the size of the written face
                rep["output_shape"]["file_bytes"] = os.path.getsize(tmp)
        if job.report:      # streamed: a million points' JSON is never one string
            tx.write(job.report, lambda tmp: report_io.write_file(rep, tmp))
        for attr, text in _texts(job, comp, rep).items():
            tx.stage_text(getattr(job, attr), text)
        tx.commit()
    return comp, rep


def _texts(job, comp, rep):
    """The text outputs of ``job`` (points CSV, HTML report) by attribute; the JSON report
    is written by :func:`surfcomp.io.report.write_file`."""
    texts = {}
    if job.points:
        texts["points"] = corrected_points_csv(comp)
    if job.html:
        from ..io.html_report import render_html  # only here: its import is not free

        texts["html"] = render_html(rep)
    return texts


def _face_warnings(nominal, prepared):
    from .nominal import face_warnings

    prepared.warnings.extend(face_warnings(nominal, prepared))


def _inputs_record(job, nominal, ms):
    surface = nominal.surface
    return {
        "nominal": {"path": os.path.abspath(job.nominal), "sha256": sha256_file(job.nominal),
                    "face": nominal.face_name, "object": nominal.object_name,
                    "surface": nominal.converted or "BSplineSurface",
                    "poles": list(surface.shape),
                    "degree": [surface.degree_u, surface.degree_v],
                    "rational": surface.weights is not None,
                    "u_range": list(surface.u_range), "v_range": list(surface.v_range)},
        "measurements": {"path": os.path.abspath(job.measurements), "sha256": ms.sha256,
                         "units": ms.units, "kind": ms.kind(), "points": len(ms),
                         "columns": dict(ms.columns),
                         # the first names only: a table may have a million extra columns
                         "ignored_columns": list(ms.ignored_columns[:IGNORED_LISTED]),
                         "ignored_column_count": len(ms.ignored_columns)},
        **({"plan": {"path": os.path.abspath(job.plan), "sha256": sha256_file(job.plan),
                     "touches": job.touches}} if job.plan else {}),
    }


def corrected_face(comp, nominal):
    """The corrected face: the nominal face's boundary (trim, holes) on the corrected
    surface, with the nominal's orientation (:func:`surfcomp.app.shapes.corrected_shape`)."""
    from .shapes import corrected_shape

    return corrected_shape(nominal, comp.corrected, "face", nominal.face_name).shape


def curve_net(comp):
    """The papers' construction aid: B-spline curves through the corrected points along
    both grid directions (Werner Fig. 3b), as a compound of edges."""
    import FreeCAD
    import Part

    if comp.prepared.scattered:
        raise InputError(note(("curves",), " needs a measurement grid (the curve net runs "
                              "along its rows and columns); these points are scattered"))
    pts = comp.prepared.grid.take(comp.corrected_points())
    edges = []
    for line in list(pts) + list(pts.transpose(1, 0, 2)):
        c = Part.BSplineCurve()
        c.interpolate([FreeCAD.Vector(*p) for p in line.tolist()])
        edges.append(c.toShape())
    return Part.Compound(edges)


#: CAD output formats by file extension
CAD_FORMATS = {".step": "step", ".stp": "step", ".iges": "iges", ".igs": "iges",
               ".brep": "brep", ".brp": "brep"}


def cad_format(path, option="output"):
    """The CAD format of an output file from its extension (checked before any work)."""
    ext = os.path.splitext(path)[1].lower()
    if ext not in CAD_FORMATS:
        raise InputError(option + ": unsupported file type %r (expected .step, .iges or "
                         ".brep)" % ext, file=path)
    return CAD_FORMATS[ext]


def write_face(path, shape, output=None, name=None):
    """Write a shape as STEP, IGES or BREP, chosen by the file extension of ``path``.

    ``output``: the :class:`surfcomp.app.shapes.Output` of ``shape``; a face bounded by its
    surface's knot domain (``output.natural``) goes to STEP from its pole net
    (:mod:`surfcomp.io.step_face`, faster than OpenCASCADE's writer), its product
    named ``name`` (default: the file's name).
    """
    import Part

    fmt = cad_format(path)
    if fmt == "step" and output is not None and output.natural is not None:
        write_natural_face(path, output.natural, shape.Orientation == "Reversed",
                           output.edge_tolerance, name)
        return
    try:
        {"step": shape.exportStep, "iges": shape.exportIges, "brep": shape.exportBrep}[fmt](path)
    except (Part.OCCError, RuntimeError) as exc:
        # OpenCASCADE's writers report a full disk or a write error only as this
        raise InputError("OpenCASCADE could not write the %s file: %s (a full disk, or no "
                         "permission to write there?)" % (fmt.upper(), exc), file=path) from None
    if not os.path.getsize(path):
        raise InputError("OpenCASCADE wrote an empty file", file=path)


def corrected_points_csv(comp):
    """Corrected points (Werner eq. 2/3) as CSV in file order, with grid indices (-1 for
    scattered points)."""
    p = comp.prepared
    row, col = p.row_col()
    if row is None:  # scattered: no grid indices
        row = col = np.full(p.u.size, -1)
    cor = comp.corrected_points()
    delta = comp.per_point("delta")
    rows = ["row,col,x_nom,y_nom,z_nom,i,j,k,correction,x_cor,y_cor,z_cor"]
    for k in range(p.u.size):
        rows.append("%d,%d,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.6f,%.6f,%.6f,%.6f"
                    % ((row[k], col[k]) + tuple(p.nominal[k]) + tuple(p.normal[k]) + (delta[k],)
                       + tuple(cor[k])))
    return "\n".join(rows) + "\n"


def load_job_file(path):
    """Read a JSON job file (see README, 'freecadcmd'): a regular UTF-8 file of bounded
    size and nesting whose known keys hold values of their type
    (:func:`surfcomp.io.jobfile.read_job_file`)."""
    from ..io.jobfile import read_job_file

    data = read_job_file(path)
    try:
        return Job.from_dict(data, os.path.dirname(os.path.abspath(path)))
    except InputError as exc:
        if exc.file is None:            # about the job file's keys: name the job file
            exc.file = path
        raise
