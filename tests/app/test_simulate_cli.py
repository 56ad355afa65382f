# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp simulate`` on the bundled example and the presets: exit codes, JSON
content, model options, the papers' tables beside the simulated ones, refused options."""

import hashlib
import json
import os
import subprocess
import sys

import numpy as np
from numpy.testing import assert_allclose

import surfcomp.cli
from surfcomp.app.nominal import load_nominal
from surfcomp.core.compensation.corrected import MATCH_TOL
from surfcomp.core.simulation import presets
from surfcomp.core.simulation import simulate as sm
from tests.app.helpers import EXAMPLE_STEP, ROOT, run_in_process

#: until the command is listed in surfcomp.cli.COMMANDS the tests register it for the child
#: process only; afterwards they run the real ``python3 -m surfcomp``
_SHIM = ("import sys, surfcomp.cli as c; c.COMMANDS = tuple(c.COMMANDS) + ('simulate',); "
         "sys.exit(c.main(sys.argv[1:]))")


def run_cli(*args):
    head = (["-m", "surfcomp"] if "simulate" in surfcomp.cli.COMMANDS else ["-c", _SHIM])
    return subprocess.run([sys.executable, *head, "simulate", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def simulate_in_process(*args):
    """``simulate ARGS`` in this process (tests/app/helpers.py), for the runs whose results
    a test checks."""
    return run_in_process("simulate", *args)


def test_simulate_example_writes_json_with_every_replica(tmp_path):
    out = simulate_in_process(EXAMPLE_STEP, "--grid", "15x15", "--replicas", "2", "--seed", "4",
                              "--json", tmp_path / "s.json", "--html", tmp_path / "s.html",
                              "--quiet")
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
    """Only a constant 10 um error, no noise: before mean 10 um, offset removes it to the
    construction's precision."""
    out = simulate_in_process(EXAMPLE_STEP, "--grid", "7x7", "--replicas", "1", "--methods",
                              "none,offset,raw", "--offset", "0.01", "--slope-gain", "0",
                              "--abs-slope-gain", "0", "--tilt", "0,0", "--bow", "0,0",
                              "--sigma", "0", "--probe-sigma", "0",
                              "--json", tmp_path / "s.json", "--quiet")
    assert out.returncode == 0, out.stderr
    d = json.loads((tmp_path / "s.json").read_text())
    assert d["model"]["offset"] == 0.01 and d["model"]["sigma"] == 0.0
    before = d["before"]["replicas"][0]["all"]
    assert_allclose([before["mean"], before["min"], before["max"], before["max_positive"]], 0.01,
                    atol=1e-9)
    assert before["max_negative"] == 0.0        # no point below the nominal
    for m in d["methods"][1:]:
        r = m["replicas"][0]
        # at the nodes within the residual iteration's target MATCH_TOL (0.02 um; measured
        # 0.0095 um); between them the lean face (one knot span per grid step) carries the
        # constant offset of the curved face within 0.017 um (measured; 4 spans per step
        # gave 0.002 um), well inside the 0.1 um limit
        grid, every = r["grid"], r["all"]
        assert max(abs(grid["max_negative"]), abs(grid["max_positive"])) < MATCH_TOL, m["label"]
        assert max(abs(every["max_negative"]), abs(every["max_positive"])) < 3e-5, m["label"]


def _bad(tmp_path, capsys, *args):
    """The command run in this process (the refusals need no fresh one: the options are
    checked before any work; the real process is the other tests'): exit 2, a message,
    nothing written."""
    argv = ["simulate", EXAMPLE_STEP, *args, "--json", tmp_path / "s.json", "--html",
            tmp_path / "s.html", "--quiet"]
    rc = surfcomp.cli.main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert rc == 2, (rc, err)
    assert "Traceback" not in err
    assert os.listdir(tmp_path) == []
    return err


def test_bad_options_exit_2_and_write_nothing(tmp_path, capsys):
    assert "--grid '2x40': expected at least 3x3" in _bad(tmp_path, capsys, "--grid", "2x40")
    assert "unknown method 'best'" in _bad(tmp_path, capsys, "--methods", "raw,best")
    assert "--tilt '0.1': expected 2 comma-separated numbers" in _bad(tmp_path, capsys, "--tilt",
                                                                      "0.1")
    assert "--report-method 'none'" in _bad(tmp_path, capsys, "--report-method", "none")
    assert "sigma must be >= 0" in _bad(tmp_path, capsys, "--sigma", "-0.001")
    assert "Face9" in _bad(tmp_path, capsys, "--face", "Face9")


def test_options_that_go_with_another_are_refused_without_it(tmp_path, capsys):
    """Taken without a word before: the HTML report's method without --html, a face of
    NOMINAL on the preset's own surface, how an axis error file is read without the file."""
    for args, text in (
            (("--report-method", "mirror"), "--report-method picks the method of the HTML "
                                             "report (expected --html OUT.html with it)"),
            (("--face", "Face3"), "--face picks the face of NOMINAL, and none is given"),
            (("--object", "Part"), "--object picks the face of NOMINAL, and none is given"),
            (("--axis-units", "in"), "--axis-units tells how --axis-errors ERR.csv is read"),
            (("--reference", "1,2,3"), "--reference tells how --axis-errors ERR.csv is read"),
            (("--max-error", "5"), "--max-error tells how --axis-errors ERR.csv is read")):
        argv = ["simulate", "--preset", "mirror2019-s1", "--replicas", "1", *args, "--json",
                tmp_path / "s.json", "--quiet"]
        assert surfcomp.cli.main([str(a) for a in argv]) == 2, args
        err = capsys.readouterr().err
        assert text in err and "Traceback" not in err, (args, err)
        assert os.listdir(tmp_path) == []


def test_out_of_range_and_non_finite_options_name_the_option(tmp_path, capsys):
    """Issue 12: every option value that is not finite, negative where it cannot be, or
    beyond the limits is refused with exit 2 and a message naming the option."""
    for args, text in (
            (("--grid", "801x45"), "--grid '801x45': expected at most 800x800"),
            (("--margin", "nan"), "--margin nan"), (("--margin", "0.5"), "--margin 0.5"),
            (("--stock", "-0.1"), "--stock -0.1"), (("--stock", "inf"), "--stock inf"),
            (("--seed", "-1"), "--seed -1"), (("--between", "0"), "--between 0"),
            (("--replicas", "0"), "--replicas 0"), (("--refine", "0"), "--refine 0"),
            (("--deflection", "0,nan,0"), "--deflection '0,nan,0'"),
            (("--wavelength", "-10"), "--wavelength '-10'"),
            (("--semi-engagement", "-0.2"), "--semi-engagement '-0.2'"),
            (("--correlation-length", "inf"), "--correlation-length 'inf'"),
            (("--offset", "nan"), "--offset 'nan'"),
            (("--preset", "werner"), "unknown preset 'werner'")):
        assert text in _bad(tmp_path, capsys, *args), args
    out = run_cli("--quiet")  # neither a face nor a preset
    assert out.returncode == 2 and "give NOMINAL" in out.stderr and "mirror2019-s1" in out.stderr


def test_preset_prints_the_papers_table_beside_the_simulated_one(tmp_path):
    """No NOMINAL: the preset's own surface (mirror paper Fig. 2), its 70 points, 4 replicas;
    the paper's Tab. 3-4 figures in the rows of the simulated ones, JSON and HTML."""
    out = simulate_in_process("--preset", "mirror2019-s1", "--json", tmp_path / "s.json",
                              "--html", tmp_path / "s.html", "--report-method", "mirror",
                              "--quiet")
    assert out.returncode == 0, out.stderr
    text = out.stdout.split("Paper vs simulated: preset mirror2019-s1")[1]
    rows = {ln.split("|")[0].strip(): ln.split("|") for ln in text.splitlines() if "|" in ln}
    assert rows["none"][1].split() == ["14.1", "6.2", "-", "-", "54.9"]
    assert rows["offset"][1].split() == ["2.0", "6.1", "-", "-", "30.1"]
    assert rows["semi-finished"][1].split() == ["15.1", "6.2", "-", "-", "57.6"]
    assert rows["mirror"][1].split() == ["0.1", "2.4", "-", "-", "12.8"]
    assert rows["raw"][1].split() == ["-"] * 5 and len(rows["raw"][2].split()) == 5
    assert "mirror (vs semi-finished)" in text and "Preset:    mirror2019-s1" in out.stdout
    d = json.loads((tmp_path / "s.json").read_text())
    assert d["grid"] == [10, 7] and d["replicas"] == 4 and d["model"]["stock"] == 0.2
    assert d["inputs"]["nominal"]["preset"] == "mirror2019-s1"
    assert "path" not in d["inputs"]["nominal"] and d["inputs"]["nominal"]["degree"] == [2, 1]
    assert {m["label"]: m for m in d["methods"]}["mirror"]["stock_mm"] == 0.2
    side = {r["method"]: r for r in d["side_by_side"]["rows"]}
    # calibrated to the paper's semi-finished parts (Tab. 3: 15.1 um, std 6.2 um)
    assert_allclose([side["semi-finished"]["simulated"][k] for k in ("mean", "std")],
                    [0.0151, 0.0062], rtol=0.1)
    assert side["mirror"]["simulated"]["std"] < 0.5 * side["none"]["simulated"]["std"]
    assert_allclose(d["side_by_side"]["gains"][1]["std"]["paper"], 1 - 2.4 / 6.2, atol=1e-12)
    page = (tmp_path / "s.html").read_text()
    assert 'id="side-by-side"' in page and "What the model contains and leaves out" in page
    for key in ("before", "none", "offset", "raw", "filtered", "semi-finished", "mirror"):
        assert 'alt="simulated map of %s"' % key in page, key
    assert "<td class=\"num\">54.9</td>" in page


def test_preset_on_a_nominal_file_is_the_same_process_on_that_face(tmp_path):
    """The bundled example face is the werner2022 preset's surface: the preset run on the
    STEP file gives the preset's own numbers (no random part: exactly)."""
    out = simulate_in_process(EXAMPLE_STEP, "--preset", "werner2022", "--grid", "9x9",
                              "--replicas", "1", "--methods", "none,raw,mirror", "--sigma",
                              "0", "--probe-sigma", "0", "--json", tmp_path / "s.json",
                              "--quiet")
    assert out.returncode == 0, out.stderr
    assert "surface replaced by NOMINAL" in out.stdout and "Paper vs simulated" in out.stdout
    d = json.loads((tmp_path / "s.json").read_text())
    assert d["model"]["deflection"] == [0.02, 0.2, 0.15] and d["model"]["sigma"] == 0.0
    assert d["preset"]["surface_replaced_by"] == d["inputs"]["nominal"]["path"]
    p = presets.get_preset("werner2022")
    res = presets.run_preset(p, grid=(9, 9), replicas=1, model=p.machining_model(
        sigma=0.0, probe_sigma=0.0), specs=sm.method_specs(["none", "raw", "mirror"]))
    for m in d["methods"]:
        got = m["replicas"][0]["all"]
        assert_allclose([got["mean"], got["std"]],
                        [res.values(m["label"], "mean")[0], res.values(m["label"], "std")[0]],
                        atol=1e-8)
    assert load_nominal(EXAMPLE_STEP).surface.shape == presets.werner_surface().shape
