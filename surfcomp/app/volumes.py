# SPDX-License-Identifier: LGPL-2.1-or-later
"""The volume a replaced face adds to or removes from its solid, and the correction's integral.

OCCT's default volume integration (``Shape.Volume``) is off by about 1e-4 of the volume on
trimmed B-spline faces - a few percent of the change a correction of some micrometres
makes. The change is computed here instead by the divergence theorem over the faces that
changed: with ``F(x) = (x - c) / 3`` (``div F = 1``),

    dV = [flux of F through the corrected face - through the nominal face]
         + sum over re-trimmed neighbours of the flux through the strip they gained or lost,
         + the same for the kept edges (moved by at most retrim.PRECISION, the gap closed
           by the edge's tolerance: up to 1 % of a change of micrometres over a long edge),

the first term by :func:`surfcomp.core.surface.trimmed.domain_integral` over both faces' (u, v)
regions on one scan grid broken at the knots of both surfaces, the strips from the re-trimmed
edges' samples (strip width times the flux density, along the edge; their error is of
second order in the correction).
"""

import numpy as np

from ..core.surface import bspline
from ..core.surface.trimmed import MAX_KNOTS, correction_integral, domain_integral, knots_of
from .face_data import geometry_box
from .nominal import boundary_polylines
from .retrim import KEPT

#: the trapezoidal rule: ``numpy.trapezoid`` since numpy 2.0, where ``trapz`` is deprecated
_trapezoid = getattr(np, "trapezoid", None) or np.trapz



def correction_volume(nominal, corrected):
    """The integral of the correction over the (trimmed) nominal face (mm^3, positive =
    material removed): :func:`surfcomp.core.surface.trimmed.correction_integral` inside the face's
    boundary in (u, v)."""
    surface = nominal.surface
    if nominal.untrimmed:
        (u0, u1), (v0, v1) = surface.u_range, surface.v_range   # the tensor rule's case
        lines = [np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1], [u0, v0]])]
    else:
        lines = boundary_polylines(nominal.bspline_face)
    return correction_integral(surface, corrected, nominal.outward, lines)


def _flux(s, su, sv, outward, centre):
    return outward * np.einsum("...j,...j->...", s - centre, np.cross(su, sv)) / 3.0


def _flux_density(surface, outward, centre):
    """``(func, grid)`` of the flux density for :func:`domain_integral`: point by point
    and on a tensor grid."""
    def func(u, v):
        return _flux(*bspline.derivatives(surface, u, v, order=1), outward, centre)

    def grid(us, vs):
        return _flux(*bspline.evaluate_grid(surface, us, vs, order=1), outward, centre)
    return func, grid


def _box(*polylines):
    pts = np.concatenate([p for group in polylines for p in group])
    (u0, v0), (u1, v1) = pts.min(0), pts.max(0)
    return u0, u1, v0, v1


def _strip_flux(p, centre, samples):
    """Flux of F through the strip the neighbour of re-trimmed edge ``p`` loses (its
    boundary moved into it) or gains: ``-integral (F . n_g) (d . m) ds``, ``d`` the move of
    the edge, ``m`` the unit vector into the neighbour across the edge."""
    import FreeCAD

    ts, old, new, ab = samples
    g = p.neighbour
    normals = np.array([tuple(g.normalAt(float(a), float(b))) for a, b in ab])
    deriv = np.gradient(old, ts, axis=0)
    speed = np.linalg.norm(deriv, axis=1)
    across = np.cross(normals, deriv / speed[:, None])
    k = len(ts) // 2
    step = min(0.01, 1e-3 * geometry_box(g).DiagonalLength)
    probe = FreeCAD.Vector(*(old[k] + step * across[k]))
    if not g.isPartOfDomain(*g.Surface.parameter(probe)):
        across = -across
    move = np.einsum("ij,ij->i", new - old, across)
    density = np.einsum("ij,ij->i", (old - centre) / 3.0, normals)
    return -float(_trapezoid(density * move * speed, ts))


def _kept_samples(p, nominal, corrected, n=33):
    """``(t, nominal points, corrected points, (a, b) on the neighbour)`` along kept edge
    ``p`` (its pcurve is the nominal's on both surfaces)."""
    import FreeCAD

    c2d, a, b = p.pcurve
    ts = np.linspace(a, b, n)
    uv = np.array([(w.x, w.y) for w in (c2d.value(float(t)) for t in ts)])
    old = bspline.evaluate(nominal, uv[:, 0], uv[:, 1])
    new = bspline.evaluate(corrected, uv[:, 0], uv[:, 1])
    g = p.neighbour.Surface
    ab = np.array([g.parameter(FreeCAD.Vector(*map(float, x))) for x in old])
    return ts, old, new, ab


def volume_change(nominal, corrected, new_face, plan, centre=None):
    """The solid's volume after minus before (mm^3) when the nominal face is replaced by
    ``new_face`` on ``corrected`` and its neighbours re-trimmed as ``plan`` says
    (:class:`surfcomp.app.retrim.Plan`). ``centre`` (3,): the point F is taken from (the
    face's centre by default); the faces of a region sum their changes with one centre."""
    old_lines = boundary_polylines(nominal.bspline_face)
    new_lines = boundary_polylines(new_face)
    box = _box(old_lines, new_lines)
    if centre is None:
        bb = geometry_box(nominal.bspline_face)
        centre = np.array([bb.Center.x, bb.Center.y, bb.Center.z])
    knots = knots_of(nominal.surface, corrected)
    panels = 16
    if max(len(k) for k in knots) > MAX_KNOTS:      # very fine corrections: a fixed grid
        knots, panels = knots_of(nominal.surface), 256
    # one scan grid with panels broken at both surfaces' knots: the quadrature errors of
    # the two fluxes cancel to far below the change
    func, grid = _flux_density(corrected, nominal.outward, centre)
    change = domain_integral(func, new_lines, box=box, knots=knots, panels=panels, grid=grid)
    func, grid = _flux_density(nominal.surface, nominal.outward, centre)
    change -= domain_integral(func, old_lines, box=box, knots=knots, panels=panels, grid=grid)
    for p in plan.edges:
        if p.samples is not None:
            change += _strip_flux(p, centre, p.samples)
        elif p.kind == KEPT and p.neighbour is not None and not p.seam and p.move > 0.0:
            change += _strip_flux(p, centre, _kept_samples(p, nominal.surface, corrected))
    return change
