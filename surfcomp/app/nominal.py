# SPDX-License-Identifier: LGPL-2.1-or-later
"""Load the nominal face from STEP/IGES/BREP or an FCStd document (app layer, headless).

The nominal is never modified: everything here works on copies.
"""

import os
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..core.compensation import region_field
from ..core.surface.surface_checks import check_nominal
from ..core.surface.trimmed import area_samples, inside, whole_domain
from ..errors import GeometryError, note
from . import fcenv
from .cadread import CAD_EXTENSIONS, read_cad
from .convert import surface_from_raw
from .face_data import EDGE_POINTS, boundary_points, face_data, line_ends, pick_face, surface_type


@dataclass
class Nominal:
    """The chosen nominal face and its B-spline form.

    Attributes
    ----------
    face : Part.Face
        A copy of the original face (as found in the file/document).
    bspline_face : Part.Face
        The same face (geometry, boundary, orientation) as a B-spline face: ``face`` itself,
        or its ``toNurbs`` form; its pcurves are in the parametrisation of ``surface``.
    surface : surfcomp.core.surface.bspline.Surface
        Core arrays of ``bspline_face.Surface`` made non-periodic and cut to the face's UV
        bounds (:func:`surfcomp.app.face_data.work_surface`, same parametrisation);
        ``u_range``/``v_range`` = those bounds.
    source, object_name : str
    data : surfcomp.app.face_data.FaceData
        The face as plain data (:func:`nominal_from_data`): ``outward`` (+1 when the face's
        outward normal is Su x Sv, -1 when the face is reversed), ``face_name`` and
        ``converted`` (what the original surface was when it had to be converted, e.g.
        'Cylinder') are its. A nominal the reader child sent
        (:func:`surfcomp.app.cadread.take_face`) has only this: ``face``, ``bspline_face``
        and ``shape`` are None (the process has no FreeCAD), and its ``data`` holds the
        boundary polylines.
    """

    face: object
    bspline_face: object
    surface: object
    source: str
    data: object
    object_name: str = None
    shape: object = None

    @property
    def outward(self):
        return self.data.outward

    @property
    def face_name(self):
        return self.data.face_name

    @property
    def converted(self):
        return self.data.converted

    @cached_property
    def untrimmed(self):
        """True when the face is bounded by its surface's whole domain
        (:func:`bounds_whole_domain`), told once for the trim warning, the correction's
        volume and the direct program's trim."""
        return ends_whole_domain(self.data.line_ends, self.surface.u_range,
                                 self.surface.v_range)

    @cached_property
    def boundary(self):
        """The face's :func:`boundary_polylines` (:data:`EDGE_POINTS` per edge), sampled
        once: the child's when it sent them."""
        if self.data.boundary is not None:
            return [np.array(p, dtype=float) for p in self.data.boundary]
        return boundary_polylines(self.bspline_face)


def read_shape(path, object_name=None):
    """Return ``(shape, object_name)`` from a CAD file or an FCStd document.

    For an FCStd the document is opened hidden and closed again; ``object_name``
    picks the object (by Name or Label); without it the only object with a shape
    that has B-spline faces is taken.
    """
    fcenv.import_freecad()
    if not os.path.isfile(path):
        raise GeometryError("nominal file not found (expected a STEP, IGES, BREP or FCStd file)",
                            file=path)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".fcstd":
        return _shape_from_document(path, object_name)
    if ext not in CAD_EXTENSIONS:
        raise GeometryError("unsupported nominal file type %r (expected .step/.stp, .iges/.igs, "
                            ".brep/.brp or .FCStd)" % ext, file=path)
    if object_name:
        raise GeometryError(note(("object",), " applies to FCStd documents only"), file=path)
    return read_cad(path), None


def _shape_from_document(path, object_name):
    import FreeCAD

    from .documents import open_document  # (documents only: it loads the CAM adapters)

    before = set(FreeCAD.listDocuments())
    doc = open_document(path)[0]
    try:
        if object_name:
            obj = doc.getObject(object_name) or next(
                (o for o in doc.Objects if o.Label == object_name), None)
            if obj is None:
                names = ", ".join(o.Name for o in doc.Objects if hasattr(o, "Shape"))
                raise GeometryError("no object %r in the document (objects with shapes: %s)"
                                    % (object_name, names or "none"), file=path)
            if not hasattr(obj, "Shape") or obj.Shape.isNull():
                raise GeometryError("object %r has no shape" % object_name, file=path)
            return obj.Shape.copy(), obj.Name
        cands = [o for o in doc.Objects if hasattr(o, "Shape") and not o.Shape.isNull()
                 and any(surface_type(f) == "BSplineSurface" for f in o.Shape.Faces)
                 and not o.InList]
        if len(cands) != 1:
            raise GeometryError("%s objects with B-spline faces at the top of the document (%s): "
                                "choose one with --object NAME"
                                % ("no" if not cands else len(cands),
                                   ", ".join(o.Name for o in cands) or "none"), file=path)
        return cands[0].Shape.copy(), cands[0].Name
    finally:
        if doc.Name not in before:
            FreeCAD.closeDocument(doc.Name)


def load_nominal(path, face_name=None, object_name=None):
    """Load the nominal face (see module docstring) as a :class:`Nominal`."""
    shape, obj = read_shape(path, object_name)
    face, name = pick_face(shape, face_name, source=path)
    return nominal_from_face(face, source=path, face_name=name, object_name=obj, shape=shape)


def nominal_from_face(face, source="<document>", face_name="Face1", object_name=None, shape=None):
    """Build a :class:`Nominal` from a ``Part.Face`` (a copy is kept)."""
    face = face.copy()
    try:
        data, bface = face_data(face, face_name)
    except GeometryError as exc:
        exc.file = exc.file or source
        raise
    return nominal_from_data(data, source, object_name, face, bface, shape)


def nominal_from_data(data, source, object_name=None, face=None, bspline_face=None, shape=None):
    """Build a :class:`Nominal` from its :class:`surfcomp.app.face_data.FaceData` (and the
    face it was taken from, where this process has it)."""
    u0, u1, v0, v1 = data.bounds
    try:
        surface = surface_from_raw(data.surface, (u0, u1), (v0, v1))
    except (ValueError, OverflowError) as exc:
        raise GeometryError("the face's B-spline surface cannot be used: %s" % exc,
                            file=source) from None
    check_nominal(surface, source, "the surface of %s" % data.face_name)
    return Nominal(face=face, bspline_face=bspline_face, surface=surface, source=source,
                   data=data, object_name=object_name, shape=shape)


#: a measured point farther than this (mm) outside the trimmed face is reported
OUTSIDE_TOLERANCE = 1e-3


def boundary_polylines(face, points=EDGE_POINTS):
    """The face's edges as polylines in (u, v) (pcurves sampled at ``points`` parameters),
    each in its direction in the face's wire: together they bound the face (outer wire and
    holes, which run the other way round; a seam edge's two pcurves)."""
    return [np.array(p, dtype=float) for p in boundary_points(face, points)]


def bounds_whole_domain(face, u_range, v_range):
    """True when every edge of ``face`` is a straight line in (u, v) along one side of the
    rectangle ``u_range x v_range`` and together they go once around it
    (:func:`ends_whole_domain` of its :func:`surfcomp.app.face_data.line_ends`)."""
    return ends_whole_domain(line_ends(face), u_range, v_range)


def ends_whole_domain(ends, u_range, v_range):
    """The answer :func:`surfcomp.core.surface.trimmed.whole_domain` gives on the
    :func:`boundary_polylines` of a face whose edges are the straight lines ``ends``
    (:func:`surfcomp.app.face_data.line_ends`), from the ends of each edge alone (the points
    between the ends of a line lie on the same side), without sampling 400 points of every
    pcurve. False for anything else (None: an edge is not a line; then sample them)."""
    if not ends:
        return False
    ends = [np.array(piece, dtype=float) for piece in ends]
    if not all(_one_side(piece, u_range, v_range) for piece in ends):
        return False
    return whole_domain(ends, u_range, v_range)


def _one_side(piece, u_range, v_range, tol=1e-9):
    """Both ends of a line on the same side of the rectangle (as ``whole_domain`` tells a
    side: within ``tol`` of its extent), so that every point between them is too."""
    (u0, u1), (v0, v1) = u_range, v_range
    du, dv = tol * (u1 - u0), tol * (v1 - v0)
    u, v = piece[:, 0], piece[:, 1]
    return any(bool(np.all(near)) for near in (np.abs(u - u0) <= du, np.abs(u - u1) <= du,
                                               np.abs(v - v0) <= dv, np.abs(v - v1) <= dv))


def outside_trim(nominal, prepared):
    """The measured points that lie on the nominal surface but outside the trimmed face:
    ``(indices, distances)`` in file order, distances (mm) from the face (its boundary).
    Nothing (empty arrays) on a face bounded by its surface's whole domain
    (:func:`bounds_whole_domain`): every point on the surface is on the face. The distances
    are OCCT's where this process has the face, else to its boundary polylines on the
    surface (:meth:`surfcomp.core.compensation.program_trim.Trim.closest`: the face the
    reader child sent)."""
    if nominal.untrimmed:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    candidates = np.nonzero(~inside(nominal.boundary, prepared.u, prepared.v))[0]
    points = np.asarray(prepared.nominal, dtype=float)[candidates]
    face = nominal.bspline_face
    if face is not None:
        import FreeCAD
        import Part

        dist = np.array([face.distToShape(Part.Vertex(FreeCAD.Vector(*p)))[0] for p in points])
    elif len(points):
        from ..core.compensation.program_trim import Trim

        dist = Trim(nominal.surface, nominal.boundary).closest(points)[3]
    else:
        dist = np.zeros(0)
    keep = dist > OUTSIDE_TOLERANCE
    return candidates[keep], dist[keep]


def trim_warning(nominal, prepared):
    """A warning naming how many measured points lie outside the trimmed face and where
    (None when all lie on the face). Such points are still used: the correction field is
    defined over the whole surface; the face keeps its boundary."""
    idx, dist = outside_trim(nominal, prepared)
    if not idx.size:
        return None
    far = idx[np.argmax(dist)]
    lines = ", ".join(str(int(prepared.lines[k])) for k in idx[:5])
    more = " and %d more" % (idx.size - 5) if idx.size > 5 else ""
    return ("%s: %d of %d measured points lie on the surface of %s but outside its trimmed "
            "boundary (lines %s%s), up to %.3f mm beyond it at (%.3f, %.3f, %.3f), line %d "
            "(a probe near a fillet or a hole?); they are used for the correction and counted "
            "in the statistics, and the corrected face keeps the nominal's boundary"
            % ((prepared.source, idx.size, prepared.u.size, nominal.face_name, lines, more,
                float(dist.max())) + tuple(prepared.nominal[far]) + (int(prepared.lines[far]),)))


#: measured points that cover less than this share of the face's area are reported
MIN_COVERAGE = 0.5
#: a face sample is covered when a measured point lies within this many point spacings
COVERAGE_SPACINGS = 3.0


def coverage(nominal, prepared, n=80):
    """The share of the face's area (inside its trim) within :data:`COVERAGE_SPACINGS`
    median point spacings of a measured point (on ``n`` x ``n`` area samples,
    :func:`surfcomp.core.surface.trimmed.area_samples`), as the region route tells it."""
    pts = np.asarray(prepared.nominal, dtype=float)
    if len(pts) < 2:
        return 0.0
    samples, area = area_samples(nominal.surface, nominal.data.bounds,
                                 None if nominal.untrimmed else nominal.boundary, n)
    return region_field.coverage(samples, pts, COVERAGE_SPACINGS * region_field.spacing(pts),
                                 area)


def coverage_warning(nominal, prepared):
    """A warning when the measured points cover less than :data:`MIN_COVERAGE` of the face
    (:func:`coverage`): elsewhere the correction is the field's continuation from the
    measured area, which nothing measured (None otherwise)."""
    share = coverage(nominal, prepared)
    if share >= MIN_COVERAGE:
        return None
    return ("%s: the measured points cover %.0f %% of %s (its area within %g point spacings "
            "of a point); over the rest of the face the correction is continued from the "
            "border of the measured area, where nothing was measured (expected measurements "
            "over the whole face)" % (prepared.source, 100 * share, nominal.face_name,
                                      COVERAGE_SPACINGS))


def face_warnings(nominal, prepared):
    """What the face's trim and extent say about the measured points: the
    :func:`trim_warning` and the :func:`coverage_warning`, those that apply."""
    return [w for w in (trim_warning(nominal, prepared), coverage_warning(nominal, prepared))
            if w]
