# SPDX-License-Identifier: LGPL-2.1-or-later
"""A region's corrected faces put back in their solid, the faces outside the region that
meet them re-trimmed (issue 30; app layer).

Every corrected face meets the rest of the solid as one corrected face does
(:func:`surfcomp.app.retrim.plan`, with the region's other faces as ``region``): an edge it
shares with a face outside the region is kept where the correction moves it by at most
:data:`~surfcomp.app.retrim.PRECISION`, re-trimmed where the neighbour meets it at an angle,
and refused where the neighbour is tangent (naming the edge and the faces); an edge shared
with another face of the region keeps its pcurve on both corrected surfaces, and where it
ends at a re-trimmed neighbour its end slides to that neighbour's surface. The neighbours
take the new edges (:func:`surfcomp.app.shapes.replacement_pairs`, the single face's
builder), and OpenCASCADE's general fuse with a fuzzy value of PRECISION joins the region's
faces along their common edges (its sewing leaves these apart on FreeCAD 0.20).

The volume change is the flux of ``F(x) = (x - c) / 3`` through the changed faces and the
strips the re-trimmed neighbours gain or lose (:func:`surfcomp.app.volumes.volume_change`,
one ``c`` for the region), not OCCT's volume of the whole solid, which is off by about 1e-4
of the volume on trimmed B-spline faces.
"""

from types import SimpleNamespace

import numpy as np

from ..core.limits import NIL_INTEGRAL
from ..errors import GeometryError
from . import retrim
from .face_data import geometry_box
from .shapes import _nearest, _oriented, rebuild_face, replacement_pairs
from .volumes import volume_change

PRECISION = retrim.PRECISION


def replace_region(shape, faces, label="faces"):
    """``shape`` with the region's faces (``faces``: :class:`surfcomp.app.region.RegionFace`
    with ``part_surface`` set) rebuilt on their corrected surfaces, sharing their common
    edges, and the neighbours outside the region re-trimmed to meet them:
    ``(shape, plans, new faces by index)``."""
    region = [shape.Faces[f.index] for f in faces]
    plans, built = [], []
    for f in faces:
        plan = retrim.plan(shape, f.index, f.bface, f.part_surface, label, region)
        plans.append(plan)
        built.append(rebuild_face(f.bface, f.part_surface, plan.pcurves()))
    built = _sewn(built, plans)
    new, pairs, done = {}, [], []
    for f, plan, face in zip(faces, plans, built):
        new[f.index] = face
        for old, rep in replacement_pairs(shape.Faces[f.index], face, f.part_surface, plan):
            # a vertex two corrected faces share is one vertex of the sewn faces
            if not any(old.isSame(o) for o in done):
                done.append(old)
                pairs.append((old, rep))
    out = shape.replaceShape(pairs)
    out.fix(1e-7, 1e-7, PRECISION)
    return out, plans, new


def _sewn(built, plans):
    """The rebuilt faces, those sharing an edge sharing one edge (their corrected surfaces
    meet there up to the fit), in the same order: sewn at PRECISION, or where sewing leaves
    an edge apart (it does on the 10 m faces of a pipe), with the second face taking the
    first one's edge and vertices (:func:`_shared`). OpenCASCADE's general fuse would
    join them too, but takes minutes on a pair of large faces."""
    import Part

    common = sum(p.kind == retrim.REGION for plan in plans for p in plan.edges) // 2
    if not common:
        return built
    for face in built:      # its edges get 3D curves (sewing compares them)
        face.fix(1e-7, 1e-7, PRECISION)
    shell = Part.Compound(built)
    shell.sewShape(PRECISION)
    if len(shell.Edges) == sum(len(f.Edges) for f in built) - common:
        faces = _centres(shell)
        return [_matching(faces, f) for f in built]
    return _shared(built, plans)


def _shared(built, plans):
    """The rebuilt faces, the second of two sharing an edge taking the first one's edge
    and vertices, its pcurve on the second surface added by OpenCASCADE's fix."""
    import Part

    shared, out = [], []
    for plan, face in zip(plans, built):
        bs = face.Surface
        swap = []
        for p in plan.edges:
            if p.kind != retrim.REGION:
                continue
            c2d, a, b = p.pcurve
            mid = c2d.value(0.5 * (a + b))
            mine = _nearest(face.Edges, bs.value(mid.x, mid.y), "edge")
            theirs = next((e for old, e in shared if old.isSame(p.edge)), None)
            if theirs is None:
                shared.append((p.edge, mine))
                continue
            # the same edge (one TShape), oriented as this face runs along it
            along = (mine.valueAt(mine.FirstParameter)
                     - theirs.valueAt(theirs.FirstParameter)).Length < 10 * PRECISION
            same = Part.Edge(theirs)
            same.Orientation = mine.Orientation if along else \
                ("Reversed" if mine.Orientation == "Forward" else "Forward")
            swap.append((mine, same))
            for v in theirs.Vertexes:
                own = _nearest(face.Vertexes, v.Point, "vertex")
                swap.append((own, _oriented(Part.Vertex(v), own)))
        if swap:
            face = face.replaceShape(swap)
            face.fix(1e-7, 1e-7, PRECISION)
        out.append(face)
    return out


def neighbours(faces, plans):
    """Per edge a region face shares with a face outside it: the faces, the edge, what was
    done to it and how far the correction moves it; and the re-trimmed faces' names."""
    inside = {f.index + 1 for f in faces}
    edges, cut = [], set()
    for f, plan in zip(faces, plans):
        for p in plan.edges:
            if p.kind not in (retrim.KEPT, retrim.RETRIM):
                continue
            edges.append({"face": f.name, "neighbour": "Face%d" % plan.names.face_no(p.neighbour),
                          "edge": "Edge%d" % plan.names.edge_no(p.edge), "kind": p.kind,
                          "move_um": p.move * 1e3})
        cut.update(k for k in plan.retrimmed_faces() if k not in inside)
    return edges, ["Face%d" % k for k in sorted(cut)]


def _tolerance(shape):
    return max([e.Tolerance for e in shape.Edges] + [v.Tolerance for v in shape.Vertexes])


def _centres(shape):
    """``shape``'s faces with their centres and areas, told once: ``[(face, centre, area)]``
    (OpenCASCADE integrates each face for them: on a solid of 190 faces, asking again for
    every face looked for took two thirds of a region's run)."""
    return [(g, g.CenterOfMass, g.Area) for g in shape.Faces]


def _matching(faces, face):
    """The face of ``faces`` (:func:`_centres`) that is ``face`` after the fuse (same area
    and centre)."""
    c, area = face.CenterOfMass, face.Area
    return min(faces, key=lambda t: (t[1] - c).Length + abs(t[2] - area))[0]


def closed_solid(shape, faces, integral, label="faces"):
    """The one closed valid solid ``shape`` (itself one) becomes with the region corrected
    and its neighbours re-trimmed, and its figures: ``(solid, dict)``. ``integral``: the
    correction's integral over the region (mm^3, positive inwards)."""
    import Part

    out, plans, new = replace_region(shape, faces, label)
    edges, cut = neighbours(faces, plans)
    shells = out.Shells
    if len(shells) != 1 or not shells[0].isClosed():
        raise GeometryError("the corrected faces do not close the solid again at %g mm (the "
                            "continuity figures above show where)" % PRECISION)
    solid = Part.Solid(shells[0])
    if solid.Volume < 0:
        solid.reverse()
    tol = max(e.Tolerance for e in solid.Edges)
    # the faces the correction touched: the region's and the re-trimmed neighbours'
    touched = [new[f.index] for f in faces] + [out.Faces[int(n[4:]) - 1] for n in cut]
    centres = _centres(solid)
    local = max(_tolerance(_matching(centres, g)) for g in touched)
    problems = []
    if not solid.isValid():
        problems.append("not valid")
    if len(solid.Faces) != len(shape.Faces):
        problems.append("%d faces instead of %d" % (len(solid.Faces), len(shape.Faces)))
    # a nominal whose own edges carry a larger tolerance (a Rhino export: 0.06 mm, its faces'
    # edges that far apart) keeps it; the correction may widen it by a tenth
    nominal_tol = max(e.Tolerance for e in shape.Edges)
    allowed = PRECISION + (1.1 * nominal_tol if nominal_tol > PRECISION else nominal_tol)
    if tol > allowed:
        problems.append("edge tolerance %.3g mm (more than %.3g mm)" % (tol, allowed))
    if problems:
        raise GeometryError("the corrected region does not give a valid solid (%s)"
                            % ", ".join(problems))
    bb = geometry_box(shape)
    centre = np.array([bb.Center.x, bb.Center.y, bb.Center.z])
    change = 0.0
    for f, plan in zip(faces, plans):
        nominal = SimpleNamespace(bspline_face=f.bface, surface=f.surface, outward=f.outward)
        change += volume_change(nominal, f.built.surface, new[f.index], plan, centre)
    return solid, {"integral_mm3": -integral, "change_mm3": change,
                   "occt_change_mm3": solid.Volume - shape.Solids[0].Volume,
                   "edge_tolerance_mm": tol, "nominal_edge_tolerance_mm": nominal_tol,
                   "touched_edge_tolerance_mm": local,
                   "relative_error": (abs(change + integral) / abs(integral)
                                      if abs(integral) >= NIL_INTEGRAL else None),
                   "retrimmed_faces": cut, "neighbour_edges": edges}
