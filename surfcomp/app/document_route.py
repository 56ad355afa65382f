# SPDX-License-Identifier: LGPL-2.1-or-later
"""The batch route on a shop document: compensate a face in an FCStd, replace the nominal,
let Path regenerate, save a new document and (optionally) post the G-code.

    python3 -m surfcomp compensate DOC.FCStd MEAS.csv --object O --face F --replace \\
        --save OUT.FCStd [--gcode OUT.ngc --post linuxcnc]

Safety rules:

- Path and OpenCamLib are set up *before* the document is opened
  (:func:`surfcomp.app.cam.setup_workbench`), and the document is opened through
  :func:`surfcomp.app.documents.open_for_update` (Document.xml checked, only trusted proxy
  modules imported): an object whose module cannot be imported at open time loses its
  proxy, and a document saved like that can never recompute that object again. Such
  documents are refused (nothing is written); so is a document already open in this
  FreeCAD session, which FreeCAD would hand back instead of reading the file, so that the
  route would change the user's open document.
- The outputs are checked against the inputs and each other before the document is
  opened; the input document is never overwritten unless ``overwrite_input=True``.
- All outputs (document, G-code) are written together or not at all (temporary files
  renamed at the end); after any failure nothing is written.
"""

import json
import os
from dataclasses import dataclass, field

from ..core import budget
from ..core.compensation.pipeline import Options
from ..core.progress import report
from ..errors import ComputationError, GeometryError, InputError
from ..io.atomic import Transaction, check_outputs
from ..io.fcstd import parse_document
from ..io.outpath import shown
from ..io.readers import read_any
from . import align_doc, cam, cam_job, features, toolpaths
from . import progress as recompute_order
from .documents import open_for_update, restore_failures
from .properties import store_options


@dataclass
class DocumentJobResult:
    """What :func:`run_document_job` did (names are document object names)."""

    document: str
    compensation: str
    measurement: str
    replaced: list = field(default_factory=list)       # (object, property) rebound
    jobs: list = field(default_factory=list)           # Path jobs that use the compensation
    operations: list = field(default_factory=list)     # their operations that regenerated
    toolpaths: list = field(default_factory=list)      # surfcomp.app.toolpaths.JobReport
    saved: str = None
    gcode: str = None
    gcode_lines: int = 0
    statistics: dict = field(default_factory=dict)
    checks: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    output: str = "face"                               # the feature's Output
    volume_change: float = 0.0                         # mm^3 (solid output)
    correction_volume: float = 0.0                     # mm^3, integral of the correction
    alignment: list = field(default_factory=list)      # the compensation's Alignment lines
    alignment_warnings: list = field(default_factory=list)
    base: str = None                                   # the previous round (iterations)
    round: int = 1



def check_restored(doc, refused, info, document):
    """Refuse a document some objects of which did not restore (``refused``, ``info`` as
    :func:`surfcomp.app.documents.open_document` returns them): saving it would lose them."""
    problems = restore_failures(doc, info=info)
    if problems:
        why = "".join("; module %s %s" % item for item in sorted(refused.items()))
        raise InputError("%d object(s) did not restore, so the document cannot be updated "
                         "safely (saving would lose them): %s%s"
                         % (len(problems), "; ".join(problems), why), file=document)

def _find_object(doc, name, source):
    obj = doc.getObject(name) or next((o for o in doc.Objects if o.Label == name), None)
    if obj is None:
        names = ", ".join(o.Name for o in doc.Objects
                          if hasattr(o, "Shape") and not o.Shape.isNull()) or "none"
        raise GeometryError("no object %r in the document (objects with shapes: %s)"
                            % (name, names), file=source)
    if not hasattr(obj, "Shape") or obj.Shape.isNull() or not obj.Shape.Faces:
        raise GeometryError("object %r has no faces" % name, file=source)
    return obj


def _round_of(doc, obj, face, replace, source):
    """``(nominal, base)``: ``obj`` itself and no base, or, when ``obj`` is a compensation,
    its nominal and ``obj`` (the new compensation is its next round: deviations stay against
    the nominal, the correction adds to the earlier rounds').

    Raises
    ------
    InputError
        ``obj`` is a region object, a compensation not computed or of another face than
        ``face``; or (with ``replace``) a nominal that a compensation replaces now: its users
        cut that compensation's corrected face, so a new first round would find nothing to
        replace, and measuring the part they machined asks for that compensation's next round.
    """
    from . import replace as replace_mod
    from .region_doc import is_region

    if is_region(obj):
        raise InputError("%s is a region compensation: add its next round with --faces "
                         "(expected a single-face compensation or the nominal's object)"
                         % obj.Label, file=source)
    if not features.is_compensation(obj):
        replacing = [o.Label for o in doc.Objects if replace_mod.is_replacing(o)
                     and getattr(o, "Nominal", None) is obj]
        if replace and replacing:
            raise InputError("%s is replaced by %s now (its users cut that corrected face), so "
                             "there is nothing of %s to replace; expected --object %s for the "
                             "next round of %s, or restore the nominal first"
                             % (obj.Label, ", ".join(replacing), obj.Label, replacing[0],
                                replacing[0]), file=source)
        return obj, None
    features.chain(obj)
    if face and face != obj.FaceName:
        raise InputError("%s compensates %s.%s, not %s: its next round compensates the same "
                         "face (expected --face %s or none)"
                         % (obj.Label, obj.Nominal.Label, obj.FaceName, face, obj.FaceName),
                         file=source)
    if obj.Shape.isNull() or {"Invalid", "Error"} & set(obj.State):
        raise InputError("%s is not computed (state %s): its next round stacks on its "
                         "correction; recompute it first" % (obj.Label, ", ".join(obj.State)),
                         file=source)
    return obj.Nominal, obj


def _jobs_using(doc, comp):
    jobs = []
    for job in cam_job.jobs_of(doc):
        if any(comp in list(getattr(c, "Objects", []) or []) or c is comp for c in job.Model.Group):
            jobs.append(job)
    return jobs


def run_document_job(document, measurements, object_name, face=None, save=None, replace=True,
                     gcode=None, post="linuxcnc", post_args="--no-show-editor", job_name=None,
                     units="mm", options=None, output=None, overwrite_input=False,
                     fmt="auto", sample=None,
                     progress=None, deviation_units=None, max_memory=None, align=None):
    """Compensate face ``face`` of ``object_name`` in the FreeCAD document ``document``.

    Parameters
    ----------
    document : str
        The shop document (.FCStd); it is only read (unless ``overwrite_input``).
    measurements : str
        Measurement file (any format :func:`surfcomp.io.readers.read_any` reads); its data
        is stored in the document.
    object_name : str
        Name or label of the object holding the nominal face, or of a compensation: the new
        one is its next round (``Base``; same nominal face, its ``Output`` by default).
    face : str, optional
        ``FaceN`` (default: the object's only B-spline face; a compensation's own face).
    save : str, optional
        Where to save the updated document (required with ``replace`` or ``gcode``).
    replace : bool
        Rebind the users of the nominal (Path Job models, operations) to the compensation
        (:func:`surfcomp.app.replace.replace`) and recompute.
    gcode : str, optional
        Write the regenerated program of the Job that uses the compensation.
    post, post_args : str
        Path post-processor name and its argument string.
    job_name : str, optional
        Which Job to post when several use the compensation.
    units : str
        Units of measurement columns without a unit suffix.
    deviation_units : str, optional
        Unit of a deviation column without a suffix when it is not ``units``.
    options : surfcomp.core.compensation.pipeline.Options, optional
        Method, mask, edge, stock, refine (default: Werner's filtered 5x5).
    output : {'face', 'solid'}, optional
        The feature's output; default ``solid`` when the object has several faces
        (so ``FaceN`` links of Path operations stay valid), else ``face``.
    overwrite_input : bool
        Allow ``save`` to be the input document.
    fmt, sample : str, optional
        Measurement file format and QIF sample (see :func:`surfcomp.io.readers.read_any`).
    max_memory : int, optional
        Bytes: the compensation's estimated peak memory (from the number of points read,
        :mod:`surfcomp.core.budget`) above it is refused before the work (None: the
        machine's memory). FreeCAD's own recompute of the CAM Job is not estimated.
    align : surfcomp.core.measurement.align_report.AlignOptions, optional
        How to align the measured points to the nominal; written to the measurement
        object's Align* properties, so the document's recompute aligns the same way
        (:mod:`surfcomp.app.align_doc`). None: the properties keep their defaults.

    Returns
    -------
    DocumentJobResult

    Raises
    ------
    InputError
        Bad paths, a document with objects that did not restore, an output equal to the
        input, several Jobs without ``job_name``; nothing is written.
    ComputationError
        An object is invalid after the recompute; nothing is written.
    """
    options = (options or Options()).validate()
    _check_paths(document, measurements, save, gcode, replace, overwrite_input)
    report(progress, 0.0, "setting up Path and OpenCamLib")
    cam.setup_workbench()
    import FreeCAD

    from . import replace as replace_mod

    report(progress, 0.05, "opening %s" % os.path.basename(document))
    before = set(FreeCAD.listDocuments())
    doc, refused, info = open_for_update(document)
    try:
        check_restored(doc, refused, info, document)
        nominal, base = _round_of(doc, _find_object(doc, object_name, document), face,
                                  replace, document)
        if base is not None:
            face = base.FaceName
            output = output or base.Output
        paths_before = toolpaths.snapshot(doc)
        report(progress, 0.1, "reading the measurements")
        comp, meas = _add_compensation(doc, nominal, face, measurements,
                                       (units, deviation_units), fmt, sample, options, output,
                                       max_memory, base)
        if align is not None:
            align_doc.settle(meas, align)
        report(progress, 0.15, "compensating %s.%s" % (nominal.Label, comp.FaceName))
        # computed once outside the recompute so bad input raises with file and line
        features.compensation_result(comp)
        comp.recompute()
        result = DocumentJobResult(document=os.path.abspath(document), compensation=comp.Name,
                                   measurement=meas.Name, round=int(comp.Round),
                                   base=None if base is None else base.Name)
        if replace:
            report(progress, 0.3, "replacing the nominal")
            result.replaced = replace_mod.replace(doc, comp)
        report(progress, 0.35, "recomputing the document (Path regenerates the tool paths)")
        _recompute(doc)
        jobs = _jobs_using(doc, comp)
        result.jobs = [j.Name for j in jobs]
        result.toolpaths = toolpaths.compare(doc, paths_before, result.jobs)
        result.operations = [op.name for j in result.toolpaths for op in j.regenerated()]
        text = post_program(jobs, gcode, post, post_args, job_name, progress)
        result.statistics = json.loads(comp.Statistics)
        result.checks = json.loads(comp.Checks)
        result.warnings = list(comp.Warnings)
        result.output = comp.Output
        result.volume_change = float(comp.VolChange)
        result.alignment = list(comp.Alignment)
        result.alignment_warnings = [w for w in result.warnings if w in result.alignment]
        result.correction_volume = float(comp.CorrVol)
        report(progress, 0.95, "saving")
        _write(doc, result, save, gcode, text, _declared(document, measurements, save, gcode,
                                                         overwrite_input))
        report(progress, 1.0, "done")
        return result
    finally:
        if doc.Name not in before and doc.Name in FreeCAD.listDocuments():
            FreeCAD.closeDocument(doc.Name)


def _declared(document, measurements, save, gcode, overwrite_input):
    """(outputs, inputs) for :class:`surfcomp.io.atomic.Transaction`."""
    inputs = [("MEASUREMENTS", measurements),
              ("document", document, ("--save",)) if overwrite_input else
              ("document (--overwrite-input allows it)", document)]
    return [("--save", save), ("--gcode", gcode)], inputs


def _check_paths(document, measurements, save, gcode, replace, overwrite_input):
    if not os.path.isfile(document):
        raise InputError("document not found (expected a FreeCAD .FCStd file)", file=document)
    if not document.lower().endswith(".fcstd"):
        raise InputError("expected a FreeCAD document (.FCStd)", file=document)
    if (replace or gcode) and not save:
        raise InputError("--replace and --gcode need --save OUT.FCStd (the input document is "
                         "not overwritten)")
    if save and not save.lower().endswith(".fcstd"):
        raise InputError("the saved document must end in .FCStd", file=save)
    check_outputs(*_declared(document, measurements, save, gcode, overwrite_input))
    if save:
        _check_linked_files(document, save)


def _check_linked_files(document, save):
    """Refuse ``save`` in a folder from which the document's links to other documents (kept
    by FreeCAD as paths relative to the document's folder, also in a copy saved elsewhere)
    would find another file or none: the saved document would reopen without them."""
    here, there = (os.path.dirname(os.path.abspath(p)) for p in (document, save))
    for name in parse_document(document)["files"]:
        if os.path.isabs(name):
            continue
        linked, found = (os.path.realpath(os.path.join(d, name)) for d in (here, there))
        if linked != found:
            raise InputError("--save in %s: the document links objects of %s by a path "
                             "relative to its folder, which FreeCAD keeps in the saved copy, "
                             "so from there the links would point to %s and the saved "
                             "document would reopen without them; nothing was written. "
                             "Expected --save in the document's folder %s"
                             % (there, linked, found, here), file=save)


def _add_compensation(doc, nominal, face, measurements, units, fmt, sample, options, output,
                      max_memory=None, base=None):
    """The measurement (``units``: the coordinates' and the deviation column's, or None)
    and the compensation objects of a document job (``base``: the previous round); the
    points are read and the estimated peak memory checked before anything is added to the
    document."""
    if output is None:
        output = "solid" if len(nominal.Shape.Faces) > 1 else "face"
    ms = read_any(os.fspath(measurements), units=units[0], fmt=fmt or "auto", sample=sample,
                  deviation_units=units[1])
    budget.check_job(len(ms), True, max_memory)
    meas = features.make_measurement_from_set(doc, ms)
    comp = features.make_compensation(doc, nominal, face, meas, method=options.method,
                                      output=output, base=base)
    store_options(comp, options)     # every option, so none is left at its default unsaid
    return comp, meas


def _recompute(doc):
    """Recompute ``doc``; refuse (nothing is written) when an object ends invalid or in error,
    or a CAM operation logged an error: it kept an old or a truncated tool path, which no
    summary may call regenerated and no program may be posted from
    (:func:`surfcomp.app.progress.recompute_all`)."""
    recompute_order.recompute_all(doc)
    bad = [o for o in doc.Objects if recompute_order.failed(o)]
    if bad:
        raise ComputationError("after the recompute %d object(s) failed: %s"
                               % (len(bad), "; ".join("%s (%s): %s" % (
                                   o.Label, o.Name, recompute_order.state_text(o)) for o in bad)))


def _one_job(jobs, job_name):
    using = ", ".join(j.Label for j in jobs)
    if not jobs:
        raise InputError("no Path jobs use the compensation, so there is no program to post "
                         "(a Job uses it after the replace when the Job's model is the "
                         "nominal)")
    chosen = [j for j in jobs if job_name in (j.Name, j.Label)] if job_name else jobs
    if not chosen:
        # not "no Path jobs use the compensation": they do, under other names
        raise InputError("no Path job named %r uses the compensation (the Jobs that do: %s); "
                         "expected one of their names or labels" % (job_name, using))
    if len(chosen) != 1:
        raise InputError("%d Path jobs use the compensation (%s): choose one with the job name"
                         % (len(chosen), ", ".join(j.Label for j in chosen)))
    return chosen[0]


def post_program(jobs, gcode, post, post_args, job_name, progress=None):
    """The program of the one Job of ``jobs`` (``job_name`` picks it among several) posted
    with ``post``, or None without ``gcode``."""
    if not gcode:
        return None
    job = _one_job(jobs, job_name)
    report(progress, 0.9, "post-processing %s with %s" % (job.Label, post))
    return cam_job.post_process(job, post, post_args)


def _write(doc, result, save, gcode, text, declared):
    with Transaction(*declared) as tx:
        if save:
            tmp = tx.stage(save)
            os.unlink(tmp)           # FreeCAD writes the file itself
            # saveCopy keeps the document's file name; the label follows the new file
            doc.Label = os.path.splitext(os.path.basename(save))[0]
            doc.saveCopy(tmp)
            result.saved = os.path.abspath(save)
        if text is not None:
            tx.stage_text(gcode, text)
            result.gcode = shown(gcode)
            result.gcode_lines = text.count("\n")
        tx.commit()


def outcome_lines(result):
    """What a document route did to the document: the links moved to the compensation,
    per Job which operations regenerated (commands changed) and which did not and why, the
    file saved and the program posted."""
    lines = []
    if result.replaced:
        lines.append("replaced the nominal in: %s"
                     % ", ".join("%s.%s" % pair for pair in result.replaced))
    lines += toolpaths.describe(result.toolpaths)
    if result.saved:
        lines.append("wrote %s" % result.saved)
    if getattr(result, "gcode", None):
        lines.append("wrote %s (%d lines)" % (result.gcode, result.gcode_lines))
    return lines


def summary_lines(result):
    """Short human-readable lines about a :class:`DocumentJobResult` (for the CLI)."""
    lines = ["compensation %s (measurement %s) added to the document"
             % (result.compensation, result.measurement)]
    if result.base:
        lines.append("round %d: stacked on %s (the earlier rounds' correction plus this "
                     "measurement's; deviations against the nominal)"
                     % (result.round, result.base))
    if result.output == "solid":
        lines.append("output: the nominal's shape with the face replaced; volume change %.4f "
                     "mm^3, expected from the correction %.4f mm^3 (-integral of delta dA)"
                     % (result.volume_change, -result.correction_volume))
    lines += [a for a in result.alignment if a not in result.alignment_warnings]
    return lines + outcome_lines(result)


__all__ = ["run_document_job", "DocumentJobResult", "summary_lines"]
