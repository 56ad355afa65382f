# SPDX-License-Identifier: LGPL-2.1-or-later
"""An alignment as a job runs it: the known transform, the fit, and what it moved (no FreeCAD).

:func:`align` applies a known rigid transform, then the best fit
(:func:`surfcomp.core.measurement.align.best_fit`) or the 3-2-1 alignment
(:func:`surfcomp.core.measurement.align_rps.rps_fit`), and returns the moved points with an
:class:`Alignment` record: the matrix (measured -> nominal), the RMS distance of the points
to each reference face before and after, the iterations, and, when the compensated face
took part in the fit, what the fit absorbed there: the mean normal shift it gave the face's
points and the tilt of that shift across the face (the range of its linear part). A best
fit on the compensated face removes exactly that much of the machining error's mean and
tilt from the deviations, and the corrected face would then leave it in the part.
"""

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, note
from ..choices import ALIGN_METHODS as METHODS
from .align import (
    DOF_NAMES,
    Distances,
    Reference,
    apply,
    best_fit,
    check_rigid,
    describe,
    spread,
)
from .align import parse_dof as _parse_dof
from .align_rps import rps_fit

#: a fit that moves the compensated face's points farther (mm, along the normal) started
#: in another frame: its absorbed mean and tilt are mostly that frame's offset
FAR_START = 1.0
#: the RMS before the alignment is taken over this many points at most (spread over the
#: file): points far from the faces take a projection each
BEFORE_SAMPLE = 20000


@dataclass
class AlignOptions:
    """What a job aligns: ``method`` one of :data:`METHODS`; ``faces`` the reference face
    names (empty: the compensated face); ``dof`` the degrees of freedom (text for
    :func:`surfcomp.core.measurement.align.parse_dof`); ``rps`` the 3-2-1 groups (dict);
    ``transform`` a known 4 x 4 matrix applied first (list of rows) with ``transform_source`` its
    file."""

    method: str = "none"
    faces: tuple = ()
    dof: str = "all"
    rps: dict = None
    transform: object = None
    transform_source: str = None

    def active(self):
        return self.method != "none" or self.transform is not None

    def validate(self):
        if self.method not in METHODS:
            raise InputError("align %r: expected one of %s" % (self.method, ", ".join(METHODS)),
                             options=("align",))
        if self.method == "rps" and self.rps is None:
            raise InputError("align 'rps' needs rps (the 3-2-1 point ids)",
                             options=("align", "rps"))
        if self.rps is not None and self.method != "rps":
            raise InputError("rps is used by align 'rps' only (got align %r)" % self.method,
                             options=("align", "rps"))
        dof = _parse_dof(self.dof)
        if self.method == "rps" and dof != DOF_NAMES:
            raise InputError("align_dof applies to align 'bestfit' (3-2-1 fixes all six)",
                             options=("align", "align_dof"))
        if self.transform is not None:
            check_rigid(self.transform, self.transform_source)
        return self


@dataclass
class Alignment:
    """What an alignment did (see the module docstring); lengths in mm."""

    method: str
    matrix: np.ndarray
    known: np.ndarray = None
    dof: tuple = DOF_NAMES
    faces: list = field(default_factory=list)
    iterations: int = 0
    converged: bool = True
    start: str = "as given"
    rms_before: dict = None
    rms_after: dict = None
    points: dict = None
    outliers: int = 0
    absorbed: dict = None
    warnings: list = field(default_factory=list)
    point_face: np.ndarray = None

    def as_dict(self):
        """The report's ``"alignment"`` object."""
        return {"method": self.method,
                "matrix": [[float(x) for x in row] for row in self.matrix],
                "known_transform": None if self.known is None else
                [[float(x) for x in row] for row in self.known],
                **describe(self.matrix), "dof": list(self.dof), "faces": list(self.faces),
                "start": self.start, "iterations": self.iterations,
                "converged": self.converged, "points": self.points,
                "outliers": self.outliers,
                "rms_before_um": _um(self.rms_before), "rms_after_um": _um(self.rms_after),
                "absorbed": self.absorbed}


def summary_lines(d):
    """Summary lines of a report's ``"alignment"`` object (:meth:`Alignment.as_dict`)."""
    if not d:
        return []
    out = ["Alignment:    %s%s: translation %s mm, rotation %s deg about X, Y, Z (%.6f deg)"
           % (d["method"], "" if d["known_transform"] is None else " (with the known transform)",
              " ".join("%+.6f" % x for x in d["translation_mm"]),
              " ".join("%+.6f" % x for x in d["rotation_deg"]), d["angle_deg"])]
    if d["method"] != "none":
        out.append("  %s on %s, degrees of freedom %s, start %s; %d iterations, %s"
                   % ("best fit" if d["method"] == "bestfit" else "3-2-1",
                      ", ".join(d["faces"]), " ".join(d["dof"]), d["start"], d["iterations"],
                      "converged" if d["converged"] else "NOT converged"))
        for name, after in (d["rms_after_um"] or {}).items():
            out.append("  %s: %d points, RMS distance %.3f um before, %.3f um after"
                       % (name, d["points"][name],
                          d["rms_before_um"].get(name, float("nan")), after))
        if d["outliers"]:
            out.append("  %d point(s) weighted out as outliers" % d["outliers"])
    if d["absorbed"]:
        where = d["absorbed"].get("where", "face")
        out.append("  absorbed on the compensated %s: mean offset %.3f um, tilt %.3f um "
                   "across the %s" % (where, d["absorbed"]["mean_offset_um"],
                                      d["absorbed"]["tilt_um"], where))
    return out


def _um(d):
    return None if d is None else {k: v * 1e3 for k, v in d.items()}


def per_face_rms(r, face, names):
    """RMS of the finite residuals of each face's points, and their counts."""
    rms, count = {}, {}
    for k, name in enumerate(names):
        sel = (face == k) & np.isfinite(r)
        count[name] = int(sel.sum())
        if sel.any():
            rms[name] = float(np.sqrt(np.mean(r[sel] ** 2)))
    return rms, count


def absorbed(before, after, normal):
    """What a fit moved on the compensated face: the shift of its points along the outward
    normal, ``s = n . (after - before)``; its mean and the range of its least-squares
    linear part ``a + g . x`` over the points (the tilt across the face), in um. ``before``
    is where the points came in (after a known transform): the deviations change by ``s``
    (``d_after - d_before``)."""
    s = np.einsum("ij,ij->i", normal, after - before)
    X = after - after.mean(axis=0)
    A = np.hstack([np.ones((X.shape[0], 1)), X])
    coef = np.linalg.lstsq(A, s, rcond=None)[0]
    lin = X @ coef[1:]
    return {"mean_offset_um": float(s.mean() * 1e3),
            "tilt_um": float((lin.max() - lin.min()) * 1e3) if lin.size else 0.0}


def align(points, options, references, compensated=None, ids=None, assign=None, offset=0.0,
          progress=None, source=None, passive=()):
    """Align measured points (see the module docstring).

    Parameters
    ----------
    points : ndarray (N, 3)
        Measured points (mm), in the measuring frame.
    options : AlignOptions
    references : list of Reference
        The reference faces (the compensated face alone when the user named none).
    compensated : int, optional
        Index of the compensated face in ``references`` (None: it is not among them).
    passive : tuple of int
        References that only claim their nearest points (the compensated face beside datum
        faces): those points take no part in the fit.

    Returns
    -------
    (ndarray (N, 3), Alignment)
        The points in the nominal's frame and the record (``point_face``: the nearest
        reference of every aligned point).
    """
    options.validate()
    P = np.asarray(points, dtype=float)
    known = None if options.transform is None else check_rigid(options.transform,
                                                               options.transform_source)
    start = np.eye(4) if known is None else known
    if options.method == "none":
        return apply(start, P), Alignment("none", start, known=known)
    every = [r.name for r in references]
    active = [n for k, n in enumerate(every) if k not in passive]
    dist = Distances(references, P.shape[0])
    if options.method == "rps":
        fit, _idx = rps_fit(P, options.rps, references, ids, start, offset, source=source)
        label, dof, outliers = "as given", DOF_NAMES, 0
    else:
        dof = _parse_dof(options.dof)
        fit, label = best_fit(P, references, assign, dof, start, offset=offset,
                              progress=progress, passive=passive, distances=dist)
        outliers = int(((fit.weight == 0) & np.isfinite(fit.residual)).sum())
    before, after = apply(start, P), apply(fit.matrix, P)
    if options.method == "bestfit" and not passive:
        r1, g1, f1 = fit.residual, fit.gradient, fit.face
    else:
        r1, g1, f1 = dist(after, assign)
        r1 = r1 - offset
    rms_after, count = per_face_rms(r1, f1, every)
    rms_before = _rms_before(dist, before, np.asarray(f1), every, offset)
    rec = Alignment(options.method, fit.matrix, known, dof, active, fit.iterations,
                    fit.converged, label, rms_before, rms_after, count, outliers)
    rec.point_face = f1
    if compensated is not None and compensated not in passive and options.method == "bestfit":
        on = f1 == compensated
        rec.absorbed = absorbed(before[on], after[on], g1[on])
        rec.warnings.append(_absorbed_warning(rec.absorbed, g1[on], after[on] - before[on]))
    return after, rec


def _rms_before(dist, before, face, names, offset):
    """Per reference, the RMS distance before the fit of the points the fit gave it
    (``face``: the references of the points after the fit), so that each face's before and
    after are over the same points: on a sample of :data:`BEFORE_SAMPLE` points spread over
    the file (far points cost a projection each), and every point of a face the sample
    missed."""
    s = spread(before.shape[0], BEFORE_SAMPLE)
    r0, _g, _f = dist(before[s], face[s])
    rms, _count = per_face_rms(r0 - offset, face[s], names)
    for k, name in enumerate(names):
        idx = np.flatnonzero(face == k)
        if name not in rms and idx.size:
            r, _g, _f = dist(before[idx], face[idx])
            rms.update(per_face_rms(r - offset, face[idx], names)[0])
    return rms


def _absorbed_warning(absorbed_, normal, shift):
    moved = float(np.abs(np.einsum("ij,ij->i", normal, shift)).max()) if shift.size else 0.0
    if moved > FAR_START:
        return note("the best fit used the compensated face itself and moved its points up "
                    "to %.3f mm from where they came in: what it absorbed of the machining "
                    "error's mean and tilt cannot be told apart from that move (bring them "
                    "near with " % moved, ("transform",), ", or name datum faces with ",
                    ("align_faces",), ")")
    return absorbed_note(absorbed_)


def absorbed_note(absorbed_, fitted="the compensated face itself", corrected="face"):
    """The warning that a best fit on the ``fitted`` faces absorbed ``absorbed_``
    (:func:`absorbed`), which the corrected ``corrected`` leaves in the part as far as it
    is machining error (face and region routes)."""
    return note("the best fit used %s: it absorbed a mean offset of %.3f um and a tilt of "
                "%.3f um, of the machining error or of the points' frame (the fit cannot tell "
                "them apart); what is machining error the corrected %s will leave in the part "
                "(name datum faces with " % (fitted, absorbed_["mean_offset_um"],
                                             absorbed_["tilt_um"], corrected),
                ("align_faces",), " to keep it)")


__all__ = ["AlignOptions", "Alignment", "Reference", "absorbed", "absorbed_note", "align",
           "per_face_rms", "summary_lines"]
