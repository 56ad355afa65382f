# SPDX-License-Identifier: LGPL-2.1-or-later
"""Output paths spelled every way, on every command, the document route and the job file
(issue 25): each output is resolved once, as ``open()`` would resolve it, and that path is
both what is compared with the inputs and where the file goes.

The sandbox (``box``) holds every input, a folder ``v`` with ``v/sub``, a link
``vlink -> v/sub`` and a plain file ``afile``; the kernel resolves ``vlink/..`` to ``v``,
and ``nope/..`` and ``afile/..`` not at all.
"""

import json
import os

import pytest

from surfcomp.app.file_route import JOB_FILES
from surfcomp.cli import registry

from . import inputs as I
from .harness import EXAMPLE_STEP, Case, check_message, check_tree, run_case, snapshot

BOX = "box"
INPUTS = I.setup(I.copy("nominal.step", EXAMPLE_STEP), I.put("m.csv", I.csv),
                 I.put("in.ngc", I.SMALL_PROGRAM), I.put("e.csv", I.AXIS_CSV),
                 I.put("plan.csv", I.csv),
                 I.put("t.txt", "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"),
                 I.folder("v/sub"), I.link("vlink", "v/sub"), I.put("afile", "a file"))
DOC_INPUTS = I.setup(INPUTS, I.put("d.FCStd", I.document_bytes))

#: command -> (argv before the outputs, {input file: label in messages}, outputs with a
#: harmless value each, outputs that must be given)
SIM = ("--grid", "5x5", "--replicas", "1", "--methods", "none,raw", "--quiet")
COMMANDS = {
    "compensate": (("compensate", "nominal.step", "m.csv", "--quiet"),
                   {"nominal.step": "NOMINAL", "m.csv": "MEASUREMENTS"},
                   {"-o": "c.step", "--report": "r.json", "--points": "p.csv",
                    "--curves": "n.step", "--html": "r.html"}, ()),
    "inspect": (("inspect", "nominal.step", "m.csv", "--quiet"),
                {"nominal.step": "NOMINAL", "m.csv": "MEASUREMENTS"},
                {"--report": "r.json", "--html": "r.html"}, ()),
    "simulate": (("simulate", "nominal.step", "--axis-errors", "e.csv") + SIM,
                 {"nominal.step": "NOMINAL", "e.csv": "--axis-errors"},
                 {"--json": "s.json", "--html": "s.html"}, ()),
    "gcode": (("gcode", "in.ngc", "--axis-errors", "e.csv"),
              {"in.ngc": "IN.ngc", "e.csv": "--axis-errors"},
              {"-o": "out.ngc", "--report": "r.json"}, ("-o",)),
    "plan": (("plan", "nominal.step", "--quiet"), {"nominal.step": "NOMINAL"},
             {"-o": "p.csv", "--dropped": "d.csv"}, ("-o",)),
    "document": (("compensate", "d.FCStd", "m.csv", "--object", "Nominal", "--replace",
                  "--quiet"),
                 {"d.FCStd": "document", "m.csv": "MEASUREMENTS"},
                 {"--save": "out.FCStd", "--gcode": "o.ngc"}, ("--save",)),
}

#: spellings of the input X that the kernel resolves to X itself
ONTO = ("./{x}", ".//{x}", "v/../{x}", "v/sub/../../{x}", "vlink/../../{x}",
        "vlink/./.././../{x}", "/proc/self/cwd/{x}", "../" + BOX + "/{x}", "v//..//{x}")
#: spellings whose folder the kernel cannot reach (a missing folder, a file) before ..
UNREACHABLE = ("nope/../{x}", "nope/./../{x}", "nope//../{x}", "afile/../{x}", "{x}/../{x}",
               "v/nope/../../{x}", "vlink/nope/../../{x}")
#: folders that do not exist, named plainly: an error, as for open() (no folder is made)
NEW_FOLDERS = [
    ("compensate", "--report", "new/r.json"),
    ("compensate", "-o", "vlink/../new/a/c.step"),
    ("gcode", "--report", "v/sub/../new//r.json"),
    ("simulate", "--json", ".//new/s.json"),
]
#: spellings that name a folder
FOLDERS = ("{x}/", "{x}//", "./{x}/", "{x}/.", "v/..", "vlink/.")


def _argv(command, option, path):
    head, _inputs, outputs, required = COMMANDS[command]
    argv = list(head) + [option, path]
    for other in required:
        if other != option:
            argv += [other, outputs[other]]
    return tuple(argv)


def _setup(command):
    return DOC_INPUTS if command == "document" else INPUTS


def _cases():
    cases = []
    for command, (_head, inputs, outputs, _req) in COMMANDS.items():
        for option in outputs:
            for x, label in inputs.items():
                for spelling in ONTO:
                    path = spelling.format(x=x)
                    cases.append(Case("%s-%s-%s" % (command, option, path), _argv(
                        command, option, path), _setup(command), file=path,
                        says=("%s would overwrite the input %s" % (option, label),)))
                for spelling in UNREACHABLE:
                    path = spelling.format(x=x)
                    cases.append(Case("%s-%s-%s" % (command, option, path), _argv(
                        command, option, path), _setup(command), file=path,
                        says=("%s cannot be written: its folder" % option,
                              "expected an existing folder")))
                for spelling in FOLDERS:
                    path = spelling.format(x=x)
                    cases.append(Case("%s-%s-%s" % (command, option, path), _argv(
                        command, option, path), _setup(command), file=path,
                        says=("(expected a file name",)))
            cases.append(Case("%s-%s-empty" % (command, option), _argv(command, option, ""),
                              _setup(command), says=("%s: the file name is empty" % option,)))
    return cases


@pytest.mark.parametrize("case", _cases(), ids=str)
def test_spelling_refused(case, tmp_path):
    """Refused before any work (the check precedes reading): exit 2, the user's spelling
    first in the message, nothing written."""
    run_case(case, tmp_path / BOX)


#: (command, option, spelling through the link, what is written): vlink/.. is v
THROUGH_THE_LINK = [
    ("compensate", "-o", "vlink/../nominal.step", "v/nominal.step"),
    ("compensate", "--report", "vlink/../m.csv", "v/m.csv"),
    ("inspect", "--html", "vlink/./../nominal.step", "v/nominal.step"),
    ("simulate", "--json", "vlink/../e.csv", "v/e.csv"),
    ("gcode", "-o", "vlink/../in.ngc", "v/in.ngc"),
    ("document", "--save", "vlink/../d.FCStd", "v/d.FCStd"),
]


@pytest.mark.parametrize("command, option, path, written", THROUGH_THE_LINK,
                         ids=["-".join(c[:3]) for c in THROUGH_THE_LINK])
def test_dotdot_after_a_link_writes_where_the_kernel_says(command, option, path, written,
                                                          tmp_path, request):
    """The issue's example: with vlink -> v/sub, ``vlink/../n.step`` is ``v/n.step``; the
    input ``n.step`` next to it stays as it was."""
    if command != "gcode":
        request.getfixturevalue("cad_cache")
    run_case(Case(path, _argv(command, option, path), _setup(command), rc=0,
                  writes=(written,)), tmp_path / BOX)


@pytest.mark.parametrize("command, option, path", NEW_FOLDERS,
                         ids=["-".join(c) for c in NEW_FOLDERS])
def test_a_folder_that_does_not_exist_is_an_error(command, option, path, tmp_path, request):
    if command != "gcode":
        request.getfixturevalue("cad_cache")
    run_case(Case(path, _argv(command, option, path), _setup(command), rc=2, file=path,
                  says=("cannot be written: its folder", "No such file or directory",
                        "create it first")), tmp_path / BOX)


# --------------------------------------------------------------------- every input guarded
def _registry_pairs():
    """(command, input entry, output entry) of every command line the registry allows."""
    return [(cmd, i, o) for cmd in ("compensate", "inspect", "simulate", "gcode", "plan")
            for i in registry.entries(cmd, "input") for o in registry.entries(cmd, "output")]


#: a file for each input of the registry (by label)
FILE_OF = {"NOMINAL": "nominal.step", "MEASUREMENTS": "m.csv", "--axis-errors": "e.csv",
           "IN.ngc": "in.ngc", "--plan": "plan.csv", "--program": "in.ngc",
           "--transform": "t.txt"}


@pytest.mark.parametrize("command, inp, out", _registry_pairs(),
                         ids=["%s-%s-over-%s" % (c, o.label, i.label)
                              for c, i, o in _registry_pairs()])
def test_every_input_of_the_registry_is_guarded(command, inp, out, tmp_path):
    """Enumerates the registry: each output option given each input's file is refused, so
    an input option added to the registry is guarded without further code."""
    assert inp.label in FILE_OF, "an input without a file in this test: %s" % inp.label
    argv = [command]
    for e in registry.entries(command):
        if e.role == "input" and not e.flags[0].startswith("-"):
            argv.append(FILE_OF[e.label])
        elif e.role == "input":
            argv += [e.flags[0], FILE_OF[e.label]]
        elif e.role == "output" and e is not out and e.kwargs.get("required"):
            argv += [e.flags[0], "x" + os.path.splitext(FILE_OF["IN.ngc"])[1]]
    target = FILE_OF[inp.label]
    argv += [out.flags[0], target]
    if command == "simulate":
        argv += list(SIM)
    label = inp.waiver_label if out.label in inp.waived_for else inp.label
    run_case(Case("guard", tuple(argv), INPUTS, file=target,
                  says=("%s would overwrite the input %s" % (out.label, label),)),
             tmp_path / BOX)


def test_the_registry_defines_every_file_option_of_the_parsers():
    """Every option of the parsers whose value names a file is in the registry (so its
    role is known): the ones with a file-like metavar."""
    from surfcomp.cli import COMMANDS, build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.choices and "gcode" in a.choices)
    for command in COMMANDS:
        known = {e.dest for e in registry.entries(command)}
        for action in sub.choices[command]._actions:
            meta = action.metavar or ""
            if meta in ("NOMINAL", "MEASUREMENTS") or "." in meta and "..." not in meta:
                assert action.dest in known, (command, action.dest, meta)


# --------------------------------------------------------------------- the job file
def _job(tmp, **keys):
    data = {"command": "compensate", "nominal": "nominal.step", "measurements": "m.csv"}
    data.update(keys)
    with open(os.path.join(tmp, "job.json"), "w") as fh:
        json.dump(data, fh)


def _run_job(sandbox, **keys):
    """The job file of ``keys`` run in process as the freecadcmd macro runs it."""
    import contextlib
    import io

    from surfcomp.cli.jobfile import run_job_file

    out, err = io.StringIO(), io.StringIO()
    old = os.getcwd()
    os.chdir(sandbox)
    try:
        _job(sandbox, **keys)
        before = snapshot(sandbox)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = run_job_file("job.json")
    finally:
        os.chdir(old)
    from .harness import Result

    return before, Result(rc, out.getvalue(), err.getvalue())


#: a refusal of the job file's keys names the job file as given
JOB_ITSELF = "the job file"
JOB_OUTPUTS = [attr for attr, role, _label in JOB_FILES if role == "output"]
JOB_REFUSED = (
    # named as the job file's keys: "report would overwrite the input nominal ..."
    [({attr: s.format(x=x)}, s.format(x=x), "%s would overwrite the input %s" % (attr, label))
     for attr in JOB_OUTPUTS for x, label in (("nominal.step", "nominal"),
                                              ("m.csv", "measurements"),
                                              ("job.json", "job file"))
     for s in ("{x}", "./{x}", "v/../{x}", "vlink/../../{x}")]
    + [({attr: s.format(x="nominal.step")}, s.format(x="nominal.step"),
        "cannot be written: its folder")
       for attr in JOB_OUTPUTS for s in ("nope/../{x}", "afile/../{x}")]
    # the job file's value check comes first: an empty name is not a file name
    + [({attr: ""}, JOB_ITSELF, "job key '%s' is \"\" (expected a file name (a non-empty "
        "string))" % attr) for attr in JOB_OUTPUTS]
    + [({"command": c}, JOB_ITSELF, '"command": %s: a job file runs' % json.dumps(c))
       for c in ("bogus", "simulate", "gcode")]
    + [({"command": c}, JOB_ITSELF, "job key 'command' is %s (expected a non-empty string)"
        % json.dumps(c)) for c in ("", 5)]
    + [({"command": "inspect", k: v}, JOB_ITSELF, '"%s": does nothing for "command": '
        '"inspect"' % k) for k, v in (("output", "c.step"), ("points", "p.csv"),
                                      ("curves", "n.step"), ("face_only", True),
                                      ("refine", 2), ("lean", False))]
    + [({"colour": 3}, JOB_ITSELF, "unknown job file keys: colour")]
)


@pytest.mark.parametrize("keys, file, says", JOB_REFUSED,
                         ids=["%s" % (sorted(k.items()),) for k, _f, _s in JOB_REFUSED])
def test_job_file_refused(keys, file, says, tmp_path):
    sandbox = tmp_path / BOX
    sandbox.mkdir()
    INPUTS(str(sandbox))
    before, res = _run_job(str(sandbox), **keys)
    assert res.rc == 2, res.err
    if file == JOB_ITSELF:
        file = "job.json"
    elif file is not None:                      # joined to the job file's folder
        file = os.path.join(str(sandbox), file)
    text = check_message(res, file=file, says=(says,))
    assert "wrote" not in res.out, text
    check_tree(before, snapshot(sandbox))


def test_job_file_dotdot_after_a_link(tmp_path, cad_cache):
    sandbox = tmp_path / BOX
    sandbox.mkdir()
    INPUTS(str(sandbox))
    before, res = _run_job(str(sandbox), output="vlink/../nominal.step",
                           report="vlink/../job.json")
    assert res.rc == 0, res.err
    assert "wrote vlink/../nominal.step" in res.out.replace(str(sandbox) + "/", "")
    check_tree(before, snapshot(sandbox), writes=("v/nominal.step", "v/job.json"))


FREECADCMD = [
    ({"command": "bogus"}, 2, '"command": "bogus": a job file runs "compensate" or "inspect"'),
    ({"command": "simulate"}, 2, '"command": "simulate": a job file runs'),
    ({"command": "inspect", "output": "c.step"}, 2,
     '"output": does nothing for "command": "inspect"'),
    # a job file's messages name its keys, not the command line's flags
    ({"report": "job.json"}, 2, ": report would overwrite the input job file job.json"),
    ({"output": "nope/../nominal.step"}, 2, ": output cannot be written: its folder"),
    ({"output": "vlink/../nominal.step", "method": "raw"}, 0, "wrote "),
]


@pytest.mark.parametrize("keys, rc, says", FREECADCMD,
                         ids=["%s" % (sorted(k.items()),) for k, _r, _s in FREECADCMD])
def test_freecadcmd_job(keys, rc, says, tmp_path):
    """The same through ``freecadcmd macros/surfcomp_job.py`` itself."""
    import subprocess

    from .harness import ROOT, default_signals

    sandbox = tmp_path / BOX
    sandbox.mkdir()
    INPUTS(str(sandbox))
    _job(str(sandbox), **keys)
    before = snapshot(str(sandbox))
    proc = subprocess.run(["freecadcmd", os.path.join(ROOT, "macros", "surfcomp_job.py")],
                          cwd=str(sandbox), env=dict(os.environ, SURFCOMP_JOB="job.json"),
                          capture_output=True, text=True, timeout=300,
                          preexec_fn=default_signals)
    assert proc.returncode == rc, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert says in (proc.stdout if rc == 0 else proc.stderr), proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr
    check_tree(before, snapshot(str(sandbox)), writes=("v/nominal.step",) if rc == 0 else ())
