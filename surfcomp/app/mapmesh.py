# SPDX-License-Identifier: LGPL-2.1-or-later
"""The mesh a colour map is drawn on (headless; the GUI only draws it).

- Trimmed faces: the mesh covers the face only, not the whole rectangle of its surface's
  (u, v) bounds: a triangle whose middle lies outside the face's boundary (outside its outer
  wire or in a hole) is left out.
- The map is drawn on the nominal face, where other objects of the document lie too: the
  nominal itself, a CAM Job's copy of the model and, after Replace, the corrected face or
  solid, which lies within the correction of the nominal. To be seen in front of them the
  mesh is lifted along the face's outward normal by :func:`lift` (more than the largest
  correction), and the measured points' markers by a little more, so the face does not cut
  them in half where it is tilted against the view.
"""

import numpy as np

from ..core import colormap
from ..core.surface import bspline
from ..core.surface.trimmed import inside
from .nominal import boundary_polylines, outside_trim

#: the map lies this fraction of the face's size (its bounding box diagonal) plus
#: LIFT_CORRECTION times the largest correction in front of the nominal face
LIFT_SIZE = 2e-4
LIFT_CORRECTION = 1.5
#: the markers lie this fraction of the face's size in front of the map
MARKER_LIFT = 4e-3


def face_mesh(nominal, samples):
    """The map mesh of ``nominal`` (:class:`~surfcomp.app.nominal.Nominal`) on ``samples``
    (mu, mv) points of its (u, v) bounds, trimmed to the face.

    Returns
    -------
    dict
        ``points`` (N, 3) mm, ``triangles`` (M, 3) int32 (those inside the face),
        ``u``, ``v`` (N,), ``normals`` (N, 3) outward unit normals, ``size`` the diagonal
        of the points' bounding box (mm), ``trimmed`` how many triangles were left out.
    """
    pts, tri, u, v = colormap.uv_grid_mesh(nominal.surface, samples)
    mid_u = u[tri].mean(axis=1)
    mid_v = v[tri].mean(axis=1)
    keep = inside(boundary_polylines(nominal.bspline_face, 200), mid_u, mid_v)
    normals = bspline.normals(nominal.surface, u, v) * float(nominal.outward)
    size = float(np.linalg.norm(np.ptp(pts, axis=0))) if len(pts) else 0.0
    return {"points": pts, "triangles": tri[keep], "u": u, "v": v, "normals": normals,
            "size": size, "trimmed": int((~keep).sum())}


def lift(size, correction):
    """How far (mm) a map is drawn in front of its nominal face: a little more than the
    largest correction ``correction`` (mm, NaN ignored), so the corrected face and the
    copies of the nominal lie behind it, plus a fraction of the face's ``size``."""
    c = np.asarray(correction, dtype=float)
    c = c[np.isfinite(c)]
    largest = float(np.abs(c).max()) if c.size else 0.0
    return LIFT_CORRECTION * largest + LIFT_SIZE * float(size)


def lifted(points, normals, distance):
    """``points`` moved ``distance`` (mm) along their unit ``normals``."""
    return np.asarray(points, dtype=float) + float(distance) * np.asarray(normals, dtype=float)


class _Located:
    """What :func:`surfcomp.app.nominal.outside_trim` reads of a prepared measurement."""

    def __init__(self, u, v, nominal):
        self.u, self.v, self.nominal = u, v, nominal


def outside_nodes(nominal, u, v, nodes):
    """The measured nodes that lie outside the trimmed face (in a hole, beyond its outer
    wire): ``(indices, distances)`` into ``nodes`` (K, 3), distances (mm) from the face."""
    u = np.asarray(u, dtype=float).ravel()
    v = np.asarray(v, dtype=float).ravel()
    nodes = np.asarray(nodes, dtype=float).reshape(-1, 3)
    fin = np.isfinite(u) & np.isfinite(v) & np.isfinite(nodes).all(axis=1)
    idx = np.flatnonzero(fin)
    if not idx.size:
        return idx, np.zeros(0)
    out, dist = outside_trim(nominal, _Located(u[idx], v[idx], nodes[idx]))
    return idx[out], dist


def map_mesh(obj, samples=None):
    """The mesh of a computed compensation's map (:func:`face_mesh` of its nominal face, in
    the nominal object's own coordinates), with ``outside``: the indices of the grid nodes
    outside the trimmed face (:func:`outside_nodes`)."""
    from .features import nominal_of

    nominal, _placement = nominal_of(obj)
    n, m = int(obj.GridRows), int(obj.GridCols)
    mesh = face_mesh(nominal, samples or colormap.mesh_resolution((n, m)))
    mesh["outside"] = outside_nodes(nominal, obj.U, obj.V, obj.Nodes)[0]
    return mesh


def mesh_key(obj):
    """What the mesh depends on: the nominal face's shape and the grid's shape."""
    nom = obj.Nominal
    shape = getattr(nom, "Shape", None)
    code = shape.hashCode() if shape is not None and hasattr(shape, "hashCode") else id(shape)
    return (getattr(nom, "Name", None), obj.FaceName, int(obj.GridRows), int(obj.GridCols),
            code)


def map_data(obj, quantity, samples=None, mesh=None, located=None):
    """Mesh and values of a computed compensation's map (no drawing); ``mesh`` as
    :func:`map_mesh` returns it (made when not given); ``located`` as
    :func:`surfcomp.app.reports.field_values` takes it (the mesh's place on the grid,
    kept between calls on the same mesh).

    Returns
    -------
    dict
        ``points`` (N, 3) lifted by ``lift`` (mm) in front of the face, ``triangles``
        (M, 3), ``values`` (N,) on the mesh, ``markers`` (K, 3) the measured nodes lifted
        a little more, ``marker_values`` (K,), ``outside`` (indices of the nodes outside
        the trimmed face), mm, in the nominal object's own coordinates.
    """
    from . import reports

    mesh = mesh if mesh is not None else map_mesh(obj, samples)
    values = reports.field_values(obj, quantity, mesh["u"], mesh["v"], located)
    nodes = np.asarray(obj.Nodes, dtype=float).reshape(-1, 3)
    normals = np.asarray(obj.Normals, dtype=float).reshape(-1, 3)
    dev = np.asarray(obj.Deviation, dtype=float)
    node_values = reports.quantity_values(obj, quantity).ravel()
    keep = np.isfinite(dev) & np.isfinite(node_values)
    up = lift(mesh["size"], obj.Correction)
    markers = nodes[keep]
    if normals.shape == nodes.shape:
        markers = lifted(markers, normals[keep], up + MARKER_LIFT * mesh["size"])
    return {"points": lifted(mesh["points"], mesh["normals"], up),
            "triangles": mesh["triangles"], "values": values, "markers": markers,
            "marker_values": node_values[keep], "outside": mesh["outside"], "lift": up,
            "size": mesh["size"]}
