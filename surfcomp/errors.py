# SPDX-License-Identifier: LGPL-2.1-or-later
"""The one exception hierarchy of surfcomp (pure Python, no FreeCAD).

Messages name options as the API and job files do (``max_offset``, ``stock``); an error
lists the options it names in ``options``, and the command line shows them as its flags
(:meth:`SurfcompError.shown`, :mod:`surfcomp.cli.option_flags`).
"""

import re


def renamed(text, options, name_of):
    """``text`` with every option of ``options`` named as ``name_of(option)``; a word that
    only contains an option's name, and a quoted value such as ``'rps'``, stay."""
    for name in options:
        text = re.sub(r"(?<![\w'-])%s(?![\w'-])" % re.escape(name),
                      lambda _m, name=name: name_of(name), text)
    return text


class Note(str):
    """A warning's text that names options as the API does (``refine``): the command line
    shows them as flags (``--refine``, :func:`surfcomp.cli.option_flags.shown`), the GUI as
    field labels, a document as properties. Everything else takes it as the plain string it
    is (reports, comparisons, JSON).

    ``refs``: ``(start, end, name)`` of each place the text names option ``name`` (only
    those places are renamed: the same word in the prose stays); made by :func:`note`.
    """

    def __new__(cls, text, refs=()):
        made = super().__new__(cls, text)
        made.refs = tuple(refs)
        return made

    @property
    def options(self):
        """The options the text names, in order."""
        return tuple(dict.fromkeys(name for _s, _e, name in self.refs))

    def __reduce__(self):
        return (Note, (str(self), self.refs))

    def __add__(self, other):      # a note and more text stays a note
        more = [(s + len(self), e + len(self), n) for s, e, n in getattr(other, "refs", ())]
        return Note(str(self) + other, self.refs + tuple(more))

    def __radd__(self, other):     # "FILE:LINE: " + note
        shift = len(other)
        return Note(other + str(self), tuple(getattr(other, "refs", ())) + tuple(
            (s + shift, e + shift, n) for s, e, n in self.refs))

    def shown(self, name_of=None):
        """The text with every place that names an option as itself (``refine``) naming it
        as ``name_of(option)``; a place already in a reader's words (``the compensation's
        Refine``) stays."""
        text = str(self)
        for start, end, name in sorted(self.refs, reverse=True) if name_of else ():
            if text[start:end] == name:
                text = text[:start] + name_of(name) + text[end:]
        return text


def note(*parts):
    """A :class:`Note` of ``parts``: strings, and ``(name,)`` or ``(name, text)`` where the
    text names option ``name`` (as itself, or as ``text``: ``option_name(options,
    "refine")``). Example: ``note("a larger ", ("refine",), " helps")``."""
    text, refs = "", []
    for part in parts:
        if isinstance(part, tuple):
            name, shown = part[0], part[-1]
            refs.append((len(text), len(text) + len(shown), name))
            part = shown
        text += part
    return Note(text, refs)


class SurfcompError(Exception):
    """Base class of every error surfcomp raises on purpose.

    Parameters
    ----------
    message : str
        What is wrong and, where it helps, what was expected.
    file : str, optional
        The input file the problem is in.
    line : int, optional
        1-based line number in ``file``.
    column : int or str, optional
        1-based column number or column name.
    options : tuple of str, optional
        The options (:class:`surfcomp.core.compensation.pipeline.Options` fields, job keys) the
        message names, each as its name (``max_offset``).
    """

    exit_code = 1

    def __init__(self, message, file=None, line=None, column=None, options=()):
        super().__init__(message)
        self.message = message
        self.file = file
        self.line = line
        self.column = column
        self.options = tuple(options) or tuple(getattr(message, "options", ()))

    def __str__(self):
        return self._where() + self.message

    def shown(self, name_of=None):
        """The text of ``str(self)`` with every option in ``options`` named as
        ``name_of(option)`` (the command line's ``--max-offset``) in the message; a quoted
        value such as ``'rps'`` is not an option's name. A message that is a :class:`Note`
        is renamed at the places it marks only (``output`` in "the same standard output"
        stays)."""
        if name_of and getattr(self.message, "refs", None):
            return self._where() + self.message.shown(name_of)
        return self._where() + renamed(self.message, self.options if name_of else (), name_of)

    def _where(self):
        where = ""
        if self.file is not None:
            where = str(self.file)
            if self.line is not None:
                where += ":%d" % self.line
            if self.column is not None:
                where += ":%s" % (self.column,)
            where += ": "
        return where


class InputError(SurfcompError):
    """Bad user input (files, options): the CLI exits with code 2."""

    exit_code = 2


class MeasurementFileError(InputError):
    """A measurement file cannot be read or is inconsistent."""


class GeometryError(InputError):
    """A nominal face or shape cannot be used (missing, ambiguous, degenerate)."""


class GridError(InputError):
    """Measured points do not form the structured grid a method needs."""


class GCodeError(InputError):
    """A G-code program contains something that cannot be handled safely."""


class ComputationError(SurfcompError):
    """A numerical step failed (no convergence, singular system): an internal error."""

    exit_code = 1


class Cancelled(SurfcompError):
    """The user interrupted a long step; nothing was written."""

    exit_code = 130


class FreeCADRequired(SurfcompError, ImportError):
    """A call needs FreeCAD and this Python cannot import it (the message says what to
    install or run instead)."""

    exit_code = 2


def lookup(table, name, what):
    """``table[name]``, or an InputError naming ``what`` and the known names."""
    try:
        return table[name]
    except KeyError:
        raise InputError("unknown %s %r (expected one of %s)"
                         % (what, name, ", ".join(table))) from None
