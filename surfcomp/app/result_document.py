# SPDX-License-Identifier: LGPL-2.1-or-later
"""A compensation computed by script written as a FreeCAD document: the nominal shape, the
measurement and a compensation object with the same options, recomputed there
(:func:`surfcomp.api.write_document`)."""

import os

import numpy as np

from ..errors import ComputationError, InputError
from ..io.atomic import Transaction, check_outputs
from . import features

#: the option fields a compensation object holds beside those :func:`make_compensation` sets
_PROPERTIES = {"mask_kind": "MaskKind", "max_offset": "MaxOffset", "flip_normals": "Flip",
               "refine": "Refine", "lean": "Lean", "layout": "Layout",
               "tip_radius": "TipRadius"}


def weights_text(weights):
    """A custom mask as the ``Weights`` property's text (``"1 2 1; 2 4 2; 1 2 1"``)."""
    if weights is None or isinstance(weights, str):
        return weights or ""
    return "; ".join(" ".join(repr(float(w)) for w in row)
                     for row in np.atleast_2d(np.asarray(weights, dtype=float)))


def write_result_document(result, path, output="solid", inputs=()):
    """Write ``result`` (a :class:`surfcomp.api.Result`) as the document ``path``
    (``.FCStd``), all or nothing; returns ``path``.

    Raises
    ------
    InputError
        Not an ``.FCStd`` path, an unknown ``output``, or a path that is an input.
    ComputationError
        The document's compensation did not recompute (its message is named).
    """
    import FreeCAD

    if os.path.splitext(path)[1].lower() != ".fcstd":
        raise InputError("path: a document is an .FCStd file (got %r)" % os.path.basename(path))
    if output not in features.OUTPUTS:
        raise InputError("output %r: expected one of %s" % (output, ", ".join(features.OUTPUTS)))
    check_outputs([("path", path)], inputs)
    doc = FreeCAD.newDocument("SurfcompResult")
    try:
        comp = _objects(doc, result, output)
        doc.recompute()
        bad = [o for o in doc.Objects if "Invalid" in o.State or "Error" in o.State]
        if bad:
            raise ComputationError("the document's compensation did not recompute: %s"
                                   % "; ".join("%s (%s)" % (o.Label, ", ".join(o.State))
                                               for o in bad))
        if comp.Shape.isNull():
            raise ComputationError("the document's compensation has no shape")
        with Transaction([("path", path)], inputs) as tx:
            tmp = tx.stage(path)
            doc.Label = os.path.splitext(os.path.basename(path))[0]
            os.unlink(tmp)      # FreeCAD would keep the empty file as a backup (.FCStd1)
            doc.saveCopy(tmp)
            tx.commit()
    finally:
        FreeCAD.closeDocument(doc.Name)
    return path


def _objects(doc, result, output):
    """The nominal, measurement and compensation objects of ``result`` in ``doc``."""
    nominal, options = result.nominal, result.options
    shape = nominal.shape if nominal.shape is not None else nominal.face
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = shape
    nom.Label = os.path.splitext(os.path.basename(nominal.source))[0] or "Nominal"
    face = nominal.face_name if nominal.shape is not None else "Face1"
    meas = features.make_measurement_from_set(doc, result.measurements)
    comp = features.make_compensation(
        doc, nom, face, meas, method=options.method, mask_size=options.mask_size,
        weights=weights_text(options.weights), edge=options.edge, stock=options.stock or 0.0,
        output=output, accept_stock=bool(options.accept_stock))
    for name, prop in _PROPERTIES.items():
        setattr(comp, prop, getattr(options, name))
    comp.Sigma = float(options.sigma or 0.0)
    comp.Smoothing = float(options.smoothing or 0.0)       # 0: chosen by cross-validation
    return comp
