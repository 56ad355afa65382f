# SPDX-License-Identifier: LGPL-2.1-or-later
"""Every Python module of the project (product, tests, benchmarks, tools) has at most 600
lines: past that a module usually does two jobs (CONTRIBUTING.md, "Code rules")."""

import os

from tests.conftest import ROOT

LIMIT = 600
FOLDERS = ("surfcomp", "tests", "bench", "tools")


def _modules():
    for folder in FOLDERS:
        for base, dirs, files in os.walk(os.path.join(ROOT, folder)):
            dirs[:] = [d for d in dirs if d not in ("__pycache__", "data")]
            for name in files:
                if name.endswith(".py"):
                    yield os.path.join(base, name)


def test_no_module_is_over_the_limit():
    found = list(_modules())
    assert len(found) > 300  # the walk really sees the project
    sizes = {}
    for path in found:
        with open(path, encoding="utf-8") as f:
            sizes[os.path.relpath(path, ROOT)] = sum(1 for _ in f)
    over = {p: n for p, n in sizes.items() if n > LIMIT}
    assert not over, "modules over %d lines: %s" % (LIMIT, over)
