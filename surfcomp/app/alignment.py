# SPDX-License-Identifier: LGPL-2.1-or-later
"""A job's measured points aligned to the nominal before the deviations (FreeCAD, no GUI).

Builds the reference faces from the nominal's shape (``--align-faces``; default the
compensated face itself), reads the transform and 3-2-1 files, and calls
:func:`surfcomp.core.measurement.align_report.align` on the measurement set's points.
"""

import dataclasses

import numpy as np

from ..core.measurement.align import Reference
from ..core.measurement.align_report import AlignOptions, align
from ..errors import InputError
from ..io.align_files import read_rps, read_transform


def align_options(job):
    """The :class:`AlignOptions` of a job (files read, values checked)."""
    faces = tuple(f.strip() for f in (job.align_faces or "").split(",") if f.strip())
    transform = read_transform(job.transform) if job.transform else None
    rps, _source = read_rps(job.rps) if job.rps else (None, None)
    return AlignOptions(job.align or "none", faces, job.align_dof or "all", rps, transform,
                        job.transform).validate()


def references(nominal, names):
    """``(references, index of the compensated face, passive indices)``: the named faces of
    the nominal's shape and the compensated face (passive when not named: it only claims
    its points), or the compensated face alone."""
    from .face_data import pick_face
    from .nominal import nominal_from_face

    own = Reference(nominal.face_name, nominal.surface, nominal.outward)
    if not names:
        return [own], 0, ()
    shape = nominal.shape if nominal.shape is not None else nominal.face
    refs = []
    for name in names:
        if name == nominal.face_name:
            refs.append(Reference(name, nominal.surface, nominal.outward))
            continue
        face, _ = pick_face(shape, name, nominal.source)
        other = nominal_from_face(face, nominal.source, name)
        refs.append(Reference(name, other.surface, other.outward))
    if nominal.face_name in names:
        return refs, names.index(nominal.face_name), ()
    return refs + [own], len(refs), (len(refs),)


def align_measurements(job, nominal, ms, progress=None):
    """``(measurement set with the aligned points, Alignment)`` of a job whose alignment
    is active."""
    tip = float(job.options.tip_radius or 0.0)
    return align_set(align_options(job), nominal, ms, tip, job.rps, progress)


def align_set(opts, nominal, ms, tip_radius=0.0, source=None, progress=None):
    """``(measurement set with the aligned points, Alignment)``: ``ms`` aligned to
    ``nominal`` as ``opts`` say; with datum faces, only the points on the compensated face
    stay. Refuses sets that carry nominal points or deviations (already in the nominal's
    frame)."""
    if ms.nominal is not None or ms.measured is None:
        raise InputError("--align/--transform move measured points: this file gives %s, "
                         "which are already in the nominal's frame (expected a point file "
                         "of measured points only)" % ms.kind(), file=ms.source)
    refs, comp, passive = references(nominal, opts.faces)
    tip = float(tip_radius or 0.0) if ms.tip_centres else 0.0
    assign = assigned_faces(ms, refs) if opts.method != "none" else None
    points, record = align(ms.measured, opts, refs, comp, ids=ms.ids, offset=tip,
                           progress=progress, source=source, passive=passive, assign=assign)
    ms = dataclasses.replace(ms, measured=points)
    if len(refs) > 1 and record.point_face is not None:
        keep = record.point_face == comp
        if not keep.any():
            raise InputError("no measured point lies nearer to the compensated face %s than "
                             "to the reference faces %s after the alignment"
                             % (nominal.face_name, ", ".join(opts.faces)), file=ms.source)
        ms = subset(ms, keep)
        record.warnings.append("%s: %d point(s) on the reference faces served the alignment "
                               "only; the deviations are those of the %d point(s) on %s"
                               % (ms.source, int((~keep).sum()), int(keep.sum()),
                                  nominal.face_name))
    return ms, record


def assigned_faces(ms, refs):
    """The reference index of every point from the file's face column (read with the
    points, and stored with them in a document), or None."""
    named = ms.faces
    if named is None:
        return None
    index = {r.name: k for k, r in enumerate(refs)}
    out = np.empty(len(named), dtype=int)
    for k, name in enumerate(named):
        if name not in index:
            raise InputError("face %r is not a reference face (expected one of %s: the "
                             "faces of --align-faces and the compensated face)"
                             % (name, ", ".join(index)), file=ms.source, line=int(ms.lines[k]))
        out[k] = index[name]
    return out


def subset(ms, keep):
    """The measurement set of the points ``keep`` (bool, N) only."""
    arrays = {f: getattr(ms, f)[keep] for f in ("nominal", "measured", "normal", "deviation",
                                                "row", "col", "lines")
              if getattr(ms, f) is not None}
    for name in ("ids", "faces"):
        if getattr(ms, name) is not None:
            arrays[name] = [i for i, k in zip(getattr(ms, name), keep) if k]
    return dataclasses.replace(ms, **arrays)
