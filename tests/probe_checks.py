# SPDX-License-Identifier: LGPL-2.1-or-later
"""Probing programs read by LinuxCNC's own interpreter, and the checks every test makes.

``rs274 -t TOOLS -g IN OUT`` (Debian package ``linuxcnc-uspace``) runs LinuxCNC's RS274/NGC
interpreter without a machine and prints the canonical moves: ``STRAIGHT_TRAVERSE``,
``STRAIGHT_FEED`` and ``STRAIGHT_PROBE`` with the end point, 4 decimals of the program's
unit. A probe move's start is the end of the move before it. rs274 has no probe: it takes
a probe's end point as the trip point (``#5061``-``#5063``), so a second touch backs off
from there. These helpers fail (they do not skip) without rs274.
"""

import os
import re
import subprocess

import numpy as np

RS274 = "/usr/bin/rs274"
_MOVE = re.compile(r"^\s*\d+\s+N\S*\s+(STRAIGHT_TRAVERSE|STRAIGHT_FEED|STRAIGHT_PROBE)"
                   r"\((.*)\)\s*$")
#: rs274 prints 4 decimals: a position is known within half of the last one
PRINTED = 0.5e-4


def own_tool_data(folder):
    """The environment for one ``rs274`` run: HOME in ``folder``. LinuxCNC's interpreter
    keeps its tool table in a memory-mapped file ``$HOME/.tool.mmap``, so two runs at once
    (the parallel test workers) shared one table, and one run found the other's tools
    ("Requested tool 99 not found in the tool table")."""
    return dict(os.environ, HOME=str(folder))


def rs274_moves(program, tmp_path, tool=99, diameter=2.0, other_tools=()):
    """The canonical moves of ``program``: list of ``(kind, start (3,), end (3,))`` in mm,
    the first start being the machine's origin. The tool table holds ``tool`` and the
    numbers of ``other_tools``."""
    assert os.access(RS274, os.X_OK), (
        "%s is missing: install LinuxCNC's interpreter (Debian package linuxcnc-uspace)"
        % RS274)
    table = tmp_path / "probe.tbl"
    table.write_text("T%d P%d Z0 D%g ;probe\n" % (tool, tool, diameter)
                     + "".join("T%d P%d Z0 D6 ;other\n" % (t, t) for t in other_tools))
    out = tmp_path / (os.path.basename(str(program)) + ".canon")
    run = subprocess.run([RS274, "-t", str(table), "-g", str(program), str(out)],
                         cwd=str(tmp_path), env=own_tool_data(tmp_path), capture_output=True,
                         text=True, timeout=300)
    errors = [ln for ln in run.stderr.splitlines() if ln.strip() not in ("", "executing")]
    assert run.returncode == 0 and not errors, "rs274 refused %s: %s" % (program, run.stderr)
    text = out.read_text()
    assert "PROGRAM_END" in text and "USE_LENGTH_UNITS(CANON_UNITS_MM)" in text
    moves, here = [], np.zeros(3)
    for line in text.splitlines():
        m = _MOVE.match(line)
        if m:
            end = np.array([float(v) for v in m.group(2).split(",")[:3]])
            moves.append((m.group(1), here, end))
            here = end
    return moves


def check_probe_moves(moves, points, normals, R, overtravel, max_deg=0.01):
    """Every STRAIGHT_PROBE runs along a planned -normal, in the plan's order (one or more
    per point, consecutive), and ends ``overtravel`` past the nominal contact ``p + R n``.
    Returns the probe moves as ``(start, end)`` arrays and the largest angle (degrees)."""
    probes = [(a, b) for kind, a, b in moves if kind == "STRAIGHT_PROBE"]
    ends = np.array([b for _a, b in probes])
    target = points + (R - overtravel) * normals
    per = len(probes) // len(points)
    assert len(probes) == per * len(points) and per >= 1
    # in the plan's order: probe k ends at the target of point k // per
    np.testing.assert_allclose(ends, np.repeat(target, per, axis=0), atol=PRINTED * 1.01,
                               rtol=0)
    worst = 0.0
    for k, (a, b) in enumerate(probes):
        d = (b - a) / np.linalg.norm(b - a)
        ang = np.degrees(np.arccos(np.clip(-d @ normals[k // per], -1, 1)))
        worst = max(worst, ang)
    assert worst <= max_deg, worst
    return probes, worst
