# SPDX-License-Identifier: LGPL-2.1-or-later
"""A compensation's last result, reused while its inputs stay the same.

A document recompute runs a compensation's ``execute`` whenever the object is touched, and
the shop-document route asks for its result three times (once to raise bad input with its
file and line, once to compute the object, once in the document's recompute after the
replace): the fit, the face build and the output shape's figures are the same each time
when nothing they depend on changed. The result is kept here, one per object, keyed by a
digest of the inputs' content: the nominal surface, its face (as BREP) and placement, the
measurement data and every option (:func:`surfcomp.app.preview.fingerprint`), the output
kind, the object's label (it names the object in the warnings), the whole nominal shape
for a solid output (the re-trimmed neighbours), and the previous round's correction for an
iteration. A change to any of them misses. Nothing here is saved with the document; the
kept result is shared, so callers treat it as read-only. The :data:`KEPT` most recently
used objects keep theirs.
"""

from collections import OrderedDict

import numpy as np

from .preview import digest, fingerprint

#: results kept (the most recently used objects'): each holds the fit, the corrected
#: surface and the output shape, so a session that opened many documents keeps only these
KEPT = 4

_CACHE = OrderedDict()

#: what the next round of an iteration reads from its ``Base`` (its correction field)
BASE_PROPERTIES = ("U", "V", "Correction", "GridRows", "GridCols", "Scattered", "FieldScale")


def key(obj, nominal, placement, ms, options):
    """The digest of everything the result of compensation ``obj`` depends on."""
    parts = [fingerprint(nominal, placement, ms, options), repr(options), obj.Output,
             obj.Label, nominal.bspline_face.exportBrepToString()]
    if obj.Output == "solid" and nominal.shape is not None:
        parts.append(nominal.shape.exportBrepToString())
    base = obj.Base         # its Correction holds the earlier rounds' too
    if base is not None:
        for name in BASE_PROPERTIES:
            value = getattr(base, name)
            parts.append(np.asarray(value, dtype=float) if isinstance(value, list) else value)
    return digest(*parts)


def result(obj, digest, make):
    """The kept result of ``obj`` for ``digest``, else ``make()``'s (kept for the next
    recompute)."""
    name = (obj.Document.Name, obj.Name)
    got = _CACHE.pop(name, None)
    if got is None or got[0] != digest:
        got = (digest, make())
    _CACHE[name] = got
    while len(_CACHE) > KEPT:
        _CACHE.popitem(last=False)
    return got[1]


def forget(obj=None):
    """Drop the kept result of ``obj`` (every object's when None)."""
    if obj is None:
        _CACHE.clear()
    else:
        _CACHE.pop((obj.Document.Name, obj.Name), None)
