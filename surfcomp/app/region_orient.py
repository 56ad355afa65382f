# SPDX-License-Identifier: LGPL-2.1-or-later
"""Outward normals of a region's faces when no solid orients them (issue 30; app layer).

A face's outward normal is ``Su x Sv`` turned by its ``Orientation``; in a solid the faces'
orientations agree (every edge is run through once in each direction by the two faces
sharing it). A compound of faces read from separate files need not: the BladeX blade's
pressure side and tip cap, as read from their IGES files, face into the blade (the pressure
side's normal points at the suction side 3.5 mm away, the tip cap's to +z at the blade's -z
end). Taken as they are, the sides would meet at 40 to 180 degrees where they really meet
at 0 to 143, and their deviations would be taken along the wrong side.

:func:`orient` makes the faces of each connected part of the region agree, edge by edge:
two faces sharing an edge must run through it in opposite directions (the edge's direction
in a face is its curve's, reversed where the face takes the edge ``Reversed``, which
includes the face's own orientation). Which side of an agreeing set is outside is then
decided by the enclosed volume ``1/3 sum integral (x - c) . n dA``, which is positive for
outward normals, where the part closes (every edge of its faces shared); an open part keeps
the orientation most of its faces have.
"""

import numpy as np

from ..core.surface.bspline import derivatives
from ..core.surface.trimmed import inside
from ..errors import GeometryError
from .face_data import geometry_box
from .region import run_direction, shared_edges

#: parameter samples per direction for the enclosed volume
VOLUME_SAMPLES = 80


def _agree(faces, edges):
    """Per shared edge: (a, b, True when a and b run through it in opposite directions)."""
    out = []
    for e in edges:
        ra = run_direction(faces[e.a].face.Edges[e.edge_a], e.samples)
        rb = run_direction(faces[e.b].face.Edges[e.edge_b], e.samples)
        out.append((e.a, e.b, ra != rb))
    return out


def _volume(faces, flip, members):
    """Enclosed volume (mm^3) of the faces ``members`` with the outward signs ``flip``
    applied (positive: the normals point out)."""
    pts = np.concatenate([np.array(tuple(geometry_box(faces[i].face).Center))[None]
                          for i in members])
    c = np.mean(pts, axis=0)
    total = 0.0
    for i in members:
        f = faces[i]
        u0, u1, v0, v1 = f.bface.ParameterRange
        n = VOLUME_SAMPLES
        us = u0 + (np.arange(n) + 0.5) * (u1 - u0) / n
        vs = v0 + (np.arange(n) + 0.5) * (v1 - v0) / n
        U, V = np.meshgrid(us, vs, indexing="ij")
        ok = inside(f.polylines, U.ravel(), V.ravel())
        S, Su, Sv = derivatives(f.surface, U.ravel()[ok], V.ravel()[ok], order=1)
        flux = np.einsum("ij,ij->i", S - c, np.cross(Su, Sv))
        total += f.outward * flip[i] * float(np.sum(flux)) * (u1 - u0) * (v1 - v0) / n / n
    return total / 3.0


def orient(shape, faces):
    """Turn the ``outward`` sign of the region's faces so they agree (module docstring).

    Faces of one solid are left as they are (the solid orients them). Returns the names of
    the faces whose outward normal is taken against their own orientation.

    Raises
    ------
    GeometryError
        The faces cannot agree (a one-sided surface, or edges matched wrongly).
    """
    if len(faces) < 2 or len(shape.Solids) == 1:
        return []
    edges = shared_edges(shape, faces, angles=False)
    links = {i: [] for i in range(len(faces))}
    for a, b, same in _agree(faces, edges):
        links[a].append((b, same))
        links[b].append((a, same))
    flip = {}
    turned = []
    for start in range(len(faces)):
        if start in flip:
            continue
        flip[start] = 1
        members, todo = [start], [start]
        while todo:
            i = todo.pop()
            for j, same in links[i]:
                want = flip[i] if same else -flip[i]
                if j not in flip:
                    flip[j] = want
                    members.append(j)
                    todo.append(j)
                elif flip[j] != want:
                    raise GeometryError(
                        "%s and %s cannot be given agreeing outward normals (their shared "
                        "edges are run through inconsistently): correct them apart"
                        % (faces[i].name, faces[j].name), options=("faces",))
        shared = {(e.a, e.edge_a) for e in edges} | {(e.b, e.edge_b) for e in edges}
        closed = all((i, k) in shared for i in members
                     for k, ed in enumerate(faces[i].face.Edges)
                     if not ed.Degenerated and ed.Length >= 1e-6)
        if closed and len(members) > 1:
            sign = 1 if _volume(faces, flip, members) > 0 else -1
        else:
            sign = 1 if sum(flip[i] for i in members) >= 0 else -1
        for i in members:
            if flip[i] * sign < 0:
                faces[i].outward = -faces[i].outward
                turned.append(faces[i].name)
    return turned
