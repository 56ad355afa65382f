# SPDX-License-Identifier: LGPL-2.1-or-later
"""The command line's flag of each option a message names.

Errors below the command line name options as the API and job files do (``max_offset``,
listed in :attr:`surfcomp.errors.SurfcompError.options`); the command line prints them as
its flags (``--max-offset``) through :func:`shown`.
"""

from ..core.options import OPTIONS

#: options outside the registry whose flag is not ``--`` and the name with dashes
_FLAGS = {"fmt": "--format"}


def flag(name):
    """The flag of option ``name`` (``max_offset`` -> ``--max-offset``): the registry's
    (:mod:`surfcomp.core.options`) for its options; the name itself for an option the
    command line does not have (``lean``: job files only), or a name that is a flag
    already."""
    if name.startswith("-"):
        return name
    if name in OPTIONS:
        return OPTIONS[name].flag or name
    if name in _FLAGS:
        return _FLAGS[name]
    return "--" + name.replace("_", "-")


def shown(exc):
    """The text of the error ``exc`` with its options named as flags."""
    return exc.shown(flag)
