# SPDX-License-Identifier: LGPL-2.1-or-later
"""What a compensation's filter preview reuses between its recomputes.

A preview (``Preview`` true: the filter task panel's live maps) changes only the filter:
mask size, weights, kind, sigma, edge handling. The measured points' location on the face
(the projection), their grid and the grid's parameter scale depend on none of those, so
they are kept here, keyed by a fingerprint of everything they depend on (the nominal
surface and its placement, the measurement data, the options outside the filter), and a
preview only filters and recolours. Nothing here is saved with the document: the cache is
transient, one entry per compensation object, and any change to an input misses it.
"""

import hashlib
from dataclasses import fields
from dataclasses import replace as _dc_replace

import numpy as np

#: core options that only the filter uses: a change of these keeps the prepared grid
FILTER_FIELDS = ("mask_size", "weights", "mask_kind", "sigma", "edge")

_CACHE = {}


def digest(*parts):
    h = hashlib.sha1()
    for part in parts:
        if part is None:
            h.update(b"-")
        elif isinstance(part, np.ndarray):
            a = np.ascontiguousarray(part)
            h.update(str((a.dtype.str, a.shape)).encode())
            h.update(a.tobytes())
        else:
            h.update(repr(part).encode())
        h.update(b"|")
    return h.hexdigest()


def fingerprint(nominal, placement, ms, options):
    """What the prepared grid of a compensation depends on, as a hex digest: the nominal
    surface (poles, knots, weights, degrees, work area, orientation), its boundary
    (vertices and edge lengths: the points outside the trim), its placement, the
    measurement arrays and every option outside :data:`FILTER_FIELDS`."""
    s = nominal.surface
    face = nominal.bspline_face
    boundary = ([tuple(v.Point) for v in face.Vertexes], [e.Length for e in face.Edges])
    surf = [np.asarray(getattr(s, name), dtype=float) if getattr(s, name, None) is not None
            else None for name in ("poles", "knots_u", "knots_v", "weights")]
    opts = [(f.name, getattr(options, f.name)) for f in fields(options)
            if f.name not in FILTER_FIELDS]
    arrays = [None if getattr(ms, name) is None else np.asarray(getattr(ms, name))
              for name in ("nominal", "measured", "normal", "deviation", "row", "col", "lines")]
    return digest(*surf, s.degree_u, s.degree_v, s.u_range, s.v_range, nominal.outward,
                   nominal.face_name, boundary, repr(placement), *arrays, ms.ids, ms.source,
                   ms.warnings, opts)


def prepared(obj, key, make):
    """``(prepared, trim warning, parameter scale)`` of compensation ``obj`` for the
    fingerprint ``key``: the kept one when the key matches, else ``make()``'s (kept for
    the next preview). The prepared set comes back with its own warnings list, so a
    caller may add to it."""
    name = (obj.Document.Name, obj.Name)
    got = _CACHE.get(name)
    if got is None or got[0] != key:
        got = (key,) + tuple(make())
        _CACHE[name] = got
    prep, warning, scale = got[1:]
    return _dc_replace(prep, warnings=list(prep.warnings)), warning, scale


def forget(obj=None):
    """Drop the kept grid of ``obj`` (every object's when None)."""
    if obj is None:
        _CACHE.clear()
    else:
        _CACHE.pop((obj.Document.Name, obj.Name), None)
