# SPDX-License-Identifier: LGPL-2.1-or-later
"""A compensation object's measured points aligned to its nominal (FreeCAD, no GUI).

The settings are properties of the measurement object (``AlignMethod``, ``AlignFaces``,
``AlignDof``, ``AlignRps``, ``AlignTransform``: the measurement knows its frame); the
result goes to the compensation (``AlignMatrix``, ``Alignment``). Messages name those
properties.
"""

import json

import numpy as np

from ..core.align import check_rigid, parse_dof
from ..core.align_report import AlignOptions, summary_lines
from ..errors import InputError
from ..io.align_files import read_rps


def options_of(meas):
    """The :class:`AlignOptions` of a measurement object, checked (None: no alignment)."""
    method = getattr(meas, "AlignMethod", "none")
    matrix = list(getattr(meas, "AlignTransform", []) or [])
    if method == "none" and not matrix:
        return None
    label = meas.Label
    if matrix and len(matrix) != 16:
        raise InputError("%s: AlignTransform holds %d numbers (expected 16: the 4x4 matrix "
                         "row-major, or none)" % (label, len(matrix)))
    transform = check_rigid(np.reshape(matrix, (4, 4)), label) if matrix else None
    dof = meas.AlignDof or "all"
    parse_dof(dof, "%s: AlignDof" % label)
    rps = None
    if method == "rps":
        if not meas.AlignRps.strip():
            raise InputError("%s: AlignMethod rps needs AlignRps (the 3-2-1 point ids, "
                             "P1,P2,P3;P4,P5;P6)" % label)
        rps = rps_groups(meas.AlignRps, label)
    faces = tuple(f.strip() for f in meas.AlignFaces.split(",") if f.strip())
    return AlignOptions(method, faces, dof, rps, transform, label).validate()


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


def store(obj, alignment):
    """Write an alignment's result to a compensation object (empty without one)."""
    if not hasattr(obj, "AlignMatrix"):
        return
    d = None if alignment is None else alignment.as_dict()
    obj.AlignMatrix = [] if d is None else [float(x) for row in d["matrix"] for x in row]
    obj.Alignment = [] if d is None else summary_lines(d) + list(alignment.warnings)
