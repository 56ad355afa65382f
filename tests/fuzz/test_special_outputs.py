# SPDX-License-Identifier: LGPL-2.1-or-later
"""Device and special outputs, standard output, long names (issue 25).

Nothing is staged in, or renamed over, anything in /dev, /proc or /sys or anything that is
not a regular file; ``-`` writes to standard output without renaming. The /dev cases run
against a fake device folder (``outpath.SPECIAL_FOLDERS`` pointed at the sandbox), never by
renaming over the machine's real /dev/stdout. A closed or full standard output after the
commit exits 0 and names the outputs (they are complete); standard output failing while
it is itself an output rolls every file back (exit 2).
"""

import json
import os
import subprocess
import sys

import pytest

from surfcomp.errors import InputError
from surfcomp.io import outpath

from . import inputs as I
from .harness import (
    EXAMPLE_STEP,
    Case,
    check_tree,
    default_signals,
    run_case,
    run_cli,
    snapshot,
    subprocess_env,
)

GCODE = ("gcode", "in.ngc", "--axis-errors", "e.csv")
BASE = I.setup(I.put("in.ngc", I.SMALL_PROGRAM), I.put("e.csv", I.AXIS_CSV))


@pytest.fixture
def fake_dev(tmp_path, monkeypatch):
    """A sandbox whose ``fakedev`` folder counts as /dev: ``fakedev/stdout`` is a link to
    ``captured.ngc`` (standard output redirected to a file), ``fakedev/null`` a regular
    file standing in for a device node."""
    box = tmp_path / "box"
    box.mkdir()
    BASE(str(box))
    (box / "fakedev").mkdir()
    (box / "captured.ngc").write_text("what the shell redirected\n")
    os.symlink("../captured.ngc", str(box / "fakedev" / "stdout"))
    (box / "fakedev" / "null").write_text("")
    os.symlink("fakedev/null", str(box / "to-null.ngc"))
    monkeypatch.setattr(outpath, "SPECIAL_FOLDERS",
                        outpath.SPECIAL_FOLDERS + (str(box / "fakedev"),))
    return box


@pytest.mark.parametrize("option, path, says", [
    ("-o", "fakedev/stdout", "is in %s, a folder of devices and kernel state"),
    ("-o", "fakedev/../fakedev/stdout", "is in %s"),
    ("-o", "./fakedev//null", "is in %s"),
    ("--report", "fakedev/new.json", "is in %s"),
    ("-o", "to-null.ngc", "leads to %s/null, in a folder of devices"),
], ids=["stdout-link", "dotdot-spelling", "doubled-slash", "new-file-in-dev", "link-into-dev"])
def test_nothing_is_staged_in_a_device_folder(fake_dev, option, path, says):
    before = snapshot(fake_dev)
    argv = GCODE + (option, path) + (("-o", "out.ngc") if option != "-o" else ())
    res = run_cli(argv, str(fake_dev))
    assert res.rc == 2, res.err
    assert (says % os.path.realpath(str(fake_dev / "fakedev"))) in res.err, res.err
    assert res.err.startswith("surfcomp: error: %s: %s " % (path, option)), res.err
    check_tree(before, snapshot(fake_dev))
    assert os.readlink(str(fake_dev / "fakedev" / "stdout")) == "../captured.ngc"


@pytest.mark.parametrize("path", ["/proc/self/fd/1", "/proc/self/x.ngc", "/sys/x.ngc",
                                  "/dev/shm/../null"])
def test_kernel_folders_refused(tmp_path, path):
    """Refused by the check, before anything is created (safe on the real folders)."""
    box = tmp_path / "box"
    res = run_case(Case(path, GCODE + ("-o", path), BASE, file=path), box)
    assert "folder of devices and kernel state" in res.err or "is a folder" in res.err or \
        "not a regular file" in res.err, res.err


def test_real_dev_stdout_refused():
    """The real ``/dev/stdout`` is refused by the resolution itself, which stages nothing
    (the whole command is run only against a fake device folder above: as root, a
    regression there must not be able to rename over the real one)."""
    with pytest.raises(InputError) as info:
        outpath.resolve("-o", "/dev/stdout")
    text = str(info.value)
    assert "is in /dev" in text and "use - for standard output" in text, text


def test_fifo_and_links_to_it_refused(tmp_path):
    def setup(box):
        BASE(box)
        os.mkfifo(os.path.join(box, "f.ngc"))
        os.symlink("f.ngc", os.path.join(box, "lf.ngc"))
    for path in ("f.ngc", "lf.ngc", "./lf.ngc"):
        run_case(Case(path, GCODE + ("-o", path), setup, file=path,
                      says=("not a regular file",)), tmp_path / path.replace("/", "_"))


def test_link_to_a_regular_file_is_written_through(tmp_path):
    """``cur.ngc -> runs/r1.ngc``: as ``open()`` would, the file the link leads to gets the
    program; the link stays a link."""
    box = tmp_path / "box"
    box.mkdir()
    BASE(str(box))
    (box / "runs").mkdir()
    (box / "runs" / "r1.ngc").write_text("old\n")
    os.symlink("runs/r1.ngc", str(box / "cur.ngc"))
    res = run_cli(GCODE + ("-o", "cur.ngc"), str(box))
    assert res.rc == 0, res.err
    assert os.readlink(str(box / "cur.ngc")) == "runs/r1.ngc"
    text = (box / "runs" / "r1.ngc").read_text()
    assert text.startswith("(surfcomp") or "G1" in text, text[:200]
    assert sorted(os.listdir(str(box / "runs"))) == ["r1.ngc"]


# --------------------------------------------------------------------- standard output
def _popen(argv, cwd, stdout):
    return subprocess.Popen([sys.executable, "-m", "surfcomp"] + list(argv), cwd=cwd,
                            stdout=stdout, stderr=subprocess.PIPE, env=subprocess_env(),
                            preexec_fn=default_signals)


def test_dash_writes_the_program_to_stdout(tmp_path):
    box = tmp_path / "box"
    box.mkdir()
    BASE(str(box))
    ref = run_cli(GCODE + ("-o", "ref.ngc"), str(box))
    assert ref.rc == 0, ref.err
    proc = _popen(GCODE + ("-o", "-", "--report", "r.json"), str(box), subprocess.PIPE)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert out == (box / "ref.ngc").read_bytes()
    err = err.decode()
    assert "wrote - (standard output)" in err and "wrote r.json" in err
    assert "Predicted positional error" in err          # the summary went to stderr
    assert json.loads((box / "r.json").read_text())["outputs"]["program"] == "-"
    assert sorted(os.listdir(str(box))) == ["e.csv", "in.ngc", "r.json", "ref.ngc"]


def test_report_to_stdout_in_process(tmp_path):
    box = tmp_path / "box"
    box.mkdir()
    BASE(str(box))
    res = run_cli(GCODE + ("-o", "out.ngc", "--report", "-"), str(box))
    assert res.rc == 0, res.err
    rep = json.loads(res.out)
    assert rep["schema"] == "surfcomp-gcode-report/1" and rep["outputs"]["report"] == "-"
    assert "wrote out.ngc" in res.err


def test_two_outputs_to_stdout_refused(tmp_path):
    run_case(Case("two-dashes", GCODE + ("-o", "-", "--report", "-"), BASE, file="-",
                  says=("-o and --report name the same standard output",)), tmp_path / "box")


@pytest.mark.parametrize("how", ["closed-pipe", "dev-full"])
def test_failing_stdout_after_the_commit(tmp_path, how):
    """``| head`` (the reader gone) or ``> /dev/full``: the outputs are complete, exit 0,
    stderr names them (was exit 120)."""
    box = tmp_path / "box"
    box.mkdir()
    BASE(str(box))
    argv = GCODE + ("-o", "out.ngc", "--report", "r.json")
    if how == "closed-pipe":
        proc = _popen(argv, str(box), subprocess.PIPE)
        proc.stdout.close()
        err = proc.stderr.read()
        proc.wait(timeout=120)
        why = "Broken pipe"
    else:
        with open("/dev/full", "wb") as full:
            proc = _popen(argv, str(box), full)
            err = proc.stderr.read()
            proc.wait(timeout=120)
        why = "No space left on device"
    err = err.decode()
    assert proc.returncode == 0, err
    assert ("surfcomp: standard output failed (%s) after the outputs were complete; "
            "written: out.ngc, r.json" % why) in err, err
    assert "Traceback" not in err
    assert sorted(os.listdir(str(box))) == ["e.csv", "in.ngc", "out.ngc", "r.json"]


@pytest.mark.parametrize("how", ["closed-pipe", "dev-full"])
def test_failing_stdout_that_is_an_output_rolls_back(tmp_path, how):
    """``-o -`` when standard output cannot take the program: no file is written either
    (``--report r.json`` is rolled back), exit 2."""
    box = tmp_path / "box"
    box.mkdir()
    BASE(str(box))
    before = snapshot(str(box))
    argv = GCODE + ("-o", "-", "--report", "r.json")
    if how == "closed-pipe":
        proc = _popen(argv, str(box), subprocess.PIPE)
        proc.stdout.close()
        err = proc.stderr.read()
        proc.wait(timeout=120)
    else:
        with open("/dev/full", "wb") as full:
            proc = _popen(argv, str(box), full)
            err = proc.stderr.read()
            proc.wait(timeout=120)
    err = err.decode()
    assert proc.returncode == 2, err
    assert "surfcomp: error: -: cannot write the file: " in err, err
    assert "Traceback" not in err and "wrote" not in err
    check_tree(before, snapshot(str(box)))


# --------------------------------------------------------------------- long names
def _name(total, ext=".ngc", char="a"):
    return char * ((total - len(ext.encode())) // len(char.encode())) + ext


@pytest.mark.parametrize("name", [_name(250), _name(255), _name(254, char="\u00e9"),
                                  _name(255, ".json")], ids=["250", "255", "254-bytes-utf8",
                                                             "255-json"])
def test_names_up_to_the_limit(tmp_path, name):
    """The staged file's name fits the file system even when the output's own takes all of
    it (the temporary name added 14 characters: a 250-character name was refused)."""
    assert len(name.encode()) <= 255
    opt = "--report" if name.endswith(".json") else "-o"
    argv = GCODE + ((opt, name) if opt == "-o" else ("-o", "out.ngc", opt, name))
    writes = (name,) if opt == "-o" else (name, "out.ngc")
    run_case(Case("long", argv, BASE, rc=0, writes=writes), tmp_path / "box")


def test_name_past_the_limit_refused(tmp_path):
    name = _name(256)
    run_case(Case("too-long", GCODE + ("-o", name), BASE, file=name,
                  says=("has a name of 256 bytes; the file system takes at most 255",)),
             tmp_path / "box")


def test_250_character_corrected_face(tmp_path, cad_cache):
    """The CAD writer's staged file keeps the .step suffix it chooses the format by."""
    name = _name(250, ".step")
    run_case(Case("long-step", ("compensate", "n.step", "m.csv", "-o", name, "--quiet"),
                  I.setup(I.copy("n.step", EXAMPLE_STEP), I.put("m.csv", I.csv)), rc=0,
                  writes=(name,)), tmp_path / "box")


def test_255_byte_name_replaced(tmp_path):
    """An existing output with a name of 255 bytes is replaced (its backup during the
    commit fits the file system too); nothing else is left."""
    box = tmp_path / "box"
    box.mkdir()
    BASE(str(box))
    name = _name(255)
    (box / name).write_text("old program\n")
    res = run_cli(GCODE + ("-o", name), str(box))
    assert res.rc == 0, res.err
    assert "G1" in (box / name).read_text()
    assert sorted(os.listdir(str(box))) == sorted(["e.csv", "in.ngc", name])
