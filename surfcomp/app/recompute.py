# SPDX-License-Identifier: LGPL-2.1-or-later
"""Recompute a document's CAM operations in a child process, so the GUI keeps painting.

A 3D Surface operation spends most of its time in single long C++ calls (the tessellation,
OpenCamLib's drop cutter), during which the GUI's event loop cannot run. So after Replace or
Restore the operations (and their dressups) are computed by a child process (FreeCAD's
``freecadcmd`` next to the GUI, or this Python importing FreeCAD as a library), on a copy of
the document saved for it (``doc.saveCopy``); the document itself is not touched while the
child runs:

- the GUI waits in its event loop (it repaints, and Esc kills the child at once: nothing in
  the document changed, so a cancel needs no recompute);
- the objects before the first operation (model clones) are recomputed in this process, as
  in the child; from the first operation on, every property the child's recompute changed
  (the operations' ``Path`` and depths, the dressups' results, the Stock's box, the Job's
  ``CycleTime``) is written onto the same object of the document, and those objects are
  marked recomputed. The document ends as a recompute in this process leaves it, with each
  operation computed once (in the child).

Paths go across as their commands' parameters in JSON (Python's float text is exact, where
FreeCAD's own file keeps 6 decimals); the other properties through FreeCAD's
``dumpPropertyContent``/``restorePropertyContent``.

The child runs :func:`_main` of this module (``python3 -m surfcomp.app.recompute COPY.FCStd
JOB.json OUTDIR``, or a two-line script under ``freecadcmd``).
"""

import base64
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile

from ..errors import ComputationError
from . import progress as recompute_order
from .cadread import _python

#: the child writes these into OUTDIR
STATUS, RESULT, LOG = "status.json", "result.json", "worker.log"


# --------------------------------------------------------------------------- both sides
def _write_json(path, data):
    """Write ``data`` so that a reader never sees half a file."""
    tmp = path + ".part"
    with open(tmp, "w", encoding="utf-8") as f:
        json.dump(data, f)
    os.replace(tmp, path)


def _content(obj, prop):
    """A property's saved content, comparable between two moments (the zip FreeCAD dumps
    carries a time stamp; its members do not)."""
    with zipfile.ZipFile(io.BytesIO(bytes(obj.dumpPropertyContent(prop)))) as z:
        return [(n, z.read(n)) for n in sorted(z.namelist())]


def _snapshot(doc):
    return {(o.Name, p): _content(o, p) for o in doc.Objects for p in o.PropertiesList
            if p not in ("Proxy", "ExpressionEngine")}


def _is_shape(obj, prop):
    return obj.getTypeIdOfProperty(prop) == "Part::PropertyPartShape"


def _encode(obj, prop):
    if prop == "Path" and obj.getTypeIdOfProperty(prop) == "Path::PropertyPath":
        return ["commands", [[c.Name, dict(c.Parameters)] for c in obj.Path.Commands]]
    return ["content", base64.b64encode(bytes(obj.dumpPropertyContent(prop))).decode("ascii")]


def _decode(obj, prop, kind, data):
    if kind == "commands":
        import Path

        obj.Path = Path.Path([Path.Command(name, params) for name, params in data])
    else:
        obj.restorePropertyContent(prop, base64.b64decode(data))


# --------------------------------------------------------------------------- the child
def _count_executions(obj, counts):
    """Count the operation's ``opExecute`` calls (FreeCAD's operations call it through
    the proxy at each recompute)."""
    proxy = getattr(obj, "Proxy", None)
    real = getattr(proxy, "opExecute", None)
    if real is None:
        return

    def counted(*args, **kwargs):
        counts[obj.Name] = counts.get(obj.Name, 0) + 1
        return real(*args, **kwargs)

    proxy.opExecute = counted


def _work(copy, job, outdir):
    t_start = time.perf_counter()
    from . import cam, documents, fcenv

    fcenv.import_freecad()
    cam.setup_workbench(require_ocl=False)
    cam.setup_ocl()
    t_open = time.perf_counter()
    doc, _refused, info = documents.open_document(copy)
    seconds = {"(set-up)": t_open - t_start, "(open)": time.perf_counter() - t_open}
    heavy = set(job["heavy"])
    lost = [p for p in documents.restore_failures(doc, info=info)
            if p.split(" ", 1)[0] in heavy]
    if lost:
        raise ComputationError("the copy's CAM objects did not restore: %s" % "; ".join(lost))
    todo = [doc.getObject(n) for n in job["todo"]]
    first = job["first"]
    counts, failed = {}, {}
    for o in todo:
        o.touch()
        if o.Name in heavy:
            _count_executions(o, counts)
    for k, o in enumerate(todo):
        if k == first:
            t0 = time.perf_counter()
            before = _snapshot(doc)
            seconds["(snapshot)"] = time.perf_counter() - t0
        _write_json(os.path.join(outdir, STATUS), {"done": k, "total": len(todo),
                                                   "current": o.Label})
        t0 = time.perf_counter()
        if not recompute_order.recompute_one(o):
            failed[o.Name] = recompute_order.state_text(o)
        seconds[o.Name] = time.perf_counter() - t0
    t0 = time.perf_counter()
    after = _snapshot(doc)
    seconds["(snapshot)"] += time.perf_counter() - t0
    rank = {o.Name: k for k, o in enumerate(todo)}
    # a shape of an object the child did not compute (the block, the model clone) changes
    # only by the tessellation the operation left on it: not written back
    ours = {o.Name for o in todo[first:]}
    changed = sorted((key for key, value in after.items() if before.get(key) != value and
                      (key[0] in ours or not _is_shape(doc.getObject(key[0]), key[1]))),
                     key=lambda key: rank.get(key[0], len(todo)))
    _write_json(os.path.join(outdir, RESULT), {
        "changes": [[name, prop] + _encode(doc.getObject(name), prop) for name, prop in changed],
        "executions": counts, "seconds": seconds, "failed": failed,
        "touched": [o.Name for o in doc.Objects if "Touched" in o.State]})


def _main(argv):
    copy, job_file, outdir = argv
    with open(job_file, encoding="utf-8") as f:
        job = json.load(f)
    try:
        _work(copy, job, outdir)
    except Exception as exc:  # any failure of the child is reported to the parent
        import traceback

        traceback.print_exc()
        _write_json(os.path.join(outdir, RESULT), {"error": "%s: %s"
                                                   % (type(exc).__name__, exc)})
        return 1
    return 0


# --------------------------------------------------------------------------- the parent
#: FreeCAD's document preferences, and their values while the child's copy is saved: shapes
#: as binary BREP (much faster to write than the text form), no compression and no
#: thumbnail
_FAST_SAVE = (("SaveBinaryBrep", "Bool", True), ("CompressionLevel", "Int", 0),
              ("SaveThumbnail", "Bool", False))


def _save_copy(doc, path):
    """``doc.saveCopy(path)``, fast: the copy lives for one recompute."""
    import FreeCAD

    prefs = FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Document")
    kept = []
    for name, kind, value in _FAST_SAVE:
        getter, setter = getattr(prefs, "Get" + kind), getattr(prefs, "Set" + kind)
        had = name in getattr(prefs, "Get%ss" % kind)()
        kept.append((name, kind, had, getter(name)))
        setter(name, value)
    try:
        doc.saveCopy(path)
    finally:
        for name, kind, had, value in kept:
            if had:
                getattr(prefs, "Set" + kind)(name, value)
            else:
                getattr(prefs, "Rem" + kind)(name)


def _child_command(root, args, tmp):
    """How to start the child: this Python (the command line, the tests) with ``-m``, or,
    inside the FreeCAD GUI (whose ``sys.executable`` is FreeCAD), FreeCAD's console program
    next to it running a small script: the same FreeCAD, Python and OpenCamLib."""
    exe = sys.executable or ""
    if os.path.basename(exe).startswith("python"):
        return [exe, "-m", "surfcomp.app.recompute"] + list(args)
    here = os.path.dirname(exe)
    names = ("freecadcmd", "FreeCADCmd", "freecadcmd.exe", "FreeCADCmd.exe")
    cmd = next((os.path.join(here, n) for n in names if os.path.isfile(os.path.join(here, n))),
               None) or shutil.which("freecadcmd") or shutil.which("FreeCADCmd")
    if cmd is None:
        return [_python(), "-m", "surfcomp.app.recompute"] + list(args)
    script = os.path.join(tmp, "child.py")
    with open(script, "w", encoding="utf-8") as f:
        f.write("import os, sys\nsys.path.insert(0, %r)\nfrom surfcomp.app.recompute import "
                "_main\nrc = _main(%r)\nsys.stdout.flush()\nsys.stderr.flush()\nos._exit(rc)\n"
                % (root, list(args)))
    return [cmd, script]


def _nothing():
    return None


class ChildRecompute:
    """The recompute of ``doc``'s pending objects, its operations in a child process.

    ``start()``, then ``poll()`` until it returns False (the caller's event loop runs in
    between), then ``finish()``; or ``cancel()`` at any time before ``finish``.

    Attributes
    ----------
    todo : list of document objects
        What needs a recompute, in dependency order.
    heavy : set of str
        Names of the CAM operations and dressups among them (computed by the child).
    executions : dict
        ``{operation name: opExecute calls in the child}`` after ``finish``.
    """

    def __init__(self, doc, todo=None):
        self.doc = doc
        self.todo = list(todo if todo is not None else recompute_order.pending(doc))
        self.heavy = {o.Name for o in self.todo if recompute_order.is_path_generator(o)}
        #: the objects from the first operation on are computed by the child (what they
        #: compute can depend on the operations' side effects, e.g. the Stock's size on the
        #: model's tessellation); the ones before, which the operations use, here
        self.first = next((k for k, o in enumerate(self.todo) if o.Name in self.heavy),
                          len(self.todo))
        self.proc = None
        self.tmp = None
        self.started = None
        self.executions = {}
        #: ``{object name or '(set-up)', '(open)', '(snapshot)': seconds in the child}``
        self.seconds = {}

    def needed(self):
        """Whether anything is left for a child (False: recompute in place, it is cheap)."""
        return bool(self.heavy)

    def start(self, between=None):
        """Save the copy and start the child; ``between()`` (the GUI's event processing)
        is called between the two."""
        import surfcomp

        between = between or _nothing
        self.tmp = tempfile.mkdtemp(prefix="surfcomp-recompute-")
        copy = os.path.join(self.tmp, "copy.FCStd")
        _save_copy(self.doc, copy)
        between()
        job = os.path.join(self.tmp, "job.json")
        _write_json(job, {"todo": [o.Name for o in self.todo], "heavy": sorted(self.heavy),
                          "first": self.first})
        root = os.path.dirname(os.path.dirname(os.path.abspath(surfcomp.__file__)))
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [root] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
        env.pop("PYTHONHOME", None)
        with open(os.path.join(self.tmp, LOG), "w") as log:
            self.proc = subprocess.Popen(_child_command(root, [copy, job, self.tmp], self.tmp),
                                         stdout=log, stderr=subprocess.STDOUT,
                                         stdin=subprocess.DEVNULL, env=env, cwd=self.tmp,
                                         start_new_session=True)
        self.started = time.monotonic()
        return self

    def poll(self):
        """True while the child runs."""
        return self.proc is not None and self.proc.poll() is None

    def status(self):
        """``(objects done, objects in all, label of the current one, seconds so far)``."""
        try:
            with open(os.path.join(self.tmp, STATUS), encoding="utf-8") as f:
                s = json.load(f)
        except (OSError, ValueError):
            s = {"done": 0, "total": len(self.todo), "current": ""}
        return s["done"], s["total"], s["current"], time.monotonic() - self.started

    def cancel(self):
        """Stop the child at once; the document is as it was before :meth:`start`."""
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self._cleanup()

    def _cleanup(self):
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.tmp = None

    def _result(self):
        self.proc.wait()
        path = os.path.join(self.tmp, RESULT)
        result = {}
        if os.path.isfile(path):
            with open(path, encoding="utf-8") as f:
                result = json.load(f)
        if self.proc.returncode != 0 or "changes" not in result:
            with open(os.path.join(self.tmp, LOG), encoding="utf-8", errors="replace") as f:
                tail = f.read()[-2000:]
            raise ComputationError("the recompute process failed (exit %s): %s\n%s"
                                   % (self.proc.returncode, result.get("error", "no result"),
                                      tail))
        return result

    def finish(self, between=None):
        """Put the child's results onto the document and recompute the rest in place;
        ``between()`` (the GUI's event processing) is called after each object recomputed
        and each property written.

        Returns the names of the objects recomputed (in place or by the child).

        Raises
        ------
        ComputationError
            The child failed (crashed, or the copy did not open); the document is as
            before :meth:`start`.
        """
        between = between or _nothing
        try:
            result = self._result()
        finally:
            self._cleanup()
        between()
        self.executions = result["executions"]
        self.seconds = result["seconds"]
        # the cheap objects the operations use (model clones) are recomputed here, as in the
        # child; the operations and everything after them get the child's results
        for o in self.todo[:self.first]:
            recompute_order.recompute_one(o)
            between()
        for name, prop, kind, data in result["changes"]:
            target = self.doc.getObject(name)
            if target is not None:
                _decode(target, prop, kind, data)
                between()
        for o in self.todo[self.first:]:
            if o.Name in result["failed"]:
                recompute_order.recompute_one(o)    # it fails here too, with its message
            else:
                o.purgeTouched()
        done = [o.Name for o in self.todo]
        # writing a result touches its object (the Job's CycleTime, a triangulated Stock);
        # what the child's recompute left untouched is untouched here too
        touched_there = set(result["touched"])
        for o in self.doc.Objects:
            if "Touched" in o.State and o.Name not in touched_there:
                o.purgeTouched()
        return done


def settle_after_undo(doc, touched_before):
    """After a cancelled recompute and the undo of the change that asked for it: every
    property is back at its value from before the change (the undo puts back also what was
    recomputed inside the step, e.g. a model clone's shape), so the objects the undo touched
    are marked recomputed again, without a recompute; those that were touched already before
    the change (``touched_before``) stay touched.

    Returns the names of the objects marked recomputed."""
    done = []
    for o in doc.Objects:
        if "Touched" in o.State and o.Name not in touched_before:
            o.purgeTouched()
            done.append(o.Name)
    return done


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
