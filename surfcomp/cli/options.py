# SPDX-License-Identifier: LGPL-2.1-or-later
"""The options on the command line, from the option registry (:mod:`surfcomp.core.options`,
:mod:`surfcomp.core.option_tables`): flag, type, default, choices, metavar and help."""

from ..core.options import OPTIONS, cli_help
from ..errors import InputError


def kwargs(name, table=OPTIONS):
    """argparse's keyword arguments of option ``name`` of ``table``."""
    o = table[name]
    kw = dict(help=cli_help(name, table))
    if o.dest:
        kw["dest"] = o.dest
    if o.type is bool:
        kw["action"] = "store_true"
        return kw
    kw["default"] = o.default
    if o.choices is not None:
        kw["choices"] = o.choices
    elif o.type in (int, float):
        kw["type"] = o.type
    if o.metavar:
        kw["metavar"] = o.metavar
    return kw


def check_range(option, value):
    """Refuse ``value`` of ``option`` (a registry :class:`surfcomp.core.options.Option`)
    outside its ``low`` .. ``high``; None (unset) passes."""
    if value is not None and not option.low <= value <= option.high:
        raise InputError("%s %s: expected %g to %g" % (option.flag, value, option.low,
                                                       option.high))


def add_arguments(parser, names, table=OPTIONS, **overrides):
    """Add the options ``names`` of ``table`` (default the compensation's) to an argparse
    ``parser`` (or argument group). ``overrides``: name -> argparse keywords that replace
    the registry's for this parser (``simulate``'s ``--mask`` takes a list)."""
    for name in names:
        kw = kwargs(name, table)
        kw.update(overrides.get(name, {}))
        parser.add_argument(table[name].flag, **kw)
