# SPDX-License-Identifier: LGPL-2.1-or-later
"""3-2-1 (RPS) alignment: six chosen points put exactly on their reference faces (no FreeCAD).

Three points on the primary face fix its normal translation and two rotations, two on the
secondary fix one translation and the last rotation, one on the tertiary the last
translation (the reference point system of VDA 5 / GOM and PolyWorks' 3-2-1). The points
are named by their ids in the measurement file (or their 1-based numbers when it has
none); each goes to the face named for its group, else to its nearest reference face. The
transform solves the six distance equations with Gauss-Newton
(:class:`surfcomp.core.measurement.align. Solver` with unit weights).
"""

import numpy as np

from ...errors import InputError
from .align import DOF_NAMES, MAX_ITER, STEP_TOL, Distances, Solver

#: the groups of a 3-2-1 set and their sizes
GROUPS = (("primary", 3), ("secondary", 2), ("tertiary", 1))
#: three primary points are collinear when the triangle's smallest height is below this
#: share of its longest side
COLLINEAR = 1e-3


def point_indices(spec, ids, n, source=None):
    """Indices (into the points) of the groups of ``spec`` (``{"primary": [id, id, id],
    "secondary": [id, id], "tertiary": [id]}``): ids are matched to the measurement file's
    point ids, or when it has none, read as 1-based point numbers.

    Returns
    -------
    dict group -> list of int
    """
    if not isinstance(spec, dict):
        raise InputError("a 3-2-1 set must name its points as {\"primary\": [3 ids], "
                         "\"secondary\": [2 ids], \"tertiary\": [1 id]}", file=source)
    lookup = None
    if ids is not None:
        lookup = {}
        for k, i in enumerate(ids):
            lookup.setdefault(str(i).strip(), []).append(k)
    out = {}
    for group, size in GROUPS:
        got = spec.get(group)
        got = got.get("points") if isinstance(got, dict) else got
        if not isinstance(got, list) or len(got) != size:
            raise InputError("3-2-1: \"%s\" needs %d point id(s), got %s"
                             % (group, size, "none" if got is None else repr(got)), file=source)
        out[group] = [_index(x, lookup, n, group, source) for x in got]
    every = sum(out.values(), [])
    if len(set(every)) != len(every):
        raise InputError("3-2-1: a point is named twice (expected six different points)",
                         file=source)
    return out


def _index(x, lookup, n, group, source):
    key = str(x).strip()
    if lookup is not None:
        if key not in lookup:
            raise InputError("3-2-1 %s: no point with the id %r in the measurement file"
                             % (group, key), file=source)
        if len(lookup[key]) > 1:
            # which of them the fit should take, the file does not say
            raise InputError("3-2-1 %s: the id %r names %d points of the measurement file "
                             "(points %s; expected an id that names one point)"
                             % (group, key, len(lookup[key]),
                                ", ".join(str(k + 1) for k in lookup[key][:5])), file=source)
        return lookup[key][0]
    if not key.isdigit() or not 1 <= int(key) <= n:
        raise InputError("3-2-1 %s: %r is not a point number 1 .. %d (the measurement file "
                         "has no point ids)" % (group, key, n), file=source)
    return int(key) - 1


def check_geometry(P, groups, source=None):
    """Refuse collinear primary points and coincident secondary points."""
    a, b, c = P[groups["primary"]]
    sides = [np.linalg.norm(b - a), np.linalg.norm(c - b), np.linalg.norm(a - c)]
    area2 = np.linalg.norm(np.cross(b - a, c - a))
    longest = max(sides)
    if longest == 0 or area2 / longest < COLLINEAR * longest:
        raise InputError("3-2-1: the three primary points are collinear (their triangle's "
                         "height is %.3g mm over a %.3g mm side; expected three points "
                         "spread over the primary face)"
                         % (area2 / longest if longest else 0.0, longest), file=source)
    d, e = P[groups["secondary"]]
    if np.linalg.norm(d - e) < COLLINEAR * longest:
        raise InputError("3-2-1: the two secondary points coincide (expected two points apart "
                         "on the secondary face)", file=source)


def rps_fit(points, spec, references, ids=None, start=None, offset=0.0, max_iter=MAX_ITER,
            tol=STEP_TOL, source=None):
    """The rigid transform putting the 3-2-1 points on their faces.

    Parameters
    ----------
    points : ndarray (N, 3)
        All measured points (mm).
    spec : dict
        Groups (:func:`point_indices`); a group may be ``{"points": [...], "face": name}``
        to name its reference face.
    references : list of surfcomp.core.measurement.align.Reference
    ids : list of str, optional
        The points' ids in the measurement file.
    start : ndarray (4, 4), optional
        Known transform to start from.

    Returns
    -------
    (surfcomp.core.measurement.align.Fit, ndarray of int (6,))
        The fit of the six points, and their indices.
    """
    P = np.asarray(points, dtype=float)
    groups = point_indices(spec, ids, P.shape[0], source)
    idx = np.array(sum((groups[g] for g, _ in GROUPS), []))
    start = np.eye(4) if start is None else start
    check_geometry(P @ start[:3, :3].T + start[:3, 3], groups, source)
    assign = _faces(spec, references, source)
    dist = Distances(references, 6)
    solver = Solver(dist, DOF_NAMES, robust=False, offset=offset, tol=tol,
                    names=[r.name for r in references])
    fit = solver.run(P[idx], start, max_iter, assign, weights=np.ones(6))
    if not fit.converged:
        raise InputError("the 3-2-1 alignment did not converge in %d iterations (expected "
                         "the six points near their faces)" % max_iter, file=source)
    return fit, idx


def _faces(spec, references, source):
    names = [r.name for r in references]
    faces = []
    for group, size in GROUPS:
        g = spec[group]
        name = g.get("face") if isinstance(g, dict) else None
        if name is None:
            return None
        if name not in names:
            raise InputError("3-2-1 %s: face %r is not a reference face (expected one of %s, "
                             "given by align_faces)" % (group, name, ", ".join(names)),
                             file=source, options=("align_faces",))
        faces += [names.index(name)] * size
    return np.array(faces)
