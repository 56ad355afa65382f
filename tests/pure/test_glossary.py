# SPDX-License-Identifier: LGPL-2.1-or-later
"""The glossary of docs/architecture.md fixes the words; the code's texts use them: the
filtered part is the determined component (of the systematic error), never "repeatable"."""

import os
import re

from tests.conftest import ROOT


def _glossary():
    text = open(os.path.join(ROOT, "docs", "architecture.md"), encoding="utf-8").read()
    section = text.split("\n## Glossary\n", 1)[1].split("\n## ", 1)[0]
    return {m.group(1): m.group(2) for m in re.finditer(r"^\| ([^|]+?) \| ([^|]+?) \|",
                                                         section, re.M)}


def _sources():
    for folder, _dirs, files in os.walk(os.path.join(ROOT, "surfcomp")):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                yield path, open(path, encoding="utf-8").read()


def test_the_glossary_defines_the_words():
    words = _glossary()
    for word in ("nominal", "deviation (d)", "determined component (d_f)", "systematic error",
                 "random component", "correction (delta, Δ)", "edge handling", "option"):
        assert word in words, word
    assert "scipy.ndimage's `mirror`" in words["edge handling"]


def test_no_source_calls_the_determined_component_repeatable():
    found = [os.path.relpath(p, ROOT) for p, text in _sources()
             if re.search(r"\brepeatable\b", text)]
    assert found == []

