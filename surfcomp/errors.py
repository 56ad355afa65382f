# SPDX-License-Identifier: LGPL-2.1-or-later
"""The one exception hierarchy of surfcomp (pure Python, no FreeCAD)."""


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
    """

    exit_code = 1

    def __init__(self, message, file=None, line=None, column=None):
        super().__init__(message)
        self.message = message
        self.file = file
        self.line = line
        self.column = column

    def __str__(self):
        where = ""
        if self.file is not None:
            where = str(self.file)
            if self.line is not None:
                where += ":%d" % self.line
            if self.column is not None:
                where += ":%s" % (self.column,)
            where += ": "
        return where + self.message


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


def lookup(table, name, what):
    """``table[name]``, or an InputError naming ``what`` and the known names."""
    try:
        return table[name]
    except KeyError:
        raise InputError("unknown %s %r (expected one of %s)"
                         % (what, name, ", ".join(table))) from None
