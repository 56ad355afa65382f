# SPDX-License-Identifier: LGPL-2.1-or-later
"""A region's measured points aligned to the nominal before the deviations (FreeCAD, no GUI).

The settings are the measurement object's Align* properties, as for one face
(:mod:`surfcomp.app.align_doc`): a known transform (``AlignTransform``) first, then a best
fit or a 3-2-1 alignment. The reference faces of the fit are the region's faces, or the
datum faces ``AlignFaces`` (the region's faces not named there then only claim their
nearest points, which take no part in the fit). Points nearest to a datum face that is not
in the region served the alignment only and are left out of the compensation, as the
single-face route leaves out the points on its datum faces.

With ``Faces = auto`` the region is chosen from where the aligned points lie, so a fit on
it cannot be made first: a best fit or a 3-2-1 alignment needs the region's faces named
(a known transform alone works with ``auto``).
"""

import numpy as np

from ..core.measurement.align import Distances, Reference, apply
from ..core.measurement.align_report import absorbed, absorbed_note, align
from ..errors import InputError
from .align_doc import options_of
from .alignment import assigned_faces, subset


def references(shape, region, datum, source):
    """``(references, indices of the region's faces among them)``: the region's faces
    (0-based indices ``region``), then the datum faces (names) not in the region."""
    from .face_data import pick_face
    from .nominal import nominal_from_face

    names = ["Face%d" % (k + 1) for k in region]
    refs, own = [], []
    for name in names + [d for d in datum if d not in names]:
        face, _ = pick_face(shape, name, source)
        nom = nominal_from_face(face, source, name)
        if name in names:
            own.append(len(refs))
        refs.append(Reference(name, nom.surface, nom.outward))
    return refs, own


def aligned(meas, shape, faces_text, ms):
    """``(measurement set, Alignment or None)``: ``ms`` (document coordinates) with its
    points aligned to ``shape``'s faces as ``meas``'s Align* properties say."""
    from .region import parse_faces

    opts = options_of(meas)
    if opts is None:
        return ms, None
    if ms.nominal is not None or ms.measured is None:
        raise InputError("%s: an alignment moves measured points; this measurement gives %s, "
                         "which are already in the nominal's frame (expected a point file of "
                         "measured points only, or AlignMethod none)"
                         % (meas.Label, ms.kind()), file=ms.source)
    region = parse_faces(faces_text, shape)
    if region is None and opts.method != "none":
        raise InputError("%s: align %s with faces auto: give the region's FaceN names "
                         "instead of auto (the region is chosen from where the aligned points "
                         "lie, so it cannot be fitted first)"
                         % (meas.Label, opts.method), options=("faces", "align"))
    if opts.method == "none":
        points, record = align(ms.measured, opts, [])
        return _replaced(ms, points), record
    datum = list(opts.faces)
    refs, own = references(shape, region, datum, meas.Label)
    passive = tuple(i for i in own if refs[i].name not in datum) if datum else ()
    assign = assigned_faces(ms, refs)
    points, record = align(ms.measured, opts, refs, ids=ms.ids, assign=assign,
                           source=meas.Label, passive=passive)
    if opts.method == "bestfit" and len(passive) < len(own):
        _absorbed(record, refs, own, ms.measured, points, assign)
    ms = _replaced(ms, points)
    keep = np.isin(record.point_face, own)
    if not keep.all():
        if not keep.any():
            raise InputError("%s: no measured point lies nearer to the region's faces %s "
                             "than to the datum faces %s after the alignment"
                             % (meas.Label, ", ".join(refs[i].name for i in own),
                                ", ".join(datum)), file=ms.source)
        ms = subset(ms, keep)
        record.warnings.append("%s: %d point(s) on the datum faces served the alignment only; "
                               "the deviations are those of the %d point(s) on the region"
                               % (ms.source, int((~keep).sum()), int(keep.sum())))
    return ms, record


def _replaced(ms, points):
    import dataclasses

    return dataclasses.replace(ms, measured=points)


def _absorbed(record, refs, own, before_points, after, assign):
    """What a best fit on the region's own faces absorbed of the machining error there
    (the mean and the tilt of the normal shift it gave their points), and the warning."""
    before = before_points if record.known is None else apply(record.known, before_points)
    _r, normal, face = Distances(refs, len(after))(after, assign)
    on = np.isin(face, own) & np.all(np.isfinite(normal), axis=1)
    if not on.any():
        return
    record.absorbed = dict(absorbed(before[on], after[on], normal[on]), where="region")
    record.warnings.append(absorbed_note(record.absorbed, "the region's faces themselves",
                                         "faces"))


__all__ = ["aligned", "references"]
