# SPDX-License-Identifier: LGPL-2.1-or-later
"""The core's subsystems import each other only as docs/architecture.md says: the surface
below everything, the machine axes on their own, the simulation over the rest."""

import ast
import os

from tests.conftest import ROOT

CORE = os.path.join(ROOT, "surfcomp", "core")
#: subsystem -> the subsystems it may import (the shared modules at core/'s top are free)
ALLOWED = {
    "surface": set(),
    "axis": set(),
    "measurement": {"surface"},
    "compensation": {"surface", "axis"},
    "simulation": {"surface", "compensation", "measurement"},
}


def subsystem_imports(group):
    """``{(file, imported subsystem)}`` of the modules in ``core/<group>/``."""
    found = set()
    folder = os.path.join(CORE, group)
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".py"):
            continue
        with open(os.path.join(folder, name), encoding="utf-8") as fh:
            tree = ast.parse(fh.read())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                if node.level == 2 and node.module:
                    target = node.module.split(".")[0]
                elif node.level == 0 and (node.module or "").startswith("surfcomp.core."):
                    target = node.module.split(".")[2]
                else:
                    continue
                if target in ALLOWED:
                    found.add((name, target))
    return found


def test_every_core_module_is_in_a_subsystem_or_shared():
    subsystems = {d for d in os.listdir(CORE) if os.path.isdir(os.path.join(CORE, d))
                  and d != "__pycache__"}
    assert subsystems == set(ALLOWED)
    shared = sorted(f for f in os.listdir(CORE) if f.endswith(".py"))
    assert shared == ["__init__.py", "budget.py", "choices.py", "chunks.py", "colormap.py",
                      "command_options.py", "limits.py", "measurement_set.py", "memory.py",
                      "option_tables.py", "options.py", "progress.py"], shared


def test_subsystems_import_only_what_the_architecture_allows():
    wrong = sorted((group, name, target) for group in ALLOWED
                   for name, target in subsystem_imports(group)
                   if target != group and target not in ALLOWED[group])
    assert not wrong, wrong


def test_the_check_sees_an_import_across_subsystems():
    # the scan is not blind: the compensation's program offset does use the axis geometry
    assert ("program_offset.py", "axis") in subsystem_imports("compensation")
    assert ("simulate.py", "compensation") in subsystem_imports("simulation")
