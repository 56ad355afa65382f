# SPDX-License-Identifier: LGPL-2.1-or-later
"""``compensate SOLID MEAS --faces F1,F2|auto -o OUT``: a region of faces, files in and out
(issue 30). The numerics are in :mod:`surfcomp.core.compensation.region_field` and
:mod:`surfcomp.core.compensation.region_build`, the OpenCASCADE side in
:mod:`surfcomp.app.region`."""

import json
import os

import numpy as np

from ..core import budget
from ..core.compensation import curl_cap, region_build, region_field, region_slide
from ..core.compensation.filters import WERNER_MASK_SIZE
from ..core.compensation.folds import find_fold, fold_warning
from ..core.limits import NORMAL_WARNING_DEG
from ..core.surface.trimmed import inside
from ..errors import GeometryError, InputError, MeasurementFileError
from ..io.atomic import Transaction, check_outputs
from ..io.readers import read_any
from ..io.report import json_values
from . import fcenv, region, region_retrim
from .face_data import geometry_box
from .file_route import cad_format
from .region_orient import orient
from .region_project import per_face
from .retrim import PRECISION

#: faces with fewer points than this are not taken by --faces auto
AUTO_MIN_POINTS = 10


def _base(ms):
    base = ms.nominal if ms.nominal is not None else ms.measured
    if base is None:
        raise InputError("the measurement set has neither nominal nor measured points",
                         file=ms.source)
    return np.asarray(base, dtype=float)


def _deviation(ms, normal, signed):
    if ms.deviation is not None:
        d = np.asarray(ms.deviation, dtype=float)
        if ms.normal is None:
            return d
        # a deviation is along its given normal: turned to the outward normal's side
        return np.where(np.einsum("ij,ij->i", np.asarray(ms.normal), normal) < 0, -d, d)
    if ms.nominal is not None and ms.measured is not None:
        return np.einsum("ij,ij->i", ms.measured - ms.nominal, normal)
    return signed


def run_region(nominal, measurements, faces_text, output, report=None, units="mm", fmt="auto",
               sample=None, deviation_units=None, method="filtered", mask_size=WERNER_MASK_SIZE,
               mask_kind="box", sigma=None, max_offset=1.0, min_coverage=0.5, smoothing=None,
               max_factor=region_build.POLE_FACTOR, log=print, max_memory=None, object_name=None):
    """Run a region compensation; returns the report dict. Nothing is written on error.
    ``max_memory``: refuse a measurement whose run needs more (bytes; None: the machine's),
    as the document route does; ``object_name``: the object of an FCStd nominal holding the
    faces (Name or Label), as for one face (refused for a CAD file)."""
    outputs = [("output", output)] + ([("report", report)] if report else [])
    inputs = [("nominal", nominal), ("measurements", measurements)]
    check_outputs(outputs, inputs)
    cad_format(output)
    check_options(method, mask_size, mask_kind, sigma, max_offset, smoothing)
    fcenv.import_freecad()
    import Part

    from .nominal import read_shape

    shape, _ = read_shape(nominal, object_name)
    ms = read_any(measurements, units, fmt, sample, deviation_units=deviation_units)
    budget.check_job(len(ms), True, max_memory)
    out_shape, rep = compute_region(
        shape, ms, faces_text, (nominal, measurements), method=method, mask_size=mask_size,
        mask_kind=mask_kind, sigma=sigma, max_offset=max_offset, min_coverage=min_coverage,
        smoothing=smoothing, max_factor=max_factor, log=log)
    with Transaction(outputs, inputs) as tx:
        tx.write(output, lambda tmp: _write(out_shape, tmp, Part))
        if report:
            tx.stage_text(report, json.dumps(json_values(rep), indent=1, allow_nan=False)
                          + "\n")
        tx.commit()
    return rep


def check_method(method):
    if method not in ("raw", "filtered"):
        raise InputError("faces works with method raw or filtered (got %s)" % method,
                         options=("faces", "method"))


def check_options(method, mask_size, mask_kind, sigma, max_offset, smoothing):
    """Refuse a method other than raw or filtered and values outside the domains one face
    takes (:meth:`surfcomp.core.compensation.pipeline.Options.validate`: an even mask, a
    negative max_offset or smoothing), naming the option, before anything is read."""
    from ..core.compensation.pipeline import Options

    check_method(method)
    Options(method=method, mask_size=mask_size, mask_kind=mask_kind, sigma=sigma,
            max_offset=max_offset, smoothing=smoothing).validate()


def compute_region(shape, ms, faces_text, sources, method="filtered",
                   mask_size=WERNER_MASK_SIZE, mask_kind="box", sigma=None, max_offset=1.0,
                   min_coverage=0.5, smoothing=None, max_factor=region_build.POLE_FACTOR,
                   log=print, stack=None):
    """The region of ``shape`` (faces ``faces_text``: ``'Face1,Face2'`` or ``'auto'``)
    corrected by the measurement set ``ms``; ``sources``: the nominal's and the
    measurements' names for the report and the errors; ``stack``: a function given this
    measurement's field that returns the field to correct by (an iteration adds the earlier
    rounds'). Returns ``(shape, report dict)``; nothing is written."""
    nominal, measurements = sources
    check_options(method, mask_size, mask_kind, sigma, max_offset, smoothing)
    base = _base(ms)
    chosen = region.parse_faces(faces_text, shape)
    candidates = chosen if chosen is not None else [
        k for k, f in enumerate(shape.Faces) if _near(f, base, max_offset)]
    if not candidates:      # no face's box near a point: every face is left out
        _none_near("faces auto: no face of the shape", max_offset, measurements)
    faces = [region.region_face(shape, k) for k in candidates]
    turned = orient(shape, faces)
    if turned:
        log("outward normals taken against the faces' own orientation (to agree with their "
            "neighbours'): " + ", ".join(turned))
    dist, res = region.project_all(faces, base, max_offset)
    owner, u, v, normal, signed = region.locate(faces, base, max_offset, (dist, res))
    dropped = {}
    if chosen is None:
        keep = [i for i in range(len(faces)) if np.sum(owner == i) >= AUTO_MIN_POINTS]
        if not keep:
            _none_near("faces auto: no face of the shape", max_offset, measurements)
        first = owner
        faces_all, faces = faces, [faces[i] for i in keep]  # points go to the nearest kept face
        owner, u, v, normal, signed = region.locate(faces, base, max_offset,
                                                    (dist[keep], [res[i] for i in keep]))
        dropped = _dropped(faces_all, keep, first, owner)
    names = [f.name for f in faces]
    on = owner >= 0
    if not np.any(on):
        _none_near("none of %s" % ", ".join(names), max_offset, measurements, 1)
    counts = {f.name: int(np.sum(owner == i)) for i, f in enumerate(faces)}
    none = int(np.sum(~on)) - sum(dropped.values())
    log("points per face: " + ", ".join("%s %d" % kv for kv in counts.items())
        + "; on no face: %d" % none + dropped_text(dropped))
    d = _deviation(ms, normal, signed)
    lines = np.asarray(ms.lines) if ms.lines is not None else np.arange(2, len(base) + 2)
    turned_normals = _normal_warnings(ms, normal, owner, names, lines, measurements)
    pts, dev, lines = base[on], d[on], lines[on]
    step = region_field.spacing(pts)
    # coverage of every face
    for i, f in enumerate(faces):
        samples, area = region.face_samples(f)
        f.points = counts[f.name]
        f.coverage = region_field.coverage(samples, base[owner == i], 3.0 * step, area)
        if f.coverage < min_coverage:
            raise MeasurementFileError(
                "%s: the points cover %.0f %% of the face, less than min_coverage %.0f %% "
                "(expected measurements over the whole face, or leave it out of faces)"
                % (f.name, 100 * f.coverage, 100 * min_coverage), file=measurements,
                options=("min_coverage", "faces"))
    edges = region.shared_edges(shape, faces)
    _check_connected(faces, edges, log)
    radius = 0.5 * mask_size * step
    region_field.check_straddle(pts, dev, owner[on],
                                [(e.a, e.b, e.samples) for e in edges],
                                radius, max_offset, lines, measurements, names)
    filtered = dev if method == "raw" else region_field.mask_filter_3d(
        pts, dev, mask_size, mask_kind, sigma, step)
    bb = geometry_box(shape)
    field_radius = smoothing or max(region.FIELD_SPACINGS * step,
                                    region.FIELD_SHARE * bb.DiagonalLength)
    fld = region_field.RegionField(pts, filtered, field_radius)
    if stack is not None:
        fld = stack(fld)
    fld = _cap(faces, fld, pts, field_radius)
    sharp = region.sharp_edges(faces, edges, band=field_radius, field=fld)
    closed = _closed(shape)
    if not closed:      # a compound of faces: nothing to re-trim its neighbours in
        _check_neighbours(shape, faces, fld, sharp)
    _build(faces, fld, sharp, field_radius, max_factor)
    figures = region.continuity(faces, edges)
    fidelity = _fidelity(faces, owner, u, v, fld, base, normal, sharp)
    rep = _report(nominal, measurements, faces, counts, none, figures, fidelity,
                  field_radius, step, method, mask_size)
    rep["points_on_dropped_faces"] = dropped
    for f in rep["faces"]:
        f["warnings"].extend(turned_normals.get(f["face"], ()))
    for line in summary(rep):
        log(line)
    out_shape, kind, volume = _assemble(shape, faces, fld, closed)
    rep["output"] = {"kind": kind, "faces": len(out_shape.Faces), **volume}
    for line in neighbour_lines(rep["output"]) + [output_line(rep["output"])]:
        log(line)
    return out_shape, rep


def _normal_warnings(ms, normal, owner, names, lines, source):
    """Per face name, the warnings of the file's normals more than
    :data:`surfcomp.core.limits.NORMAL_WARNING_DEG` off the normal of the point's face, as
    one face warns (the deviation is taken along the given normal, turned to the outward
    side; far off it, the point is likely another face's)."""
    if ms.normal is None:
        return {}
    cos = np.abs(np.einsum("ij,ij->i", np.asarray(ms.normal, dtype=float), normal))
    with np.errstate(invalid="ignore"):
        ang = np.degrees(np.arccos(np.clip(cos, 0.0, 1.0)))
        off = np.flatnonzero((owner >= 0) & (ang > NORMAL_WARNING_DEG))
    out = {}
    for k in off[:10]:
        name = names[owner[k]]
        out.setdefault(name, []).append(
            "%s:%d: the given normal is %.1f degrees off the normal of %s (more than %g)"
            % (source, lines[k], ang[k], name, NORMAL_WARNING_DEG))
    if off.size > 10:
        out.setdefault(names[owner[off[10]]], []).append(
            "%s: %d more normals are more than %g degrees off their face's normal"
            % (source, off.size - 10, NORMAL_WARNING_DEG))
    return out


def _none_near(what, max_offset, measurements, least=AUTO_MIN_POINTS):
    """Refuse a measurement no face of the region takes (points in other units or in
    another frame than the nominal's), naming what was looked for."""
    raise MeasurementFileError("%s has %s within max_offset %g mm (expected points on the "
                               "region, in the nominal's units and frame: wrong face list, "
                               "units or alignment?)"
                               % (what, "a point" if least == 1 else "%d points" % least,
                                  max_offset), file=measurements,
                               options=("faces", "max_offset"))


def _dropped(faces, keep, first, owner):
    """Per face left out by ``--faces auto`` (fewer than AUTO_MIN_POINTS points), the
    points nearest to it that lie on no kept face: they are on a face, not on none."""
    out = {}
    for i, f in enumerate(faces):
        if i not in keep:
            k = int(np.sum((first == i) & (owner < 0)))
            if k:
                out[f.name] = k
    return out


def dropped_text(dropped):
    """``'; on faces left out (fewer than 10 points): Face3 4'`` or ``''``."""
    if not dropped:
        return ""
    return "; on faces left out (fewer than %d points): %s" % (
        AUTO_MIN_POINTS, ", ".join("%s %d" % kv for kv in dropped.items()))


def _near(face, base, max_offset):
    """True when a point lies in the face's bounding box widened by ``max_offset``."""
    bb = geometry_box(face)
    lo = np.array([bb.XMin, bb.YMin, bb.ZMin]) - max_offset
    hi = np.array([bb.XMax, bb.YMax, bb.ZMax]) + max_offset
    return bool(np.any(np.all((base >= lo) & (base <= hi), axis=1)))


def _check_connected(faces, edges, log):
    """Faces sharing no edge with the rest of the region are corrected apart (said)."""
    if len(faces) < 2:
        return
    linked = {e.a for e in edges} | {e.b for e in edges}
    for i, f in enumerate(faces):
        if i not in linked:
            log("%s shares no edge with the other faces of the region: corrected apart (the "
                "field still takes the points within its radius)" % f.name)


def _check_neighbours(shape, faces, fld, sharp):
    """Refuse a region of a shape that is no closed solid whose correction moves an edge
    shared with a face outside it (in a solid, :mod:`surfcomp.app.region_retrim`
    re-trims those neighbours)."""
    for e in region.shared_edges(shape, faces, all_faces=True):
        f = faces[e.a]
        n = region.normals_at(f, e.samples)[0]
        move = np.abs(fld(e.samples))
        move = float(np.max(np.linalg.norm(region_build.displacement(
            e.samples, n, move, sharp), axis=1)))
        if move > PRECISION:
            raise GeometryError(
                "%s meets Face%d, which is not in the region, where the correction moves their "
                "edge by %.2f um (more than %.2g um): a neighbour of a region is re-trimmed "
                "in a closed solid only; add Face%d to faces"
                % (f.name, -e.b, move * 1e3, PRECISION * 1e3, -e.b), options=("faces",))


def _cap(faces, fld, pts, field_radius):
    """The field held short of turning a curl of the region inside out
    (:mod:`surfcomp.core.compensation.curl_cap`); the field itself where no radius of
    curvature comes near the correction."""
    step = curl_cap.SAMPLE_STEP * field_radius / 5.0       # of the build's knot step
    samples = [curl_cap.curvature_samples(f.surface, f.outward,
                                          keep=lambda U, V, f=f: inside(f.polylines, U, V),
                                          step=step) for f in faces]
    capped = curl_cap.CappedField(fld, samples, step, curl_cap.field_largest(fld, pts))
    return capped if capped.active else fld


def _build(faces, fld, sharp, field_radius, max_factor):
    """Every face's corrected surface (``f.built``, ``f.part_surface``)."""
    from .convert import surface_to_part

    plans = region_build.knot_plans([f.surface for f in faces], field_radius / 5.0,
                                    max_factor)

    def one(i):
        return region_build.corrected_surface(faces[i].surface, faces[i].outward, fld,
                                              sharp and sharp.for_face(i),
                                              knot_step=field_radius / 5.0,
                                              max_factor=max_factor, plan=plans[i])

    for f, built in zip(faces, per_face(faces, one)):
        f.built = built
        f.part_surface = surface_to_part(built.surface)


def _fidelity(faces, owner, u, v, fld, base, normal, sharp):
    """Per face: the largest |realised - intended| at its points (um), and the same beyond
    the zones where a knife edge or a vertex is moved by one vector (there the design
    itself falls short of the correction: those points' count and largest shortfall), the
    curl cap's points and the points the face's moved edge slides past
    (:mod:`surfcomp.core.compensation.region_slide`: no corrected face lies on their
    normal line; their count, largest realised - intended and slide against distance)."""
    def one(i):
        k = np.flatnonzero(owner == i)
        if not len(k):
            return None
        # the field and the capped field in one evaluation (the cap's neighbour queries
        # are most of its cost); a field the cap leaves alone is both
        raw, intended = fld.both(base[k]) if hasattr(fld, "both") else (fld(base[k]),) * 2
        short = np.abs(raw - intended)
        curl = short > 0.0
        miss = np.abs(realised(faces[i], u[k], v[k], intended) - intended) * 1e3
        share = region_build.designed_share(base[k], normal[k], sharp)
        zone = np.abs(share - 1.0) > 1e-9
        rest = ~zone & ~curl
        slide, dist = region_slide.edge_slide(base[k][rest], normal[k][rest], intended[rest],
                                              sharp and sharp.for_face(i))
        passed = np.zeros(len(k), dtype=bool)
        passed[np.flatnonzero(rest)[slide > dist]] = True
        rest &= ~passed
        near = slide > dist
        return {"all": float(np.max(miss)),
                "beyond": float(np.max(miss[rest])) if np.any(rest) else None,
                "zone_points": int(np.sum(zone)),
                "zone_shortfall": float(np.max(np.abs(intended * (1 - share))[zone]))
                * 1e3 if np.any(zone) else 0.0,
                "curl_points": int(np.sum(curl)),
                "curl_shortfall": float(np.max(short[curl])) * 1e3 if np.any(curl) else 0.0,
                "slide_points": int(np.sum(passed)),
                "slide_miss": float(np.max(miss[passed])) if np.any(passed) else 0.0,
                "slide_distance": float(np.max(dist[near])) * 1e3 if np.any(near) else 0.0,
                "slide_slide": float(np.max(slide[near])) * 1e3 if np.any(near) else 0.0}

    return {f.name: fid for f, fid in zip(faces, per_face(faces, one)) if fid is not None}


def realised(f, u, v, guess):
    from ..core.compensation.corrected import realised_correction

    return realised_correction(f.surface, f.built.surface, u, v, f.outward, guess)


def _assemble(shape, faces, fld, closed):
    """The shape with the region's faces rebuilt: in a closed solid with its neighbours
    re-trimmed (:func:`surfcomp.app.region_retrim.closed_solid`), else the faces; and the
    volume change against ``-integral(delta dA)`` over the region."""
    import Part

    from .shapes import rebuild_face

    integral = 0.0
    for f in faces:
        pts, area = region.face_samples(f, 80)
        integral += float(np.sum(fld(pts) * area))
    if closed:
        solid, figures = region_retrim.closed_solid(shape, faces, integral)
        return solid, "solid", figures
    new = {f.index: rebuild_face(f.bface, f.part_surface) for f in faces}
    return (Part.Compound([new.get(k, g) for k, g in enumerate(shape.Faces)]), "faces",
            {"integral_mm3": -integral})


def _closed(shape):
    return len(shape.Solids) == 1 and shape.Solids[0].isValid() and \
        all(s.isClosed() for s in shape.Shells)


def _report(nominal, measurements, faces, counts, none, figures, fidelity, radius, step,
            method, mask_size):
    return {
        "command": "compensate --faces",
        "inputs": {"nominal": os.path.abspath(nominal),
                   "measurements": os.path.abspath(measurements)},
        "method": method, "mask": mask_size,
        "point_spacing_mm": step, "field_radius_mm": radius,
        "faces": [{"face": f.name, "points": counts[f.name], "coverage": f.coverage,
                   "poles": list(f.built.poles), "nominal_poles": list(f.built.nominal_poles),
                   "knot_step_mm": f.built.knot_step,
                   **_fidelity_keys(fidelity.get(f.name)), **_fold_keys(f)} for f in faces],
        "points_on_no_face": none,
        "edges": figures,
    }


def _fold_keys(f):
    """The corrected face's largest turn of the normal from the nominal's within the face's
    boundary, and the warning when it folds over itself there
    (:mod:`surfcomp.core.compensation.folds`)."""
    fold = find_fold(f.surface, f.built.surface, f.outward,
                     keep=lambda U, V: inside(f.polylines, U, V))
    text = fold_warning(f.name, fold)
    return {"normal_turn": fold.as_dict(), "warnings": [text] if text else []}


def _fidelity_keys(fid):
    if fid is None:
        return {"max_realised_minus_intended_um": None}
    return {"max_realised_minus_intended_um": fid["all"],
            "max_realised_minus_intended_beyond_edge_zones_um": fid["beyond"],
            "edge_zone_points": fid["zone_points"],
            "edge_zone_max_designed_shortfall_um": fid["zone_shortfall"],
            "curl_points": fid["curl_points"],
            "curl_max_shortfall_um": fid["curl_shortfall"],
            "edge_slide_points": fid["slide_points"],
            "edge_slide_max_realised_minus_intended_um": fid["slide_miss"],
            "edge_slide_max_distance_um": fid["slide_distance"],
            "edge_slide_max_slide_um": fid["slide_slide"]}


def summary(rep):
    """The printed lines: per face, per edge, the volume."""
    lines = []
    for f in rep["faces"]:
        beyond = f.get("max_realised_minus_intended_beyond_edge_zones_um")
        lines.append("%s: %d points, coverage %.0f %%, poles %d x %d (nominal %d x %d), "
                     "realised - intended at the points %.4f um"
                     % (f["face"], f["points"], 100 * f["coverage"], *f["poles"],
                        *f["nominal_poles"], f["max_realised_minus_intended_um"]))
        if f.get("edge_zone_points"):
            lines.append("  %s: %d points near knife edges or vertices, where the edge moves "
                         "by one vector and the correction is short by up to %.4f um by "
                         "design; beyond them realised - intended %s"
                         % (f["face"], f["edge_zone_points"],
                            f["edge_zone_max_designed_shortfall_um"],
                            "-" if beyond is None else "%.4f um" % beyond))
        if f.get("curl_points"):
            lines.append("  %s: %d points where the face curls tighter than the correction "
                         "can follow (the correction is held to %g of the radius of "
                         "curvature): short by up to %.4f um by design"
                         % (f["face"], f["curl_points"], curl_cap.SHARE,
                            f["curl_max_shortfall_um"]))
        if f.get("edge_slide_points"):
            lines.append("  %s: %d points nearer to a sharp edge than the edge slides along "
                         "the face (up to %.4f um from it, the slide up to %.4f um): no "
                         "corrected face on their normal line, the corner cut back by "
                         "design; realised - intended there up to %.4f um, beyond them and "
                         "the zones %s"
                         % (f["face"], f["edge_slide_points"], f["edge_slide_max_distance_um"],
                            f["edge_slide_max_slide_um"],
                            f["edge_slide_max_realised_minus_intended_um"],
                            "-" if beyond is None else "%.4f um" % beyond))
        lines.extend("warning: " + text for text in f.get("warnings", ()))
    for e in rep["edges"]:
        lines.append("edge %s-%s (%s): largest gap %.4f um (nominal %.4f um, %.4f um more "
                     "than the nominal's at most), largest normal angle %.4f deg (nominal "
                     "%.3f deg, changed by at most %.4f deg)"
                     % (e["faces"][0], e["faces"][1], "G1" if e["g1"] else "sharp",
                        e["max_gap_um"], e["nominal_gap_um"], e["max_gap_beyond_nominal_um"],
                        e["max_angle_deg"],
                        e["nominal_angle_deg"], e["max_angle_change_deg"]))
    return lines


def output_line(o):
    """The printed line of the output shape and its volume check."""
    if o["kind"] == "solid":
        rel = o["relative_error"]
        return ("solid: %d faces, edge tolerance %.2g mm (%.2g mm on the corrected and "
                "re-trimmed faces), volume change %.4f mm3 against -integral(delta dA) %.4f "
                "mm3 (%s); re-trimmed neighbours: %s"
                % (o["faces"], o["edge_tolerance_mm"], o["touched_edge_tolerance_mm"],
                   o["change_mm3"], o["integral_mm3"],
                   "%.2f %%" % (100 * rel) if rel is not None else
                   "a nil correction: %.4f mm3 apart" % (o["change_mm3"] - o["integral_mm3"]),
                   ", ".join(o["retrimmed_faces"]) or "none"))
    return "the nominal is not one closed solid: the output is its %d faces" % o["faces"]


def neighbour_lines(o):
    """Printed lines of the edges the region shares with faces outside it."""
    return ["edge %s-%s (%s, outside the region): %s, moved by %.4f um"
            % (e["face"], e["neighbour"], e["edge"], e["kind"], e["move_um"])
            for e in o.get("neighbour_edges", ())]

def _write(shape, path, Part):
    fmt = os.path.splitext(path)[1].lower()
    if fmt in (".step", ".stp"):
        shape.exportStep(path)
    elif fmt in (".iges", ".igs"):
        shape.exportIges(path)
    else:
        shape.exportBrep(path)
