# SPDX-License-Identifier: LGPL-2.1-or-later
"""The option registry of the compensation: every option's name, type, domain, default,
command-line flag, document property and help, written once (importable without numpy).

Who reads it:

- :class:`surfcomp.core.compensation.pipeline.Options` takes its defaults and
  :meth:`~surfcomp.core.compensation.pipeline.Options.validate` its domains from :data:`OPTIONS`;
- the command line (``compensate``, ``inspect``, ``simulate``) adds these options with
  :func:`cli_help`, the default and the choices from here;
- the compensation's property table (:mod:`surfcomp.app.properties`) takes the tooltips
  (:func:`tooltip`), defaults and enumerations from here;
- the filter task panel (:mod:`surfcomp.gui.panels`) takes its ranges, items and tooltips.

The other options (the job's inputs, the alignment, the measurement plan, the probing
program and the simulation's machining model) are records of the same type in
:mod:`surfcomp.core.option_tables`; :func:`surfcomp.core.option_tables.find` looks a name up
in every table. An option's ``label`` is its field's name in the GUI, which shows it where
a message names the option (the command line shows the flag).

A help text names other options as ``{name}`` (a field of :data:`OPTIONS`): the command
line shows the flag (``--stock``), the document the property (``Stock``). Words as in the
glossary of ``docs/architecture.md``.
"""

from dataclasses import dataclass

from . import limits
from .choices import EDGE_MODES, LAYOUTS, MASK_KINDS, METHODS


@dataclass(frozen=True)
class Option:
    """One option of the compensation.

    ``name``: the field of :class:`surfcomp.core.compensation.pipeline.Options` (the name messages
    of the core use); ``type``: ``int``, ``float``, ``str`` or ``bool``; ``default``: the
    value when it is not given (None: unset, see ``unset``); ``choices`` or ``low``/``high``:
    the domain (inclusive; ``what`` says what a value is, for messages); ``flag``: the
    command line's option (None: none); ``prop``: the compensation's document property;
    ``help``: one sentence without the default; ``unset``: what an unset value means (the
    command line's default, the property's 0); ``metavar``: the command line's value name;
    ``note``: added to the command line's default (``as in Werner 2022``); ``label``: the
    GUI field's name (messages in the GUI name the option so); ``dest``: the command line's
    attribute when it is not the flag's (``--format`` -> ``fmt``); ``stored``: the document
    property's value when unset (default 0 or empty); ``doc_help``: the tooltip when the
    property holds the value in another form than the command line (a file read in)."""

    name: str
    type: type
    default: object
    prop: str
    help: str
    flag: str = None
    choices: tuple = None
    low: float = None
    high: float = None
    what: str = ""
    unset: str = None
    metavar: str = None
    note: str = None
    label: str = None
    dest: str = None
    stored: object = None
    doc_help: str = None

    @property
    def optional(self):
        """True when None (unset) is a valid value."""
        return self.default is None

    @property
    def arg(self):
        """The command line's attribute of the option (``args.mask`` for ``--mask``)."""
        return self.dest or self.flag[2:].replace("-", "_")

    @property
    def domain(self):
        """The choices, or ``(low, high)``; None when any value of the type goes."""
        if self.choices is not None:
            return self.choices
        return None if self.low is None else (self.low, self.high)


_UM = dict(accept_um=limits.ACCEPT_TOL * 1e3, overshoot_um=limits.OVERSHOOT_TOL * 1e3)

OPTIONS = {o.name: o for o in (
    Option("method", str, "filtered", "Method", label="Method", flag="--method", choices=METHODS,
           help="correction method: raw (Werner eq. 2), filtered (eq. 3-5), mirror (needs "
                "{stock}), offset (uniform tool-radius baseline)"),
    Option("mask_size", int, 5, "MaskSize", label="Mask size",
           flag="--mask", low=1, high=limits.MAX_MASK_SIZE,
           what="an odd whole number", metavar="N", note="as in Werner 2022",
           help="odd number of grid nodes across the filter mask; custom {weights} set it"),
    Option("weights", str, None, "Weights", label="Weights", flag="--weights", metavar="W",
           unset="{mask_kind} and {mask_size}",
           help="custom mask weights, rows separated by ';', e.g. \"1 2 1; 2 4 2; 1 2 1\": "
                "they set the mask size and kind"),
    Option("mask_kind", str, "box", "MaskKind", label="Mask kind",
           flag="--mask-kind", choices=MASK_KINDS,
           help="mask shape without custom {weights}"),
    Option("sigma", float, None, "Sigma", label="Sigma", flag="--sigma", low=limits.MIN_SIGMA,
           high=limits.MAX_MASK_SIZE, what="grid steps", metavar="STEPS",
           unset="{mask_size} / 4", help="Gaussian sigma of the gaussian mask, in grid steps"),
    Option("edge", str, "renormalize", "Edge", label="Edge handling",
           flag="--edge", choices=EDGE_MODES,
           help="edge handling of the mask filter: renormalize (divide by the weights on "
                "measured points), reflect (the grid mirrored about its border node, "
                "scipy.ndimage's 'mirror'), nearest (the border node repeated)"),
    Option("stock", float, None, "Stock", label="Stock",
           flag="--stock", low=0.0, high=limits.MAX_STOCK,
           what="a length in mm", metavar="MM",
           help="semi-finishing allowance of the mirror method (mm; DH = stock / 2); a stock "
                "that does not fit the measured mean deviation is refused unless {accept_stock}"),
    Option("accept_stock", bool, False, "StockOk", label="Accept the stock", flag="--accept-stock",
           help="use the mirror method's {stock} although the measured mean deviation does not "
                "fit it (a part measured with stock s has its mean within max(s/2, 3 x the "
                "spread) of s; see docs/method.md)"),
    Option("max_offset", float, 1.0, "MaxOffset", label="Max offset", flag="--max-offset",
           low=limits.MIN_MAX_OFFSET, high=limits.MAX_MAX_OFFSET, what="a length in mm",
           metavar="MM", help="largest accepted distance of a measured point from the face (mm)"),
    Option("flip_normals", bool, False, "Flip", label="Flip normals", flag="--flip-normals",
           help="the file's normals point into the material: flip them and the sign of its "
                "deviations"),
    Option("refine", int, 4, "Refine", label="Refine",
           flag="--refine", low=1, high=limits.MAX_REFINE,
           what="a whole number of spans per grid step", metavar="K",
           help="knot spans of the corrected surface per measurement grid step at most: a grid "
                "along the face's parameter lines first gets one span per step, kept when it "
                "meets the {accept_um:g} um / {overshoot_um:g} um limits"),
    Option("lean", bool, True, "Lean", label="Lean",
           help="grids along the face's parameter lines: one knot span per grid step first, "
                "kept when it meets the limits (off in documents made before it: {refine} "
                "spans)"),
    Option("tip_radius", float, 0.0, "TipRadius", label="Tip radius", flag="--tip-radius", low=0.0,
           high=limits.MAX_TIP_RADIUS, what="a length in mm", metavar="MM",
           help="stylus ball radius when the measured points are tip centres (probe logs): "
                "each contact point is the centre moved by it against the outward normal (mm)"),
    Option("layout", str, "auto", "Layout", label="Layout", flag="--layout", choices=LAYOUTS,
           help="arrangement of the points: auto (a complete grid if they form one, else "
                "scattered, with a warning), grid (refuse anything else) or scattered"),
    Option("smoothing", float, None, "Smoothing", label="Smoothing",
           flag="--smoothing", low=limits.MIN_SMOOTHING,
           high=limits.MAX_SMOOTHING, what="a length in mm", metavar="MM",
           unset="chosen by generalized cross-validation",
           help="scattered layouts: smoothing length of the fit that takes the mask filter's "
                "place (the wavelength damped to half; mm)"),
)}

#: the options with a numeric domain: name -> (flag, property, low, high, may be None, what)
#: (the form :meth:`surfcomp.core.compensation.pipeline.Options.validate` reads)
DOMAINS = {o.name: (o.flag, o.prop, o.low, o.high, o.optional, o.what)
           for o in OPTIONS.values() if o.low is not None}


def _names(front_end, table):
    """Each option's name in a help text of ``front_end``: ``table``'s own first, then the
    compensation's, then the other tables' (:mod:`surfcomp.core.option_tables`)."""
    from .option_tables import TABLES

    both = {}
    for other in reversed(list(TABLES.values())):
        both.update(other)
    both.update(table)
    if front_end == "cli":
        return {n: o.flag or o.prop or n for n, o in both.items()}
    return {n: o.prop or o.flag or n for n, o in both.items()}


def _text(option, front_end, table):
    names = _names(front_end, table)
    text = (option.doc_help if front_end == "document" and option.doc_help
            else option.help).format(**names, **_UM)
    unset = option.unset.format(**names) if option.unset else None
    return text, unset


def cli_help(name, table=OPTIONS):
    """The command line's help of option ``name`` (of ``table``, default the
    compensation's): its help with the default (``(default 5, as in Werner 2022)``; an
    unset one says what it means)."""
    o = table[name]
    text, unset = _text(o, "cli", table)
    if o.type is bool and not o.default:
        return text
    default = unset if o.default is None else _show(o.default)
    if default is None:
        return text
    return "%s (default %s%s)" % (text, default, ", " + o.note if o.note else "")


def tooltip(name, table=OPTIONS):
    """The document property's tooltip of option ``name`` (of ``table``; what an unset
    value, 0 or empty, means in parentheses)."""
    o = table[name]
    text, unset = _text(o, "document", table)
    if unset and o.stored is None:
        text = "%s (%s: %s)" % (text, "empty" if o.type is str else "0", unset)
    return text[0].upper() + text[1:]


def _show(value):
    return "%g" % value if isinstance(value, float) else str(value)
