# SPDX-License-Identifier: LGPL-2.1-or-later
"""The choices of the options every front end offers, importable without numpy or scipy.

The command line builds its parser from these (``python3 -m surfcomp --help`` and an
argument error import no numerics); the modules that implement the choices re-export them
(``surfcomp.core.compensation.methods.METHODS``, ``surfcomp.core.compensation.filters.EDGE_MODES``,
``surfcomp.io.readers.FORMATS``).
"""

#: correction methods (:mod:`surfcomp.core.compensation.methods`)
METHODS = ("raw", "filtered", "mirror", "offset")
#: edge handling of the mask filter: 'renormalize' (default, see
#: :mod:`surfcomp.core.compensation.filters`), 'reflect' (the grid mirrored about its border node,
# which
#: is not repeated: numpy.pad's 'reflect', the mode scipy.ndimage calls 'mirror'),
#: 'nearest' (the border node repeated)
EDGE_MODES = ("renormalize", "reflect", "nearest")
#: measurement file formats (:func:`surfcomp.io.readers.read_any`; auto: detected)
MEASUREMENT_FORMATS = ("auto", "table", "xyz", "xyzijk", "probe", "qif")
#: shapes of the filter mask without custom weights
# (:func:`surfcomp.core.compensation.filters.make_mask`)
MASK_KINDS = ("box", "gaussian")
#: how the measured points are arranged: found automatically (a complete grid, else
#: scattered), or forced (:func:`surfcomp.core.compensation.pipeline.prepare`)
LAYOUTS = ("auto", "grid", "scattered")
