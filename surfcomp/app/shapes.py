"""The one face builder: the corrected face (and the nominal's shape with it) for every
route - the command line's ``-o``, the freecadcmd job, the document features and the GUI.

The corrected surface has the nominal's UV parametrisation, so the nominal face's boundary
(outer wire and holes, as 2D curves on the surface) is rebuilt on it unchanged: a trimmed
face stays trimmed, holes stay holes.
"""

import FreeCAD  # noqa: F401  (Part needs FreeCAD imported first)
import Part

from ..errors import GeometryError
from .convert import surface_to_part

#: a solid whose face was replaced gets its edges' tolerance raised to cover the shift of
#: the face border inside the neighbouring faces (mm): refuse larger shifts
MAX_EDGE_TOLERANCE = 1.0


def rebuild_face(face, bs):
    """The face ``face`` with its surface replaced by ``bs`` (same parametrisation).

    The boundary is rebuilt from the face's own 2D curves (pcurves) on the new surface,
    so trimmed faces and holes keep their place in parameter space; edges come in the
    order of ``face.Edges``.
    """
    outer = face.OuterWire
    wires = [outer] + [w for w in face.Wires if not w.isSame(outer)]
    new_wires = []
    for w in wires:
        edges = []
        for e in w.Edges:
            c2d, a, b = face.curveOnSurface(e)[:3]
            edges.append(c2d.toShape(bs, a, b))
        new_wires.append(Part.Wire(edges))
    out = Part.Face(bs, new_wires[0])
    if len(new_wires) > 1:
        out = out.cutHoles(new_wires[1:]) or out
    if face.Orientation == "Reversed":
        out.reverse()
    if not out.isValid():
        out.fix(1e-7, 1e-7, 1e-4)
    if not out.isValid() or len(out.Edges) != len(face.Edges):
        raise GeometryError("cannot rebuild %s on the corrected surface (%d edges instead of "
                            "%d)" % ("the face", len(out.Edges), len(face.Edges)))
    return out


def corrected_shape(nominal, corrected, output="face", label="compensation"):
    """The output shape of a compensation: ``(shape, max_edge_tolerance)``.

    Parameters
    ----------
    nominal : surfcomp.app.nominal.Nominal
        ``nominal.face`` is the face in ``nominal.shape``.
    corrected : surfcomp.core.bspline.Surface
    output : {'face', 'solid'}
        ``solid``: ``nominal.shape`` with the face (and its edges and vertices) replaced;
        the neighbouring faces keep their surfaces, their shared edges get the tolerance
        that covers the shift of the border (reported, at most
        :data:`MAX_EDGE_TOLERANCE`). Same number and order of faces.
    """
    bs = surface_to_part(corrected)
    old = nominal.face
    new = rebuild_face(old, bs)
    if output == "face":
        return new, max(e.Tolerance for e in new.Edges)
    shape = nominal.shape
    idx = int(nominal.face_name[4:]) - 1
    old = shape.Faces[idx]
    new = rebuild_face(old, bs)
    pairs = [(old, new)]
    for a, b in zip(old.Edges, new.Edges):
        pairs.append((a, b))
    for a, b in zip(old.Vertexes, new.Vertexes):
        pairs.append((a, b))
    out = shape.replaceShape(pairs)
    out.fix(1e-7, 1e-7, MAX_EDGE_TOLERANCE)
    problems = []
    if not out.isValid():
        problems.append("not valid")
    if len(out.Faces) != len(shape.Faces):
        problems.append("%d faces instead of %d" % (len(out.Faces), len(shape.Faces)))
    if len(out.Solids) != len(shape.Solids):
        problems.append("%d solids instead of %d" % (len(out.Solids), len(shape.Solids)))
    if not problems:
        for k, (a, b) in enumerate(zip(shape.Faces, out.Faces)):
            if k != idx and a.Surface.TypeId != b.Surface.TypeId:
                problems.append("Face%d changed its type" % (k + 1))
                break
        if out.Faces[idx].Surface.TypeId != "Part::GeomBSplineSurface":
            problems.append("%s is not the corrected surface" % nominal.face_name)
    if problems:
        raise GeometryError("%s: cannot replace %s in the nominal's shape (%s); use Output = "
                            "face" % (label, nominal.face_name, ", ".join(problems)))
    return out, max(e.Tolerance for e in out.Edges)
