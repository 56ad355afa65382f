# SPDX-License-Identifier: LGPL-2.1-or-later
"""Golden checks of a regenerated ball-end tool path (numpy and surfcomp.core only, so the GUI
tests use them too): the exact drop-cutter height and the Z change a correction causes.

A ball end mill of radius r dropped at (x, y) sits with its centre at distance r from the
surface. When the face moves in by ``t`` along its normal at the contact point, the tip moves
by ``-t / n_z`` (``n_z`` the normal's Z component there).
"""

import numpy as np

from surfcomp.core.compensation.corrected import realised_correction
from surfcomp.core.surface.bspline import Surface
from surfcomp.core.surface.projection import Projector

#: ``{(id(surface), min_samples): (surface, Projector)}`` of :func:`projector`
_PROJECTORS = {}


def projector(surface, n):
    """The :class:`Projector` that ``project(surface, points)`` builds for ``n`` points
    (the same seed grid, so the same answers), built once per surface and size: building
    one takes about a second on a refined face, and a drop-cutter check projects nine
    times."""
    key = (id(surface), n // 16)
    hit = _PROJECTORS.get(key)
    if hit is None or hit[0] is not surface:
        if len(_PROJECTORS) >= 8:
            _PROJECTORS.clear()
        hit = _PROJECTORS[key] = (surface, Projector(surface, min_samples=n // 16))
    return hit[1]


def drop_cutter(surface, outward, xy, z_guess, r, iterations=8):
    """Exact tool-tip Z of a ball end mill of radius r dropped on ``surface`` at ``xy``
    (N, 2): the ball centre lies at distance r from the surface (Newton on the centre
    height, d(distance)/dz = n_z at the foot point). Returns (z_tip (N,), projection)."""
    zc = np.asarray(z_guess, dtype=float) + r
    proj = projector(surface, len(zc))
    for _ in range(iterations):
        pr = proj.project(np.column_stack([xy, zc]))
        zc = zc - (pr.distance * outward - r) / (pr.normal[:, 2] * outward)
    return zc - r, proj.project(np.column_stack([xy, zc]))


def surface_to_json(s):
    """A core Surface as JSON-able data (for a GUI session's results)."""
    return {"poles": s.poles.tolist(), "knots_u": s.knots_u.tolist(),
            "knots_v": s.knots_v.tolist(), "degree_u": int(s.degree_u),
            "degree_v": int(s.degree_v),
            "weights": None if s.weights is None else np.asarray(s.weights).tolist(),
            "u_range": list(s.u_range), "v_range": list(s.v_range)}


def surface_from_json(d):
    return Surface(np.array(d["poles"]), np.array(d["knots_u"]), np.array(d["knots_v"]),
                   d["degree_u"], d["degree_v"],
                   weights=None if d["weights"] is None else np.array(d["weights"]),
                   u_range=tuple(d["u_range"]), v_range=tuple(d["v_range"]))


def shift_check(nominal, corrected, outward, before, after, r):
    """How the cutter locations ``after`` (on ``corrected``) moved from ``before`` (the same
    samples on ``nominal``), against what the correction implies.

    Returns a dict: ``mesh_before``/``mesh_after`` (largest |Z - exact drop-cutter Z| of each
    path: the mesh OpenCamLib drops the cutter on), ``dz`` (Z changes), ``expected``
    (``-t / n_z`` at each point), ``xy_moved`` (largest XY difference of paired samples).
    """
    before, after = np.asarray(before, float), np.asarray(after, float)
    z0, _ = drop_cutter(nominal, outward, before[:, :2], before[:, 2], r)
    z1, _ = drop_cutter(corrected, outward, after[:, :2], after[:, 2], r)
    _z, pr = drop_cutter(nominal, outward, after[:, :2], after[:, 2], r)
    t = realised_correction(nominal, corrected, pr.u, pr.v, outward)
    return {"mesh_before": float(np.abs(before[:, 2] - z0).max()),
            "mesh_after": float(np.abs(after[:, 2] - z1).max()),
            "dz": after[:, 2] - before[:, 2], "expected": -t / (pr.normal[:, 2] * outward),
            "xy_moved": float(np.abs(after[:, :2] - before[:, :2]).max())}


def assert_moved_by_the_correction(check, deflection):
    """The checks of a regenerated tool path on :func:`shift_check`'s figures: the XY
    samples paired (the scan lines follow the model's bounding box, which the correction
    moves by micrometres: 2.7 um in the shop document), each path on its surface's exact
    drop-cutter height within the operation's
    mesh ``deflection`` (mm), the Z changes equal to ``-t / n_z`` within it (median within a
    fifth of it) and, at the command where the correction is largest (at least 30 um), within
    half of it."""
    assert check["xy_moved"] < 0.5 * deflection
    assert check["mesh_before"] < deflection and check["mesh_after"] < deflection
    err = np.abs(check["dz"] - check["expected"])
    assert np.median(err) < 0.2 * deflection and err.max() < deflection
    k = int(np.argmax(np.abs(check["expected"])))
    assert check["expected"][k] < -0.03
    assert abs(check["dz"][k] - check["expected"][k]) < 0.5 * deflection


def feed_moves(op):
    """``[command index, X, Y, Z]`` of each G1 of a Path operation (modal axes carried over),
    for results a FreeCAD process hands back as JSON."""
    pos, out = {"X": float("nan"), "Y": float("nan"), "Z": float("nan")}, []
    for k, c in enumerate(op.Path.Commands):
        pos.update({a: v for a, v in c.Parameters.items() if a in pos})
        if c.Name in ("G1", "G01"):
            out.append([k, pos["X"], pos["Y"], pos["Z"]])
    return out


def shop_surfaces(doc, comp_name="Round2"):
    """The nominal (the compensation's nominal face) and corrected surface of a compensation
    in an open document, with the nominal's outward sense, as JSON-able data."""
    from surfcomp.app import reports
    from surfcomp.app.nominal import nominal_from_face

    comp = doc.getObject(comp_name)
    face = getattr(comp.Nominal.Shape, comp.FaceName)
    nominal = nominal_from_face(face, face_name=comp.FaceName)
    return {"nominal": surface_to_json(nominal.surface), "outward": int(nominal.outward),
            "corrected": surface_to_json(reports.corrected_surface(comp))}
