# SPDX-License-Identifier: LGPL-2.1-or-later
"""Errors below the command line name options as the API and job files do; the command
line shows them as its flags."""

import numpy as np
import pytest

from surfcomp.cli.option_flags import flag
from surfcomp.core.compensation.methods import compute_correction
from surfcomp.core.compensation.pipeline import Options
from surfcomp.errors import InputError

BAD = [("mask_size", 4, "--mask"), ("sigma", -1.0, "--sigma"), ("stock", 11.0, "--stock"),
       ("max_offset", float("nan"), "--max-offset"), ("refine", 0, "--refine"),
       ("tip_radius", 51.0, "--tip-radius"), ("smoothing", 0.0, "--smoothing"),
       ("method", "magic", "--method"), ("mask_kind", "disc", "--mask-kind"),
       ("edge", "wrap", "--edge"), ("layout", "ring", "--layout"),
       ("accept_stock", "yes", "--accept-stock"), ("lean", "no", "lean")]


@pytest.mark.parametrize("name, value, shown", BAD)
def test_a_bad_option_is_named_as_itself_and_shown_as_its_flag(name, value, shown):
    with pytest.raises(InputError) as err:
        Options(**{name: value}).validate()
    exc = err.value
    assert exc.message.startswith("%s %r: expected " % (name, value))
    assert exc.options == (name,)
    assert exc.shown(flag) == "%s %r: expected " % (shown, value) + \
        exc.message[len("%s %r: expected " % (name, value)):]


def test_mirror_without_stock():
    with pytest.raises(InputError) as err:
        Options(method="mirror").validate()
    assert err.value.message.startswith("method 'mirror' needs stock (the semi-finishing")
    assert err.value.shown(flag).startswith("--method 'mirror' needs --stock (the semi-")
    with pytest.raises(InputError) as err:
        compute_correction(np.zeros((3, 3)), "mirror")
    assert err.value.shown(flag).startswith("the mirror method needs --stock, the semi-")


def test_only_the_message_is_renamed_not_the_file():
    exc = InputError("stock must be a finite allowance", file="stock/stock.csv", line=2,
                     options=("stock",))
    assert str(exc) == "stock/stock.csv:2: stock must be a finite allowance"
    assert exc.shown(flag) == "stock/stock.csv:2: --stock must be a finite allowance"
    # a word that only contains an option's name stays
    assert InputError("max_offsets and stocks", options=("stock",)).shown(flag) == \
        "max_offsets and stocks"


def test_document_messages_name_the_property():
    from surfcomp.core.compensation.pipeline import option_name

    assert option_name(Options(), "max_offset") == "max_offset"
    assert option_name(Options(context="document"), "max_offset") == \
        "the compensation's MaxOffset"


def _messages_below_the_command_line():
    """``(where, AST of a message)`` of core and io: every raised exception, and every
    warning: an argument of ``*warn*.append/extend/insert(...)``, ``*.warn(...)`` and
    ``note(...)``, and what a function named ``*warning*`` returns."""
    import ast
    import os

    root = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))), "surfcomp")
    for layer in ("core", "io"):
        for folder, _dirs, files in os.walk(os.path.join(root, layer)):
            for name in sorted(files):
                if not name.endswith(".py"):
                    continue
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8") as fh:
                    tree = ast.parse(fh.read())
                where = os.path.relpath(path, root)
                for node in ast.walk(tree):
                    if isinstance(node, ast.Raise) and node.exc is not None:
                        yield "raise", "%s:%d" % (where, node.lineno), node.exc
                    elif isinstance(node, ast.Call) and _is_warning(node.func):
                        for arg in node.args:
                            yield "warning", "%s:%d" % (where, node.lineno), arg
                    elif isinstance(node, ast.FunctionDef) and "warning" in node.name:
                        for sub in ast.walk(node):
                            if isinstance(sub, ast.Return) and sub.value is not None:
                                yield "warning", "%s:%d" % (where, sub.lineno), sub.value


def _is_warning(func):
    import ast

    if isinstance(func, ast.Name):
        return func.id in ("Note", "note")
    if not isinstance(func, ast.Attribute):
        return False
    if func.attr in ("warn", "Note", "note"):
        return True
    return func.attr in ("append", "extend", "insert") and "warn" in ast.unparse(func.value)


def test_no_error_or_warning_below_the_command_line_names_a_flag():
    """Every ``raise`` and every warning in core and io names options, not flags
    (``--max-offset``): a script and a job file get the names they pass; the command line
    shows the flags, the GUI the labels."""
    import ast
    import re

    found, kinds = [], set()
    for kind, where, node in _messages_below_the_command_line():
        kinds.add(kind)
        for sub in ast.walk(node):
            if isinstance(sub, ast.Constant) and isinstance(sub.value, str) and \
                    re.search(r"(?<![\w-])--[a-z]", sub.value):
                found.append("%s: %s %s" % (where, kind, sub.value))
    assert kinds == {"raise", "warning"}
    assert found == []


def test_the_scan_finds_the_warnings():
    """The warning scan above sees the warnings it is about (it would pass on nothing)."""
    import ast

    texts = [ast.unparse(node) for kind, _where, node in _messages_below_the_command_line()
             if kind == "warning"]
    joined = " ".join(texts)
    for words in ("the filtered method or a larger", "the file states its units",
                  "choose another with", "name datum faces with", "stylus tip centres",
                  "used as a scattered layout"):
        assert words in joined, words
    assert len(texts) > 20
