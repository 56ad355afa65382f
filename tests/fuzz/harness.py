# SPDX-License-Identifier: LGPL-2.1-or-later
"""Run the command line on bad input and check what it leaves behind (issue 12).

Every case runs in its own folder, the sandbox, as the working directory, with its inputs
copied or written there, so that everything a run could touch is one tree:

- :func:`snapshot` records every entry under the sandbox: folders, files with their SHA-256,
  symbolic links with their target and the SHA-256 of the file they point to;
- :func:`run_cli` runs ``surfcomp.cli.main`` in this process (stdout and stderr captured, the
  working directory and the signal handlers it installs restored afterwards);
  :func:`run_subprocess` runs ``python3 -m surfcomp`` where a fresh interpreter is needed
  (signals, modules in the working directory, modules that print when first imported);
- :func:`check` asserts the exit code, the message form (``surfcomp: error: `` then the
  user's path and ``:line`` where a file is at fault, never a temporary name, never a
  traceback), that nothing was left behind and that every input is byte-identical.
"""

import contextlib
import hashlib
import io
import os
import re
import signal
import subprocess
import sys
import warnings
from dataclasses import dataclass

from tests.conftest import default_signals  # noqa: F401  (re-exported for the fuzz tests)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXAMPLE_STEP = os.path.join(ROOT, "examples", "nominal.step")
EXAMPLE_CSV = os.path.join(ROOT, "examples", "measurements.csv")
REALDATA = os.path.join(ROOT, "tests", "data", "real")
WAVE = os.path.join(REALDATA, "gcode", "CAMotics_GPL", "wave.gcode")
QIF_DIR = os.path.join(REALDATA, "measurement", "qif-community")

ERROR = "surfcomp: error: "
#: a staged output's temporary name: ``.NAME.<8 random characters>SUFFIX``
#: (:func:`surfcomp.io.atomic._mkstemp`) or the CAD reader's temporary folder
TEMPORARY = re.compile(r"(?:^|[\s/'\"(])\.[^\s/]+\.[A-Za-z0-9_]{8}(?:\.[A-Za-z]+)+\b"
                       r"|surfcomp-read-")
#: what ``import this`` prints first
ZEN = "Beautiful is better than ugly"


@dataclass
class Result:
    rc: int
    out: str
    err: str
    #: numeric warnings (RuntimeWarning) raised in the run: a real run prints them on stderr
    numeric_warnings: tuple = ()


@dataclass
class Case:
    """One bad (or borderline) command line.

    ``argv`` names files relative to the sandbox; ``setup(sandbox)`` writes the inputs.
    A refused case (``rc`` 2) names ``file`` (the user's path, as typed) and ``line`` at
    the start of its message and contains every string of ``says``; a case that succeeds
    (``rc`` 0) writes exactly ``writes`` and nothing else.
    """

    name: str
    argv: tuple
    setup: object = None
    rc: int = 2
    says: tuple = ()
    file: str = None
    line: int = None
    writes: tuple = ()
    usage: bool = False        # refused by argparse itself (its own message form)
    real_cad: bool = False     # read the example nominal through the CAD child every time

    def __str__(self):
        return self.name


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def snapshot(root):
    """Every entry under ``root``: relative path -> what it is.

    ``("dir",)``, ``("file", sha256)`` or ``("link", target, sha256 of the file it points to
    or None)``; links are recorded, not followed into.
    """
    entries = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, root)
            if os.path.islink(path):
                target = os.readlink(path)
                entries[rel] = ("link", target,
                                sha256(path) if os.path.isfile(path) else None)
            elif os.path.isdir(path):
                entries[rel] = ("dir",)
            elif not os.path.isfile(path):      # a FIFO or socket: never opened
                entries[rel] = ("special",)
            else:
                entries[rel] = ("file", sha256(path))
    return entries


@contextlib.contextmanager
def _restored_process_state(cwd):
    """chdir to ``cwd``; restore the working directory, the signal handlers the CLI
    installs (SIGTERM, SIGHUP) and FreeCAD's open documents check afterwards."""
    old = os.getcwd()
    saved = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP)}
    os.chdir(cwd)
    try:
        yield
    finally:
        os.chdir(old)
        for s, handler in saved.items():
            signal.signal(s, handler)


def _documents():
    fc = sys.modules.get("FreeCAD")
    return set(fc.listDocuments()) if fc is not None else set()


def run_cli(argv, cwd):
    """``surfcomp.cli.main(argv)`` in this process inside ``cwd``; returns a :class:`Result`.

    A FreeCAD document the run leaves open is a failure (it would hold the file)."""
    from surfcomp.cli import main

    out, err = io.StringIO(), io.StringIO()
    docs = _documents()
    with _restored_process_state(cwd), contextlib.redirect_stdout(out), \
            contextlib.redirect_stderr(err), warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always", RuntimeWarning)
        try:
            rc = main([str(a) for a in argv])
        except SystemExit as exc:           # argparse refuses with its usage message
            rc = exc.code
    left = _documents() - docs
    assert not left, "documents left open: %s" % sorted(left)
    numeric = tuple("%s:%s: %s" % (w.filename, w.lineno, w.message) for w in seen
                    if issubclass(w.category, RuntimeWarning))
    return Result(rc, out.getvalue(), err.getvalue(), numeric)


def subprocess_env(extra=None):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [ROOT] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    env.update(extra or {})
    return env


def run_subprocess(argv, cwd, timeout=300):
    """``python3 -m surfcomp argv`` with ``cwd`` as working directory (so that it is on
    ``sys.path``, as for a user), surfcomp found through PYTHONPATH."""
    proc = subprocess.run([sys.executable, "-m", "surfcomp"] + [str(a) for a in argv], cwd=cwd,
                          env=subprocess_env(), capture_output=True, text=True, timeout=timeout,
                          preexec_fn=default_signals)
    return Result(proc.returncode, proc.stdout, proc.stderr)


def error_line(res):
    """The one ``surfcomp: error: `` line of stderr (without the prefix)."""
    lines = [t for t in res.err.splitlines() if t.startswith(ERROR)]
    assert len(lines) == 1, "expected one '%s' line in stderr:\n%s" % (ERROR, res.err)
    return lines[0][len(ERROR):]


def check_message(res, file=None, line=None, says=(), usage=False):
    """The message form of a refused run (exit 2)."""
    assert "Traceback" not in res.err and "Warning" not in res.err, res.err
    assert not TEMPORARY.search(res.err), "a temporary name in the message:\n" + res.err
    assert ZEN not in res.out + res.err
    if usage:
        assert ": error: " in res.err and "usage:" in res.err, res.err
        text = res.err
    else:
        text = error_line(res)
        if file is not None:
            where = str(file) + ("" if line is None else ":%d" % line)
            assert text.startswith(where + ":"), "expected %r first in %r" % (where, text)
    for s in says:
        assert s in text, "%r not in %r" % (s, text)
    assert len(res.err) < 4000, "an error message of %d characters" % len(res.err)
    return text


def check_tree(before, after, writes=()):
    """``after`` is ``before`` plus exactly the files ``writes`` (and the folders holding
    them); every input is byte-identical, links unchanged."""
    changed = {k: (before[k], after.get(k)) for k in before if after.get(k) != before[k]}
    assert not changed, "inputs changed or removed: %s" % changed
    new = set(after) - set(before)
    expected = set()
    for w in writes:
        w = os.path.normpath(w)
        expected.add(w)
        parent = os.path.dirname(w)
        while parent:
            if parent not in before:
                expected.add(parent)
            parent = os.path.dirname(parent)
    assert new == expected, "left behind: %s; missing: %s" % (sorted(new - expected),
                                                              sorted(expected - new))
    for w in writes:
        assert after[os.path.normpath(w)][0] == "file", w


def run_case(case, sandbox, runner=run_cli):
    """Set up ``case`` in ``sandbox``, run it, check it; returns the :class:`Result`."""
    os.makedirs(sandbox, exist_ok=True)
    if case.setup is not None:
        case.setup(str(sandbox))
    before = snapshot(sandbox)
    res = runner(case.argv, str(sandbox))
    after = snapshot(sandbox)
    assert res.rc == case.rc, "exit %r, expected %r\nstdout:\n%s\nstderr:\n%s" % (
        res.rc, case.rc, res.out[-3000:], res.err[-3000:])
    assert not res.numeric_warnings, "numeric warnings on stderr: %s" % (res.numeric_warnings,)
    if case.rc == 0:
        assert "Traceback" not in res.err and "RuntimeWarning" not in res.err, res.err
        assert ZEN not in res.out + res.err
        assert not TEMPORARY.search(res.out + res.err), res.out + res.err
        check_tree(before, after, case.writes)
    else:
        check_message(res, case.file, case.line, case.says, case.usage)
        check_tree(before, after)
    return res


def run_either(argv, setup, sandbox, writes=(), file=None):
    """For inputs that may be good or bad: exit 0 writing exactly ``writes``, or exit 2 with
    a message (naming ``file`` when given) and nothing written; the inputs unchanged, no
    traceback, no numeric warning either way. Returns the :class:`Result`."""
    os.makedirs(sandbox, exist_ok=True)
    setup(str(sandbox))
    before = snapshot(sandbox)
    res = run_cli(argv, str(sandbox))
    after = snapshot(sandbox)
    assert res.rc in (0, 2), "exit %r\n%s" % (res.rc, res.err[-3000:])
    assert not res.numeric_warnings, res.numeric_warnings
    if res.rc == 0:
        assert "Traceback" not in res.err, res.err
        check_tree(before, after, writes)
    else:
        check_message(res, file=file)
        check_tree(before, after)
    return res

