# SPDX-License-Identifier: LGPL-2.1-or-later
"""simulate --align / --transform (issue 28): the alignment object in the JSON and HTML
reports, the summary, and bad input (exit 2, nothing written)."""

import json

import numpy as np
from numpy.testing import assert_allclose

from surfcomp.core.measurement import align
from tests.app.helpers import EXAMPLE_STEP, run_in_process
from tests.app.test_align_cli import run_cli

LOOP = ("--grid", "11x11", "--replicas", "2", "--methods", "offset,filtered", "--sigma", "0",
        "--probe-sigma", "0", "--offset", "0.02")


def test_simulate_reports_what_the_best_fit_absorbed(tmp_path):
    T = align.work_offset([30.0, 10.0, -4.0], -8.0)
    (tmp_path / "t.json").write_text(json.dumps({"matrix": T.tolist()}))
    plain = run_in_process("simulate", EXAMPLE_STEP, *LOOP, "--json", tmp_path / "p.json",
                           "--quiet")
    assert plain.returncode == 0, plain.stderr
    out = run_in_process("simulate", EXAMPLE_STEP, *LOOP, "--align", "bestfit", "--align-dof",
                         "z,rx,ry", "--transform", tmp_path / "t.json", "--json",
                         tmp_path / "s.json", "--html", tmp_path / "s.html", "--quiet")
    assert out.returncode == 0, out.stderr
    p = json.loads((tmp_path / "p.json").read_text())
    s = json.loads((tmp_path / "s.json").read_text())
    assert "alignment" not in p
    a = s["alignment"]
    assert a["method"] == "bestfit" and a["dof"] == ["z", "rx", "ry"] and a["converged"]
    assert_allclose(a["known_transform"], T, atol=1e-12)
    # the fit starts from the known transform and ends near it (the frame came back)
    assert_allclose(np.asarray(a["matrix"])[:3, 3], T[:3, 3], atol=0.1)
    fits = a["simulated"]["fits"]
    assert [(f["method"], f["replica"]) for f in fits] == [
        ("offset", 0), ("filtered", 0), ("offset", 1), ("filtered", 1)]
    assert all(f["converged"] for f in fits)
    # without noise every replica's fit absorbs the same mean: about the 25 um error
    means = [f["absorbed"]["mean_offset_um"] for f in fits]
    assert_allclose(means, means[0], atol=1e-6)
    assert -26.0 < means[0] < -23.0
    # the offset method then leaves that mean in the part; without alignment it goes
    assert _mean(s, "offset") > 20e-3 and abs(_mean(p, "offset")) < 1e-4
    assert "Alignment:    bestfit (with the known transform)" in out.stdout
    assert "offset: 2 fit(s), 2 converged; absorbed mean offset" in out.stdout
    assert "absorbed a mean offset" in out.stderr
    assert '<section id="alignment">' in (tmp_path / "s.html").read_text()


def _mean(report, label):
    """The mean deviation (mm) of the first replica's corrected part."""
    entry = next(m for m in report["methods"] if m["label"] == label)
    return entry["replicas"][0]["all"]["mean"]


def test_bad_alignment_on_simulate_exits_2_and_writes_nothing(tmp_path):
    sheared = np.eye(4)
    sheared[0, 1] = 1e-3
    np.savetxt(tmp_path / "t.txt", sheared)
    out = run_cli("simulate", EXAMPLE_STEP, *LOOP, "--transform", tmp_path / "t.txt",
                  "--json", tmp_path / "s.json", "--quiet")
    assert out.returncode == 2 and "not rigid" in out.stderr, out.stderr
    out = run_cli("simulate", EXAMPLE_STEP, "--align", "bestfit", "--compare-layouts", "20",
                  "--json", tmp_path / "s.json", "--quiet")
    assert out.returncode == 2 and "do not go with --compare-layouts" in out.stderr
    out = run_cli("simulate", EXAMPLE_STEP, *LOOP, "--align", "rps", "--json",
                  tmp_path / "s.json", "--quiet")
    assert out.returncode == 2 and "--align 'rps' needs --rps" in out.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.txt"]
