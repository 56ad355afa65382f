# SPDX-License-Identifier: LGPL-2.1-or-later
"""A compensation object's measured points aligned to its nominal (FreeCAD, no GUI).

The settings are properties of the measurement object (``AlignMethod``, ``AlignFaces``,
``AlignDof``, ``AlignRps``, ``AlignTransform``: the measurement knows its frame); the
result goes to the compensation (``AlignMatrix``, ``Alignment``). Messages name those
properties.
"""

import json

import numpy as np

from ..core.measurement.align import check_rigid, describe, parse_dof
from ..core.measurement.align_report import AlignOptions, summary_lines
from ..errors import InputError
from ..io.align_files import read_rps, read_transform
from .properties import property_text


def options_of(meas):
    """The :class:`AlignOptions` of a measurement object, checked (None: no alignment)."""
    return options_from(meas.Label, getattr(meas, "AlignMethod", "none"),
                        meas.AlignFaces, meas.AlignDof, meas.AlignRps,
                        list(getattr(meas, "AlignTransform", []) or []))


def options_from(label, method, faces, dof, rps, matrix):
    """The :class:`AlignOptions` of Align* property values (``matrix``: 16 numbers or
    none), checked, with messages naming the properties of ``label`` (None: no
    alignment). The task panel checks its fields with it before writing them."""
    if method == "none" and not matrix:
        return None
    if matrix and len(matrix) != 16:
        raise InputError("%s: AlignTransform holds %d numbers (expected 16: the 4x4 matrix "
                         "row-major, or none)" % (label, len(matrix)))
    transform = check_rigid(np.reshape(matrix, (4, 4)), label) if matrix else None
    dof = dof or "all"
    parse_dof(dof, "%s: AlignDof" % label)
    groups = None
    if method == "rps":
        if not rps.strip():
            raise InputError("%s: AlignMethod rps needs AlignRps (the 3-2-1 point ids, "
                             "P1,P2,P3;P4,P5;P6)" % label)
        groups = rps_groups(rps, label)
    names = tuple(f.strip() for f in faces.split(",") if f.strip())
    return AlignOptions(method, names, dof, groups, transform, label).validate()


def transform_from_file(path):
    """The 16 numbers (row-major) of a transform file (:mod:`surfcomp.io.align_files`),
    checked for rigidity: what ``AlignTransform`` keeps (the file is not needed again)."""
    return [float(x) for x in np.ravel(check_rigid(read_transform(path), path))]


def rps_from_file(path):
    """The ``AlignRps`` value of a 3-2-1 JSON file (its ids kept, not its path)."""
    groups, _source = read_rps(path)
    if not isinstance(groups, dict):
        raise InputError("expected a JSON object {\"primary\": [3 ids], \"secondary\": "
                         "[2 ids], \"tertiary\": [1 id]}", file=path)
    return rps_text(groups)


def transform_text(matrix):
    """``translation x y z mm, rotation a b c deg`` of 16 numbers, or ``none``."""
    if not matrix:
        return "none"
    d = describe(np.reshape(np.asarray(matrix, dtype=float), (4, 4)))
    return ("translation %s mm, rotation %s deg about X, Y, Z"
            % (" ".join("%+.4f" % x for x in d["translation_mm"]),
               " ".join("%+.4f" % x for x in d["rotation_deg"])))


def rps_groups(text, label):
    """The 3-2-1 groups of an ``AlignRps`` value: inline ids ``P1,P2,P3;P4,P5;P6`` or the
    JSON object of a 3-2-1 file (kept in the document, not the file's path)."""
    text = text.strip()
    if not text.startswith("{"):
        return read_rps(text)[0]
    try:
        return json.loads(text)
    except ValueError as exc:
        raise InputError("%s: AlignRps is not valid JSON: %s (expected P1,P2,P3;P4,P5;P6 or "
                         "a 3-2-1 file's JSON object)" % (label, exc)) from None


def rps_text(groups):
    """The ``AlignRps`` value of 3-2-1 groups: inline ids when every group is a plain list
    of ids, else the JSON object (a group naming its face)."""
    if not groups:
        return ""
    names = ("primary", "secondary", "tertiary")
    if all(isinstance(groups.get(n), list) for n in names) and not any(
            "," in str(i) or ";" in str(i) for n in names for i in groups[n]):
        return ";".join(",".join(str(i) for i in groups[n]) for n in names)
    return json.dumps(groups, sort_keys=True)


def settle(meas, opts):
    """Write :class:`AlignOptions` (checked) to a measurement object's Align* properties:
    the command line's --align options kept in the document, so a recompute aligns the
    same way."""
    meas.AlignMethod = opts.method
    meas.AlignFaces = ",".join(opts.faces)
    meas.AlignDof = opts.dof or "all"
    meas.AlignRps = rps_text(opts.rps)
    meas.AlignTransform = ([] if opts.transform is None else
                           [float(x) for x in np.ravel(opts.transform)])


def aligned(meas, nominal, ms, tip_radius=0.0):
    """``(measurement set, Alignment or None)``: ``ms`` (in the nominal's coordinates) with
    its points aligned as ``meas`` says."""
    from .alignment import align_set

    opts = options_of(meas)
    if opts is None:
        return ms, None
    return align_set(opts, nominal, ms, tip_radius, source=meas.Label)


def trial(comp, opts):
    """The :class:`Alignment` of ``opts`` on a compensation's measured points, nothing
    written: raises what the recompute would raise with these settings (a collinear 3-2-1
    set, a fit that does not converge), so a task panel can refuse them first. None
    without an alignment."""
    from . import features
    from .alignment import align_set

    if opts is None:
        return None
    nominal, placement = features.nominal_of(comp)
    ms = features.local_measurements(features.measurement_set(comp.Measurement), placement)
    return align_set(opts, nominal, ms, features.options_of(comp).tip_radius,
                     source=comp.Measurement.Label)[1]


def store(obj, alignment):
    """Write an alignment's result to a compensation object (empty without one)."""
    if not hasattr(obj, "AlignMatrix"):
        return
    d = None if alignment is None else alignment.as_dict()
    obj.AlignMatrix = [] if d is None else [float(x) for row in d["matrix"] for x in row]
    obj.Alignment = [] if d is None else summary_lines(d) + [property_text(w) for w in
                                                            alignment.warnings]
