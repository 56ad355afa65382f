# SPDX-License-Identifier: LGPL-2.1-or-later
"""Options as the GUI names them: the label of the option registry
(:mod:`surfcomp.core.options`, :mod:`surfcomp.core.option_tables`), translated.

A message below the GUI names an option as the API does (``mask_size``) and lists it in its
``options`` (:class:`surfcomp.errors.SurfcompError`, :class:`surfcomp.errors.Note`); the
task panels show it with :func:`shown`, which names each such option by the label of its
field (``Mask size``), as the command line names it by its flag
(:mod:`surfcomp.cli.option_flags`). The panels take their field labels and tooltips from
here too, so a message and the field it is about use the same words.
"""

import FreeCAD

from ..core.option_tables import TABLES, find
from ..core.options import tooltip

translate = FreeCAD.Qt.translate


def label(name, tables=None):
    """The GUI label of option ``name`` (looked up in ``tables``, names of
    :data:`surfcomp.core.option_tables.TABLES`, then in every table); the name itself for
    an option without one."""
    o = find(name, tables) or find(name)
    if o is None or not o.label:
        return name
    return translate("SurfComp", o.label)


def tip(name, table):
    """The tooltip of option ``name`` of the registry's table ``table`` (a name of
    :data:`~surfcomp.core.option_tables.TABLES`), translated as its property's is."""
    return translate("App::Property", tooltip(name, TABLES[table]))


def shown(message, tables=None):
    """The text of an error or a warning (:class:`surfcomp.errors.Note`) with the options
    it names shown as their labels; a plain string as it is."""
    if not hasattr(message, "shown"):
        return str(message)
    return message.shown(lambda name: label(name, tables))
