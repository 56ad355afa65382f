# SPDX-License-Identifier: LGPL-2.1-or-later
"""surfcomp: machining-error compensation of free-form B-spline surfaces.

Layers (imports point downwards only): ``gui`` -> ``app`` -> ``io``/``core``.
``core`` and ``io`` use numpy/scipy only and never import FreeCAD.

The Python API (:mod:`surfcomp.api`) is re-exported here: ``surfcomp.load_nominal``,
``surfcomp.compensate`` and the rest, imported on first use (``import surfcomp`` alone
needs neither numpy nor FreeCAD).
"""

__version__ = "0.1.0"

#: the names of :mod:`surfcomp.api` re-exported here
API = ("Compensation", "FreeCADRequired", "InputError", "Job", "MeasurementSet", "Options",
       "Result", "SurfcompError", "compensate", "load_nominal", "options", "read_measurements",
       "require_freecad", "run_job", "write_document", "write_face", "write_solid")


def __getattr__(name):
    if name in API:
        from . import api

        return getattr(api, name)
    raise AttributeError("module 'surfcomp' has no attribute %r" % name)


def __dir__():
    return sorted(list(globals()) + list(API))
