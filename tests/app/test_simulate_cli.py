"""``python3 -m surfcomp simulate`` on the bundled example: exit codes, JSON content, model
options."""

import hashlib
import json
import os
import subprocess
import sys

import numpy as np
from numpy.testing import assert_allclose

import surfcomp.cli
from tests.app.helpers import EXAMPLE_STEP, ROOT

#: until the command is listed in surfcomp.cli.COMMANDS the tests register it for the child
#: process only; afterwards they run the real ``python3 -m surfcomp``
_SHIM = ("import sys, surfcomp.cli as c; c.COMMANDS = tuple(c.COMMANDS) + ('simulate',); "
         "sys.exit(c.main(sys.argv[1:]))")


def run_cli(*args):
    head = (["-m", "surfcomp"] if "simulate" in surfcomp.cli.COMMANDS else ["-c", _SHIM])
    return subprocess.run([sys.executable, *head, "simulate", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def test_simulate_example_writes_json_with_every_replica(tmp_path):
    out = run_cli(EXAMPLE_STEP, "--grid", "15x15", "--replicas", "2", "--seed", "4",
                  "--json", tmp_path / "s.json", "--html", tmp_path / "s.html", "--quiet")
    assert out.returncode == 0, out.stderr
    assert "Profile error ISO 1101" in out.stdout and "per replica" in out.stdout
    d = json.loads((tmp_path / "s.json").read_text())
    assert d["schema"] == "surfcomp-simulation/1" and d["command"] == "simulate"
    assert (d["inputs"]["nominal"]["sha256"]
            == hashlib.sha256(open(EXAMPLE_STEP, "rb").read()).hexdigest())
    assert d["grid"] == [15, 15] and d["evaluation_grid"] == [29, 29] and d["replicas"] == 2
    methods = {m["label"]: m for m in d["methods"]}
    assert list(methods) == ["none", "offset", "raw", "filtered", "mirror"]
    assert methods["mirror"]["stock_mm"] == 0.3 and methods["filtered"]["mask_size"] == 5
    for m in methods.values():
        assert len(m["replicas"]) == 2
        assert (m["replicas"][1]["all"]["count"] == 29 * 29
                and m["replicas"][1]["grid"]["count"] == 225)
    none_std = np.array([r["all"]["std"] for r in methods["none"]["replicas"]])
    # the default model on the example face: Werner Tab. 1-like, std about 16.5 um
    assert_allclose(none_std, 0.0165, atol=0.0015)
    for label in ("raw", "filtered", "mirror"):
        std = np.array([r["all"]["std"] for r in methods[label]["replicas"]])
        assert np.all(std < 0.25 * none_std), label
    offset = methods["offset"]
    assert np.all(np.abs([r["all"]["mean"] for r in offset["replicas"]]) < 0.0005)
    assert_allclose([r["all"]["std"] for r in offset["replicas"]], none_std, rtol=0.03)
    page = (tmp_path / "s.html").read_text()
    assert all('id="%s"' % s in page for s in ("inputs", "maps", "simulation"))
    assert sorted(os.listdir(tmp_path)) == ["s.html", "s.json"]


def test_model_options_reach_the_model(tmp_path):
    """Only a constant 10 um error, no noise: before mean 10 um, offset removes it exactly."""
    out = run_cli(EXAMPLE_STEP, "--grid", "7x7", "--replicas", "1", "--methods", "none,offset,raw",
                  "--offset", "0.01", "--slope-gain", "0", "--abs-slope-gain", "0", "--tilt", "0,0",
                  "--bow", "0,0", "--sigma", "0", "--probe-sigma", "0",
                  "--json", tmp_path / "s.json", "--quiet")
    assert out.returncode == 0, out.stderr
    d = json.loads((tmp_path / "s.json").read_text())
    assert d["model"]["offset"] == 0.01 and d["model"]["sigma"] == 0.0
    before = d["before"]["replicas"][0]["all"]
    assert_allclose([before["mean"], before["max_negative"], before["max_positive"]], 0.01,
                    atol=1e-9)
    for m in d["methods"][1:]:
        r = m["replicas"][0]["all"]
        assert max(abs(r["max_negative"]), abs(r["max_positive"])) < 2e-6, m["label"]


def _bad(tmp_path, *args):
    out = run_cli(EXAMPLE_STEP, *args, "--json", tmp_path / "s.json", "--html", tmp_path / "s.html",
                  "--quiet")
    assert out.returncode == 2, (out.returncode, out.stderr)
    assert "Traceback" not in out.stderr
    assert os.listdir(tmp_path) == []
    return out.stderr


def test_bad_options_exit_2_and_write_nothing(tmp_path):
    assert "--grid '2x40': expected at least 3x3" in _bad(tmp_path, "--grid", "2x40")
    assert "unknown method 'best'" in _bad(tmp_path, "--methods", "raw,best")
    assert "--tilt '0.1': expected 2 comma-separated numbers" in _bad(tmp_path, "--tilt", "0.1")
    assert "--report-method 'none'" in _bad(tmp_path, "--report-method", "none")
    assert "sigma must be >= 0" in _bad(tmp_path, "--sigma", "-0.001")
    assert "Face9" in _bad(tmp_path, "--face", "Face9")
