# SPDX-License-Identifier: LGPL-2.1-or-later
"""docs/architecture.md's source tree is the package's: every module of ``surfcomp/`` has
its line, and every line names a file or folder that exists."""

import os
import re

from tests.conftest import ROOT

ARCHITECTURE = os.path.join(ROOT, "docs", "architecture.md")


def tree_block(text):
    """The fenced block under '## Source tree'."""
    section = text.split("\n## Source tree\n", 1)[1].split("\n## ", 1)[0]
    return re.search(r"^```\n(.*?)^```", section, re.S | re.M).group(1)


def tree_paths(block):
    """Paths the tree names, from its two-space indentation: ``surfcomp/core/axis/arcs.py``,
    ``surfcomp/core/`` (folders end in '/')."""
    stack, out = [], []
    for number, line in enumerate(block.splitlines(), 1):
        if not line.strip():
            continue
        indent = len(line) - len(line.lstrip(" "))
        assert indent % 2 == 0, "line %d: indentation %d is not a multiple of 2" % (number,
                                                                                    indent)
        depth, name = indent // 2, line.split()[0]
        assert depth <= len(stack), "line %d: %r is indented below no folder" % (number, name)
        del stack[depth:]
        path = "".join(stack) + name
        out.append(path)
        if name.endswith("/"):
            stack.append(name)
    return out


def package_modules():
    found = set()
    for folder, dirs, files in os.walk(os.path.join(ROOT, "surfcomp")):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        rel = os.path.relpath(folder, ROOT).replace(os.sep, "/")
        found |= {"%s/%s" % (rel, f) for f in files if f.endswith(".py")}
    return found


def problems(paths):
    """``(modules without a line, lines naming nothing)``."""
    missing = sorted(package_modules() - set(paths))
    gone = [p for p in paths if not os.path.exists(os.path.join(ROOT, p))]
    return missing, gone


def test_every_module_has_its_line_and_every_line_exists():
    with open(ARCHITECTURE, encoding="utf-8") as fh:
        paths = tree_paths(tree_block(fh.read()))
    assert len(paths) == len(set(paths)), sorted(p for p in paths if paths.count(p) > 1)
    missing, gone = problems(paths)
    assert not missing, ("modules missing from docs/architecture.md's source tree (add a line "
                         "each): %s" % ", ".join(missing))
    assert not gone, "docs/architecture.md's source tree names what does not exist: %s" % gone


def test_the_check_sees_a_missing_and_a_stale_line():
    """The check itself: nesting, a module left out, a line for no file."""
    block = "surfcomp/   pkg\n  errors.py  x\n  core/  y\n    arcs9.py  z\nInit.py  w\n"
    paths = tree_paths(block)
    assert paths == ["surfcomp/", "surfcomp/errors.py", "surfcomp/core/",
                     "surfcomp/core/arcs9.py", "Init.py"]
    missing, gone = problems(paths)
    assert "surfcomp/core/surface/grid.py" in missing and "surfcomp/errors.py" not in missing
    assert gone == ["surfcomp/core/arcs9.py"]
