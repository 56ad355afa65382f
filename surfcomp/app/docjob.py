"""The batch route on a shop document: compensate a face in an FCStd, replace the nominal,
let Path regenerate, save a new document and (optionally) post the G-code.

    python3 -m surfcomp compensate DOC.FCStd MEAS.csv --object O --face F --replace \\
        --save OUT.FCStd [--gcode OUT.ngc --post linuxcnc]

Safety rules (issue 3):

- Path and OpenCamLib are set up *before* the document is opened
  (:func:`surfcomp.app.cam.setup_workbench`): an object whose module cannot be
  imported at open time loses its proxy silently, and a document saved like that can never
  recompute that object again. Such documents are refused (nothing is written).
- The input document is never overwritten unless ``overwrite_input=True``.
- All outputs (document, G-code) are written together or not at all (temporary files
  renamed at the end); after any failure nothing is written.
"""

import json
import os
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass, field

from ..core.pipeline import Options
from ..core.progress import report
from ..errors import ComputationError, GeometryError, InputError
from ..io.atomic import Transaction
from . import cam


@dataclass
class DocumentJobResult:
    """What :func:`run_document_job` did (names are document object names)."""

    document: str
    compensation: str
    measurement: str
    replaced: list = field(default_factory=list)       # (object, property) rebound
    jobs: list = field(default_factory=list)           # Path jobs that use the compensation
    operations: list = field(default_factory=list)     # their operations (recomputed)
    saved: str = None
    gcode: str = None
    gcode_lines: int = 0
    statistics: dict = field(default_factory=dict)
    checks: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)


def _xml_objects(path):
    """Names and type ids of the objects listed in an FCStd's Document.xml."""
    try:
        with zipfile.ZipFile(path) as z:
            root = ET.fromstring(z.read("Document.xml"))
    except (OSError, KeyError, zipfile.BadZipFile, ET.ParseError) as exc:
        raise InputError("not a FreeCAD document (%s)" % exc, file=path) from exc
    objs = root.find("Objects")
    return [(o.get("name"), o.get("type")) for o in (objs if objs is not None else [])
            if o.tag == "Object"]


def preload_proxy_modules(path):
    """Import the modules of the Python proxies stored in an FCStd before opening it.

    Opened from a plain ``python3``, FreeCAD restores a proxy only when its module is
    already imported (Path's ``PathScripts.PathJob`` is not, and the Job would lose its
    proxy silently). On FreeCAD 1.x the CAM modules a 0.20 document names are aliased to
    their 1.x homes first (:func:`surfcomp.app.cam.alias_legacy_modules`). Returns
    ``{module: error text}`` for the modules that cannot be imported (their objects will be
    reported by :func:`restore_failures`).
    """
    import importlib

    try:
        with zipfile.ZipFile(path) as z:
            root = ET.fromstring(z.read("Document.xml"))
    except (OSError, KeyError, zipfile.BadZipFile, ET.ParseError) as exc:
        raise InputError("not a FreeCAD document (%s)" % exc, file=path) from exc
    names = sorted({el.get("module") for el in root.iter("Python") if el.get("module")})
    cam.alias_legacy_modules(names)
    failed = {}
    for name in names:
        try:
            importlib.import_module(name)
        except Exception as exc:  # any import-time error means the proxy cannot restore
            failed[name] = "%s: %s" % (type(exc).__name__, exc)
    return failed


def restore_failures(doc, path=None):
    """Objects of an opened document that did not restore completely.

    - Python features (``...::FeaturePython``) whose proxy is None: the proxy's module
      could not be imported at open time (e.g. Path's 3D Surface without ``ocl``, or a
      workbench that is not installed);
    - objects listed in the file (``path``) that are missing from the document (a type
      this FreeCAD does not know).

    Returns
    -------
    list of str
        One description per problem (empty when everything restored).
    """
    problems = []
    for o in doc.Objects:
        if "Python" in o.TypeId and "Proxy" in o.PropertiesList and o.Proxy is None:
            problems.append("%s (%s, label %r): its Python proxy was not restored (a module it "
                            "needs could not be imported)" % (o.Name, o.TypeId, o.Label))
    if path:
        have = {o.Name for o in doc.Objects}
        for name, typ in _xml_objects(path):
            if name not in have:
                problems.append("%s (%s): missing after opening (unknown object type?)"
                                % (name, typ))
    return problems


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


def _jobs_using(doc, comp):
    from . import pathjob

    jobs = []
    for job in pathjob.jobs_of(doc):
        if any(comp in list(getattr(c, "Objects", []) or []) or c is comp for c in job.Model.Group):
            jobs.append(job)
    return jobs


def _same_file(a, b):
    a, b = os.path.abspath(a), os.path.abspath(b)
    if a == b:
        return True
    return os.path.exists(a) and os.path.exists(b) and os.path.samefile(a, b)


def run_document_job(document, measurements, object_name, face=None, save=None, replace=True,
                     gcode=None, post="linuxcnc", post_args="--no-show-editor", job_name=None,
                     units="mm", options=None, output=None, overwrite_input=False,
                     fmt="auto", sample=None,
                     progress=None):
    """Compensate face ``face`` of ``object_name`` in the FreeCAD document ``document``.

    Parameters
    ----------
    document : str
        The shop document (.FCStd); it is only read (unless ``overwrite_input``).
    measurements : str
        Measurement file (any format :func:`surfcomp.io.readers.read_any` reads); its data
        is stored in the document.
    object_name : str
        Name or label of the object holding the nominal face.
    face : str, optional
        ``FaceN`` (default: the object's only B-spline face).
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
    options : surfcomp.core.pipeline.Options, optional
        Method, mask, edge, stock, refine (default: Werner's filtered 5x5).
    output : {'face', 'solid'}, optional
        The feature's output; default ``solid`` when the object has several faces
        (so ``FaceN`` links of Path operations stay valid), else ``face``.
    overwrite_input : bool
        Allow ``save`` to be the input document.
    fmt, sample : str, optional
        Measurement file format and QIF sample (see :func:`surfcomp.io.readers.read_any`).

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
    options = options or Options()
    if not os.path.isfile(document):
        raise InputError("document not found (expected a FreeCAD .FCStd file)", file=document)
    if not document.lower().endswith(".fcstd"):
        raise InputError("expected a FreeCAD document (.FCStd)", file=document)
    if (replace or gcode) and not save:
        raise InputError("--replace and --gcode need --save OUT.FCStd (the input document is "
                         "not overwritten)")
    if save and not save.lower().endswith(".fcstd"):
        raise InputError("the saved document must end in .FCStd", file=save)
    for out in (save, gcode):
        if out and _same_file(out, measurements):
            raise InputError("an output would overwrite the measurement file", file=out)
    if save and _same_file(save, document) and not overwrite_input:
        raise InputError("refusing to overwrite the input document (save to another file, or "
                         "ask for it explicitly)", file=save)
    if gcode and save and _same_file(gcode, save):
        raise InputError("the G-code and the document cannot be the same file", file=gcode)

    report(progress, 0.0, "setting up Path and OpenCamLib")
    cam.setup_workbench()
    import FreeCAD

    from . import features, pathjob
    from . import replace as replace_mod

    report(progress, 0.05, "opening %s" % os.path.basename(document))
    unimportable = preload_proxy_modules(document)
    before = set(FreeCAD.listDocuments())
    try:
        doc = FreeCAD.openDocument(os.path.abspath(document), True)
    except (OSError, RuntimeError, ValueError) as exc:
        raise InputError("cannot open the FreeCAD document: %s" % exc, file=document) from exc
    try:
        problems = restore_failures(doc, document)
        if problems:
            why = "".join("; module %s cannot be imported (%s)" % item
                          for item in sorted(unimportable.items()))
            raise InputError("%d object(s) did not restore, so the document cannot be updated "
                             "safely (saving would lose them): %s%s"
                             % (len(problems), "; ".join(problems), why), file=document)
        nominal = _find_object(doc, object_name, document)
        if output is None:
            output = "solid" if len(nominal.Shape.Faces) > 1 else "face"
        report(progress, 0.1, "reading the measurements")
        meas = features.make_measurement(doc, measurements, units=units, fmt=fmt,
                                         sample=sample)
        comp = features.make_compensation(
            doc, nominal, face, meas, method=options.method, mask_size=options.mask_size,
            weights=options.weights if isinstance(options.weights, str) else "",
            edge=options.edge, stock=options.stock or 0.0, output=output)
        comp.MaskKind = options.mask_kind
        comp.Sigma = float(options.sigma or 0.0)
        comp.MaxOffset = float(options.max_offset)
        comp.FlipNormals = bool(options.flip_normals)
        comp.Refine = int(options.refine)
        report(progress, 0.15, "compensating %s.%s" % (nominal.Label, comp.FaceName))
        # computed once outside the recompute so bad input raises with file and line
        features.compensation_result(comp)
        comp.recompute()
        result = DocumentJobResult(document=os.path.abspath(document), compensation=comp.Name,
                                   measurement=meas.Name)
        if replace:
            report(progress, 0.3, "replacing the nominal")
            result.replaced = replace_mod.replace(doc, comp)
        report(progress, 0.35, "recomputing the document (Path regenerates the tool paths)")
        doc.recompute()
        bad = [o for o in doc.Objects
               if "Invalid" in o.State or "Error" in o.State]
        if bad:
            raise ComputationError("after the recompute %d object(s) are invalid: %s"
                                   % (len(bad), ", ".join("%s (%s)" % (o.Label, o.Name)
                                                          for o in bad)))
        jobs = _jobs_using(doc, comp)
        result.jobs = [j.Name for j in jobs]
        result.operations = [op.Name for j in jobs for op in pathjob.operations_of(j)]
        text = None
        if gcode:
            if job_name:
                jobs = [j for j in jobs if job_name in (j.Name, j.Label)]
            if len(jobs) != 1:
                raise InputError("%s Path jobs use the compensation (%s): choose one with the "
                                 "job name" % (len(jobs) or "no",
                                               ", ".join(j.Label for j in jobs) or "none"))
            report(progress, 0.9, "post-processing %s with %s" % (jobs[0].Label, post))
            text = pathjob.post_process(jobs[0], post, post_args)
        result.statistics = json.loads(comp.Statistics)
        result.checks = json.loads(comp.Checks)
        result.warnings = list(comp.Warnings)
        report(progress, 0.95, "saving")
        with Transaction() as tx:
            if save:
                tmp = tx.stage(save)
                os.unlink(tmp)           # FreeCAD writes the file itself
                # saveCopy keeps the document's file name; the label follows the new file
                doc.Label = os.path.splitext(os.path.basename(save))[0]
                doc.saveCopy(tmp)
                result.saved = os.path.abspath(save)
            if text is not None:
                tx.stage_text(gcode, text)
                result.gcode = os.path.abspath(gcode)
                result.gcode_lines = text.count("\n")
            tx.commit()
        report(progress, 1.0, "done")
        return result
    finally:
        if doc.Name not in before and doc.Name in FreeCAD.listDocuments():
            FreeCAD.closeDocument(doc.Name)


def summary_lines(result):
    """Short human-readable lines about a :class:`DocumentJobResult` (for the CLI)."""
    lines = ["compensation %s (measurement %s) added to the document"
             % (result.compensation, result.measurement)]
    if result.replaced:
        lines.append("replaced the nominal in: %s"
                     % ", ".join("%s.%s" % pair for pair in result.replaced))
    if result.operations:
        lines.append("regenerated: %s" % ", ".join(result.operations))
    if result.saved:
        lines.append("wrote %s" % result.saved)
    if result.gcode:
        lines.append("wrote %s (%d lines)" % (result.gcode, result.gcode_lines))
    return lines


__all__ = ["run_document_job", "DocumentJobResult", "restore_failures", "summary_lines"]
