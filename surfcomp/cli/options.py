# SPDX-License-Identifier: LGPL-2.1-or-later
"""The compensation's options on the command line, from the option registry
(:mod:`surfcomp.core.options`): flag, type, default, choices, metavar and help."""

from ..core.options import OPTIONS, cli_help


def add_arguments(parser, names, **overrides):
    """Add the options ``names`` to an argparse ``parser`` (or argument group).
    ``overrides``: name -> argparse keywords that replace the registry's for this parser
    (``simulate``'s ``--mask`` takes a list)."""
    for name in names:
        o = OPTIONS[name]
        kw = dict(help=cli_help(name))
        if o.type is bool:
            kw["action"] = "store_true"
        else:
            kw["default"] = o.default
            if o.choices is not None:
                kw["choices"] = o.choices
            elif o.type is not str:
                kw["type"] = o.type
            if o.metavar:
                kw["metavar"] = o.metavar
        kw.update(overrides.get(name, {}))
        parser.add_argument(o.flag, **kw)
