# SPDX-License-Identifier: LGPL-2.1-or-later
"""Read a user's STEP/IGES/BREP file in a child process, so a damaged file cannot take ours down.

OpenCASCADE's STEP reader segfaults on some damaged files (a STEP with one entity line
removed is enough). Read in this process, that ends the command (or the user's FreeCAD
session, with its unsaved work) without a message. :func:`read_cad` runs the reader in a
child process that writes the shape as BREP (OCCT's own format, which it reads back
robustly); a crash of the child becomes a clear :class:`~surfcomp.errors.GeometryError`.

The child is, where that is safe, a fork of this process once FreeCAD and Part are imported
(:mod:`surfcomp.app.cadfork`): it has only the file to read, not a second start of Python
and FreeCAD. Elsewhere (inside the FreeCAD GUI, in a process with threads, without
``os.fork``) it is a fresh ``python3`` running this module as a script::

    python3 -m surfcomp.app.cadread IN.step OUT.brep

The direct program route needs only the face, as data: :func:`prefetch_face` forks before
this process imports FreeCAD or numpy, the child imports FreeCAD, reads the file, chooses
the face and sends its :class:`surfcomp.app.face_data.FaceData` (:func:`take_face`), while
this process imports the numerics; this process never imports FreeCAD. Where no fork may
be taken, nothing is started, and the caller loads the face itself.
"""

import os
import pickle
import shutil
import subprocess
import sys
import tempfile
import time

from ..errors import GeometryError, InputError
from ..io import forks
from . import cadfork

#: seconds the reader may take (a large assembly takes minutes; a hang must end);
#: ``SURFCOMP_CAD_TIMEOUT`` replaces it
TIMEOUT = 900.0
#: the largest ``SURFCOMP_CAD_TIMEOUT`` accepted, s (a week)
MAX_TIMEOUT = 7 * 24 * 3600.0


def timeout():
    """The reader's time limit: ``SURFCOMP_CAD_TIMEOUT`` seconds when set, else
    :data:`TIMEOUT`.

    Raises
    ------
    InputError
        The variable is not a number of seconds above 0 and at most :data:`MAX_TIMEOUT`.
    """
    text = os.environ.get("SURFCOMP_CAD_TIMEOUT")
    if text is None:
        return TIMEOUT
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value <= MAX_TIMEOUT:    # also NaN
        raise InputError("SURFCOMP_CAD_TIMEOUT=%r is not a time limit (expected seconds "
                         "above 0 and at most %d, e.g. 900)" % (text, MAX_TIMEOUT))
    return value
#: the files read in the child (the nominal's CAD formats)
CAD_EXTENSIONS = (".step", ".stp", ".iges", ".igs", ".brep", ".brp")
#: exit code of the child for a file OCCT refused without crashing
_REFUSED = 3


def _python():
    """The interpreter for the child: this one when it is a Python (CLI, freecadcmd under
    python3), else Debian's python3 (inside the FreeCAD GUI ``sys.executable`` is FreeCAD)."""
    exe = sys.executable or ""
    if os.path.basename(exe).startswith("python"):
        return exe
    return shutil.which("python3") or "/usr/bin/python3"


class _Reader:
    """The reader child of one file, started at once; :meth:`shape` waits for it. With
    ``face`` (a fork only, see :func:`prefetch_face`) the child sends the
    :class:`surfcomp.app.face_data.FaceData` of the face named ``face_name`` instead
    (:meth:`face`)."""

    def __init__(self, path, face=False, face_name=None):
        self.path = path
        self.face_name = face_name
        self.limit = timeout()
        self.started = time.monotonic()
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        self.tmp = tempfile.mkdtemp(prefix="surfcomp-read-")
        self.out = os.path.join(self.tmp, "face.pickle" if face else "shape.brep")
        # the reader gets an ASCII name linked to the file: OpenCASCADE takes file names
        # as UTF-8, and a name that is not (bytes of another encoding) cannot be passed
        src = os.path.join(self.tmp, "input" + os.path.splitext(path)[1].lower())
        try:
            os.symlink(os.path.abspath(path), src)
            if face:
                self.proc = cadfork.Forked(lambda: _read_face(src, self.out, face_name),
                                           self.tmp)
                return
            if cadfork.usable():
                self.proc = cadfork.Forked(lambda: _read_to_brep(src, self.out), self.tmp)
                return
            env = dict(os.environ, PYTHONPATH=os.pathsep.join(
                [root] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
            self.proc = subprocess.Popen([_python(), "-m", "surfcomp.app.cadread", src, self.out],
                                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                         stdin=subprocess.DEVNULL, text=True, env=env,
                                         cwd=self.tmp)
        except BaseException:
            shutil.rmtree(self.tmp, ignore_errors=True)
            raise

    def close(self):
        """Stop the child if it still runs and remove its folder."""
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.communicate()
        shutil.rmtree(self.tmp, ignore_errors=True)

    def _wait(self, label):
        """Wait for the child; refuse what it could not read (see :func:`read_cad`)."""
        path = self.path
        left = max(0.0, self.limit - (time.monotonic() - self.started))
        try:
            stderr = self.proc.communicate(timeout=left)[1]
        except subprocess.TimeoutExpired:
            raise GeometryError("could not read %s: OpenCASCADE took more than %d s (raise "
                                "SURFCOMP_CAD_TIMEOUT for very large files)"
                                % (label, self.limit), file=path) from None
        code = self.proc.returncode
        if code < 0 or code > 128:
            raise GeometryError("could not read %s: the file is damaged (OpenCASCADE "
                                "crashed while reading it)" % label, file=path)
        if code == _REFUSED:
            raise GeometryError(stderr.strip().splitlines()[-1], file=path)
        if code != 0 or not os.path.isfile(self.out):
            raise GeometryError("could not read %s: the reader failed (%s)"
                                % (label, (stderr.strip().splitlines() or ["?"])[-1]),
                                file=path)

    def shape(self, label):
        """The shape the child read (see :func:`read_cad`)."""
        import Part

        try:
            self._wait(label)
            shape = Part.Shape()
            shape.read(self.out)
        finally:
            self.close()
        if shape.isNull() or not shape.Faces:
            raise GeometryError("the file contains no faces", file=self.path)
        return shape

    def face(self, label):
        """The :class:`surfcomp.app.face_data.FaceData` the child sent (see
        :func:`take_face`)."""
        try:
            self._wait(label)
            with open(self.out, "rb") as fh:
                return pickle.load(fh)      # written by our own child, in our own folder
        finally:
            self.close()


#: readers started ahead by :func:`prefetch`, by the file's absolute path
_STARTED = {}


def prefetch(path):
    """Start reading the CAD file ``path`` now, in the child, so that the caller's own
    start (its imports, the measurement file) runs beside it; :func:`read_cad` of the same
    path takes the result. Anything not a readable CAD file is left to :func:`read_cad`
    (which then says what is wrong, in its turn); :func:`discard` stops what nobody took."""
    _start(_STARTED, path)


def _start(started, path, **kw):
    """A :class:`_Reader` of the CAD file ``path`` (``kw`` its arguments) kept in
    ``started`` by the file's absolute path; nothing for anything not a readable CAD
    file (left to :func:`read_cad`, which says what is wrong) or already started."""
    key = os.path.abspath(path)
    if key in started or not os.path.isfile(path) or \
            os.path.splitext(path)[1].lower() not in CAD_EXTENSIONS:
        return
    try:
        started[key] = _Reader(path, **kw)
    except (InputError, OSError):
        return


#: face readers started ahead by :func:`prefetch_face`, by the file's absolute path
_FACES = {}


def prefetch_face(path, face_name=None):
    """Start reading the face ``face_name`` (None: the only B-spline face) of the CAD file
    ``path`` now, in a fork of this process taken before FreeCAD is imported: the child
    imports FreeCAD and Part, reads the file and sends the face's
    :class:`surfcomp.app.face_data.FaceData` back (:func:`take_face`); this process need
    not import FreeCAD at all. Nothing is started where no fork may be taken
    (:func:`surfcomp.io.forks.may_fork`) or ``path`` is not a CAD file; :func:`discard`
    stops what nobody took."""
    if forks.may_fork():
        _start(_FACES, path, face=True, face_name=face_name)


def take_face(path, face_name=None, label="NOMINAL"):
    """The :class:`surfcomp.app.face_data.FaceData` of the face :func:`prefetch_face`
    started reading for ``path`` and ``face_name``, or None when none was started (then
    read the file with :func:`read_cad`).

    Raises
    ------
    GeometryError
        As :func:`read_cad`; or the face cannot be chosen or used (the messages of
        :func:`surfcomp.app.face_data.pick_face` and :func:`surfcomp.app.face_data.face_data`).
    """
    reader = _FACES.get(os.path.abspath(path))
    if reader is None or reader.face_name != face_name:
        return None
    del _FACES[os.path.abspath(path)]
    return reader.face(label)


def discard():
    """Stop the readers :func:`prefetch` and :func:`prefetch_face` started that nobody
    took."""
    for started in (_STARTED, _FACES):
        while started:
            started.popitem()[1].close()


def read_cad(path, label="NOMINAL"):
    """The shape in the CAD file ``path``, read by OCCT in a child process.

    Raises
    ------
    GeometryError
        The reader crashed, refused the file, timed out, or the file has no faces.
    """
    reader = _STARTED.pop(os.path.abspath(path), None) or _Reader(path)
    return reader.shape(label)


def _fatal_signals_kill():
    """Let a crash kill the child with its signal. FreeCAD installs a SIGSEGV handler that
    exits with code 1 and no message, which the parent could not tell from a reader error."""
    cadfork.default_signals(cadfork.FATAL_SIGNALS)


def _main(argv):
    src, dst = argv
    from . import fcenv

    fcenv.import_freecad()
    _fatal_signals_kill()
    return _read_to_brep(src, dst)


def _read_shape(src):
    """The shape OCCT reads from ``src``, or None when it refuses the file or finds no
    faces in it (the reason on stderr)."""
    import Part

    try:
        shape = Part.read(src)
    except (Part.OCCError, RuntimeError, ValueError) as exc:
        print("cannot read the CAD file: %s" % exc, file=sys.stderr)
        return None
    if shape.isNull() or not shape.Faces:
        print("the file contains no faces", file=sys.stderr)
        return None
    return shape


def _read_to_brep(src, dst):
    """The child's work: read ``src`` with OCCT, write it to ``dst`` as BREP; the exit code
    (0, or :data:`_REFUSED` with the reason on stderr)."""
    shape = _read_shape(src)
    if shape is None:
        return _REFUSED
    shape.exportBrep(dst)
    return 0


def _read_face(src, dst, face_name):
    """The face child's work (:func:`prefetch_face`): import FreeCAD, read ``src``, write
    the :class:`surfcomp.app.face_data.FaceData` of the face ``face_name`` to ``dst``; the
    exit code (0, or :data:`_REFUSED` with the reason on stderr)."""
    from . import fcenv

    fcenv.import_freecad()
    import Part  # noqa: F401  (imported before the signals are given back)

    cadfork.default_signals()       # FreeCAD's import installed its crash handler
    from .face_data import face_data, pick_face

    shape = _read_shape(src)
    if shape is None:
        return _REFUSED
    try:
        face, name = pick_face(shape, face_name)
        data = face_data(face, name, boundary=True)[0]
    except GeometryError as exc:
        print(exc.message, file=sys.stderr)
        return _REFUSED
    with open(dst, "wb") as fh:
        pickle.dump(data, fh, pickle.HIGHEST_PROTOCOL)
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
