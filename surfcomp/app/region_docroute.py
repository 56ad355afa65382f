# SPDX-License-Identifier: LGPL-2.1-or-later
"""The region compensation on a shop document (issue 30):

    python3 -m surfcomp compensate DOC.FCStd MEAS.csv --object O --faces F1,F2|auto \\
        [--replace] --save OUT.FCStd [--gcode OUT.ngc --post linuxcnc] [--align ...]

adds a measurement object and a ``SurfComp_RegionCompensation``
(:mod:`surfcomp.app.region_doc`) to the document, optionally moves the nominal's users (Path
Jobs) to it, recomputes, saves a copy and posts the program of the Job that uses it. When
``--object`` names a region object, the new one is its next round (its ``Base``: the
correction of the earlier rounds plus this measurement's). The alignment options become
the measurement object's Align* properties. The safety rules of the single-face route
(:mod:`surfcomp.app.document_route`) hold: the document is opened safely, the outputs are
checked against the inputs before it is opened, the input document is never overwritten
unless ``overwrite_input``, and nothing is written after any failure.
"""

import json
import os
from dataclasses import dataclass, field

from ..core import budget
from ..core.progress import report
from ..errors import InputError
from ..io.readers import read_any
from . import align_doc, cam, features, toolpaths
from .document_route import (
    _check_paths,
    _declared,
    _find_object,
    _jobs_using,
    _recompute,
    _write,
    check_restored,
    outcome_lines,
    post_program,
)
from .documents import open_for_update


@dataclass
class RegionDocumentResult:
    document: str
    compensation: str
    measurement: str
    options: dict = field(default_factory=dict)
    report: dict = field(default_factory=dict)
    replaced: list = field(default_factory=list)
    jobs: list = field(default_factory=list)
    operations: list = field(default_factory=list)     # operations that regenerated
    toolpaths: list = field(default_factory=list)
    saved: str = None
    gcode: str = None
    gcode_lines: int = 0
    base: str = None                                   # the previous round (iterations)
    alignment: list = field(default_factory=list)      # the region object's Alignment lines
    alignment_warnings: list = field(default_factory=list)


def run_region_document(document, measurements, object_name, faces, save, replace=False,
                        overwrite_input=False, units="mm", deviation_units=None, fmt="auto",
                        sample=None, max_memory=None, progress=None, gcode=None,
                        post="linuxcnc", post_args="--no-show-editor", job_name=None,
                        align=None, **options):
    """Compensate the region ``faces`` (``'Face1,Face2'`` or ``'auto'``) of ``object_name``
    in ``document``; save the result to ``save``. ``object_name`` may name a region object:
    the new one is its next round. ``gcode``, ``post``, ``post_args``, ``job_name``: post
    the program of the Job that uses the region object (as
    :func:`surfcomp.app.document_route.run_document_job`); ``align``: an
    :class:`~surfcomp.core.measurement.align_report.AlignOptions` written to the
    measurement object. ``options``: the region object's properties (``Method``,
    ``MaskSize``, ``MaskKind``, ``Sigma``, ``MaxOffset``, ``MinCoverage``, ``Smoothing``).
    Returns a :class:`RegionDocumentResult`.

    Raises
    ------
    InputError, MeasurementFileError, GeometryError
        Bad paths or input, a region that cannot be corrected (named), a nominal that is not
        one closed solid; nothing is written.
    """
    if not save:
        raise InputError("--faces on a document needs --save OUT.FCStd (the input document is "
                         "not overwritten)")
    _check_paths(document, measurements, save, gcode, replace, overwrite_input)
    report(progress, 0.0, "setting up Path")
    cam.setup_workbench()
    import FreeCAD

    from . import region_doc
    from . import replace as replace_mod

    before = set(FreeCAD.listDocuments())
    report(progress, 0.05, "opening %s" % os.path.basename(document))
    doc, refused, info = open_for_update(document)
    try:
        check_restored(doc, refused, info, document)
        nominal = _find_object(doc, object_name, document)
        base = None
        if region_doc.is_region(nominal):
            base, nominal = nominal, nominal.Nominal
            region_doc.chain(base)
            if base.Shape.isNull() or not base.FieldCentres:
                raise InputError("%s holds no correction field to stack on (not computed, or "
                                 "saved by an earlier surfcomp): recompute it first"
                                 % base.Label, file=document)
        if len(nominal.Shape.Solids) != 1:
            raise InputError("%s has %d solids: a region in a document is corrected on one "
                             "closed solid (expected an object with one solid)"
                             % (nominal.Label, len(nominal.Shape.Solids)), file=document)
        paths_before = toolpaths.snapshot(doc)
        report(progress, 0.1, "reading the measurements")
        ms = read_any(os.fspath(measurements), units=units, fmt=fmt or "auto", sample=sample,
                      deviation_units=deviation_units)
        budget.check_job(len(ms), True, max_memory)
        meas = features.make_measurement_from_set(doc, ms)
        if align is not None:
            align_doc.settle(meas, align)
        comp = region_doc.make_region(doc, nominal, faces, meas, base=base, **options)
        report(progress, 0.2, "compensating the region %s of %s" % (faces, nominal.Label))
        # computed once outside the recompute so bad input raises with its message
        run = region_doc.compute(comp)
        region_doc.write_results(comp, run)
        comp.Placement = run.shape.Placement
        comp.Shape = run.shape
        # computed: the document's recompute need not do it again. The new measurement
        # object's own recompute is only the check of its stored lists, which the
        # computation just made (features.measurement_set); left touched, it would have
        # the recompute compute the region, which uses it, a second time
        comp.purgeTouched()
        meas.purgeTouched()
        result = RegionDocumentResult(document=os.path.abspath(document),
                                      compensation=comp.Name, measurement=meas.Name,
                                      options=region_doc.options_record(comp),
                                      base=None if base is None else base.Name)
        if replace:
            report(progress, 0.6, "replacing the nominal")
            result.replaced = replace_mod.replace(doc, comp)
        report(progress, 0.65, "recomputing the document")
        _recompute(doc)
        result.report = json.loads(comp.Report)
        jobs = _jobs_using(doc, comp)
        result.jobs = [j.Name for j in jobs]
        result.toolpaths = toolpaths.compare(doc, paths_before, result.jobs)
        result.operations = [op.name for j in result.toolpaths for op in j.regenerated()]
        text = post_program(jobs, gcode, post, post_args, job_name, progress)
        result.alignment = list(comp.Alignment)
        result.alignment_warnings = [] if run.alignment is None else list(run.alignment.warnings)
        report(progress, 0.95, "saving")
        _write(doc, result, save, gcode, text,
               _declared(document, measurements, save, gcode, overwrite_input))
        report(progress, 1.0, "done")
        return result
    finally:
        if doc.Name not in before and doc.Name in FreeCAD.listDocuments():
            FreeCAD.closeDocument(doc.Name)


def summary_lines(result):
    """The printed lines of a :class:`RegionDocumentResult`."""
    from .region_route import dropped_text, output_line, summary

    rep = result.report
    lines = ["region compensation %s (measurement %s) added to the document: faces %s"
             % (result.compensation, result.measurement,
                ", ".join(f["face"] for f in rep["faces"]))]
    if result.base:
        lines.append("round %d: stacked on %s (the earlier rounds' correction plus this "
                     "measurement's)" % (rep["round"], result.base))
    lines.append("options: " + ", ".join("%s %s" % kv for kv in result.options.items()))
    lines.append("points per face: " + ", ".join("%s %d" % (f["face"], f["points"])
                                                 for f in rep["faces"])
                 + "; on no face: %d" % rep["points_on_no_face"]
                 + dropped_text(rep.get("points_on_dropped_faces", {})))
    lines += [a for a in result.alignment if a not in result.alignment_warnings]
    lines += summary(rep)
    lines.append(output_line(rep["output"]))
    return lines + outcome_lines(result)


__all__ = ["run_region_document", "RegionDocumentResult", "summary_lines"]
