# SPDX-License-Identifier: LGPL-2.1-or-later
"""surfcomp: machining-error compensation of free-form B-spline surfaces.

Layers (imports point downwards only): ``gui`` -> ``app`` -> ``io``/``core``.
``core`` and ``io`` use numpy/scipy only and never import FreeCAD.
"""

__version__ = "0.1.0"
