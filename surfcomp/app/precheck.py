# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measured points against a nominal face before they enter the document (the import
preview): the same location and plausibility checks the deviation map runs
(:func:`surfcomp.core.compensation.pipeline.prepare`: distance from the face within the max offset,
inside its border, normals on the outward side, deviations within the max offset), so a
unit choice that puts the points off the face is shown in the preview, not by a failed
map later.
"""

from ..core.compensation.pipeline import Options, prepare
from ..errors import SurfcompError
from .features import is_compensation, is_measurement, local_measurements, nominal_in


def nominal_candidate(doc):
    """``(object, 'FaceN')`` of the only object of ``doc`` with one B-spline face to take as
    the nominal (surfcomp's own objects left out), else None."""
    from .face_data import pick_face

    found = []
    for obj in doc.Objects if doc is not None else []:
        shape = getattr(obj, "Shape", None)
        if shape is None or is_compensation(obj) or is_measurement(obj) or shape.isNull():
            continue
        try:
            found.append((obj, pick_face(shape, None, source=obj.Label)[1]))
        except SurfcompError:
            continue
    return found[0] if len(found) == 1 else None


def check_on_face(nom_obj, face_name, ms, max_offset=1.0):
    """``(errors, warnings)`` (lists of str) of a measurement set located on face
    ``face_name`` (None: the only B-spline face) of ``nom_obj``, as the deviation map with
    the default options locates it; the first failed check is the one error."""
    try:
        nominal, placement = nominal_in(nom_obj, face_name)
        local = local_measurements(ms, placement)
        prepared = prepare(nominal.surface, nominal.outward, local,
                           Options(max_offset=max_offset, context="document"))
    except SurfcompError as exc:
        return [str(exc)], []
    return [], [w for w in prepared.warnings if w not in (ms.warnings or [])]
