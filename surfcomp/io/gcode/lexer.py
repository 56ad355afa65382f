# SPDX-License-Identifier: LGPL-2.1-or-later
"""Lexer of G-code text: lines, words and comments (no FreeCAD).

The file is handled as Latin-1 text, which maps every byte to one character and back, so
that lines the compensation leaves alone are written back byte for byte.
"""

import math
import re

from ...errors import GCodeError
from ..files import clip

#: the axis words the compensation handles, in output order
AXIS_LETTERS = "XYZ"

_WORD = re.compile(r"([A-Za-z])[ \t]*([+-]?(?:\d+(?:\.\d*)?|\.\d+))")
_LINE = re.compile(r"[^\n]*\n|[^\n]+$")


class Word:
    """One word of a line: ``letter`` (upper case), ``value``, its ``text`` and span."""

    __slots__ = ("letter", "value", "text", "start", "end")

    def __init__(self, letter, value, text=None, start=-1, end=-1):
        self.letter = letter
        self.value = value
        self.text = text
        self.start = start
        self.end = end

    @property
    def decimals(self):
        t = self.text
        if t is None:
            return 0
        k = t.find(".")
        return 0 if k < 0 else len(t) - k - 1

    def __repr__(self):
        return "Word(%s%s)" % (self.letter, self.text if self.text is not None else self.value)


def tokenize(content, source=None, line=None):
    """Split the code of one line into words.

    Parameters
    ----------
    content : str
        The line without its line ending.

    Returns
    -------
    (list of Word, bool)
        The words in order and whether the line starts with block delete ``/``.

    Raises
    ------
    GCodeError
        Parameters, expressions, O words, malformed words, unclosed comments.
    """
    words = []
    block = False
    i, n = 0, len(content)
    while i < n:
        c = content[i]
        if c in " \t\r":
            i += 1
        elif c == "(":
            i = _comment_end(content, i, source, line)
        elif c == ";" or (c == "%" and not words and content.strip() == "%"):
            break
        elif c == "/" and not words and not block:
            block = True
            i += 1
        else:
            m = _WORD.match(content, i)
            if not m:
                _refuse(content, i, source, line)
            words.append(_word(content, m, source, line))
            i = m.end()
    return words, block


def _comment_end(content, i, source, line):
    """Index after the comment ``( ... )`` that starts at ``i``."""
    j = content.find(")", i + 1)
    if j < 0:
        raise GCodeError("comment opened with '(' is not closed", file=source, line=line,
                         column=i + 1)
    k = content.find("(", i + 1, j)
    if k >= 0:
        raise GCodeError("nested '(' inside a comment", file=source, line=line, column=k + 1)
    return j + 1


def _o_word(text, source, line, i):
    return GCodeError("O word %r: subroutines and flow control (O-words) cannot be "
                      "compensated; expand the program first" % clip(text), file=source, line=line,
                      column=i + 1)


def _word(content, m, source, line):
    """The :class:`Word` of the match ``m`` of :data:`_WORD`."""
    i, end = m.start(), m.end()
    letter = m.group(1).upper()
    if letter == "O":
        raise _o_word(content[i:end], source, line, i)
    if end < len(content) and (content[end] == "." or content[end].isdigit()):
        raise GCodeError("malformed number in %r" % clip(content[i:end + 1]), file=source,
                         line=line, column=i + 1)
    text = m.group(2)
    value = float(text)
    if not math.isfinite(value):
        raise GCodeError("number %s%s... with %d digits is out of range (expected a "
                         "number a machine can move by)" % (m.group(1), text[:12], len(text)),
                         file=source, line=line, column=i + 1)
    return Word(letter, value, text, i, end)


def _refuse(content, i, source, line):
    """Raise the error for what starts at ``i`` and is neither a word nor a comment."""
    c = content[i]
    if c == "#" or c == "[":
        raise GCodeError("LinuxCNC parameter or expression %r: parameters and expressions "
                         "cannot be compensated; expand them to plain numbers first"
                         % content[i:i + 16].strip(), file=source, line=line, column=i + 1)
    if c.isalpha():
        rest = content[i + 1:].lstrip(" \t")
        if rest[:1] in ("#", "["):
            raise GCodeError("LinuxCNC parameter or expression in %r: parameters and "
                             "expressions cannot be compensated; expand them to plain "
                             "numbers first" % content[i:i + 16].strip(), file=source,
                             line=line, column=i + 1)
        if c.upper() == "O":
            raise _o_word(content[i:i + 16].strip(), source, line, i)
        raise GCodeError("word %r without a number" % c, file=source, line=line, column=i + 1)
    raise GCodeError("unexpected character %r (expected G-code words, comments in "
                     "parentheses or after ';')" % c, file=source, line=line, column=i + 1)


def split_lines(text):
    """Lines of ``text`` as ``(content, ending)`` pairs; ``''.join`` of them gives ``text``.

    The ending is ``'\\n'``, ``'\\r\\n'`` or ``''`` (last line without one).
    """
    out = []
    for m in _LINE.finditer(text):
        s = m.group(0)
        if s.endswith("\r\n"):
            out.append((s[:-2], "\r\n"))
        elif s.endswith("\n"):
            out.append((s[:-1], "\n"))
        else:
            out.append((s, ""))
    return out


#: the UTF-8 byte-order mark as Latin-1 text (some editors start every file with it)
BOM = "\xef\xbb\xbf"


def decode(data):
    """``data`` as text: bytes are decoded as Latin-1 (one character per byte), without a
    UTF-8 byte-order mark at the start (:func:`surfcomp.io.gcode.stream.compensate_gcode`
    writes it back)."""
    text = data.decode("latin-1") if isinstance(data, (bytes, bytearray)) else data
    return text[len(BOM):] if text.startswith(BOM) else text
