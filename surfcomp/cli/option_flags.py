# SPDX-License-Identifier: LGPL-2.1-or-later
"""The command line's flag of each option a message names.

Errors and warnings below the command line name options as the API and job files do
(``max_offset``, listed in :attr:`surfcomp.errors.SurfcompError.options` and
:attr:`surfcomp.errors.Note.options`); the command line prints them as its flags
(``--max-offset``) through :func:`shown`.
"""

from ..core.option_tables import find

#: the job's files that are no option of the registry: ``output`` is ``-o``, the inputs are
#: the positional arguments
FILE_FLAGS = {"output": "-o", "nominal": "NOMINAL", "measurements": "MEASUREMENTS"}


def flag(name):
    """The flag of option ``name`` (``max_offset`` -> ``--max-offset``): the option
    registry's (:mod:`surfcomp.core.options`, :mod:`surfcomp.core.option_tables`) for its
    options; the name itself for an option the command line does not have (``lean``: job
    files only), or a name that is a flag already."""
    if name.startswith("-"):
        return name
    if name in FILE_FLAGS:
        return FILE_FLAGS[name]
    o = find(name)
    if o is not None:
        return o.flag or name
    return "--" + name.replace("_", "-")


def shown(message):
    """The text of the error or warning ``message`` with its options named as flags (a
    plain string as it is)."""
    if not hasattr(message, "shown"):
        return str(message)
    return message.shown(flag)
