# SPDX-License-Identifier: LGPL-2.1-or-later
"""What the command line's help and the docs say about the options is what the parsers and
the option registry take: the values the README and docs give an option lie in the
registry's domain."""

import glob
import os
import re

from surfcomp.core.options import OPTIONS
from tests.conftest import ROOT


def _docs():
    """README and docs/*.md but the benchmarks (whose flags are the bench scripts')."""
    paths = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs",
                                                                              "*.md")))
    return [p for p in paths if not p.endswith("benchmarks.md")]


def test_the_docs_give_the_compensation_options_values_in_their_domain():
    """README said '--smoothing 0 switches it off': the registry's domain starts at 0.001 mm,
    and the run is refused."""
    numeric = {o.flag: o for o in OPTIONS.values() if o.flag and o.low is not None}
    outside = []
    for path in _docs():
        with open(path, encoding="utf-8") as fh:
            for number, line in enumerate(fh, 1):
                if "bench/" in line:
                    continue
                for flag, value in re.findall(r"(--[a-z-]+)[ =](-?\d[\d.]*(?:e-?\d+)?)\b", line):
                    o = numeric.get(flag)
                    if o is not None and not o.low <= float(value) <= o.high:
                        outside.append((os.path.basename(path), number, flag, value))
    assert not outside
