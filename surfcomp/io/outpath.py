# SPDX-License-Identifier: LGPL-2.1-or-later
"""Where an output goes, resolved once, the way the kernel resolves it for ``open()``.

An output path is split into its folder and its name. The folder is resolved by the
kernel (``os.stat``), so ``missing/..``, ``file/..`` and ``link/..`` mean what they mean to
``open()``: the first two are errors, the last is the folder above the link's target. The
resolved path (the folder's real path plus the name; a name that is a symbolic link to a
regular file is followed to that file, as ``open()`` follows it) is both the identity
compared with every input and the place the staging file goes. ``-`` is standard output.
"""

import os
import stat

from ..errors import InputError

#: the output name that means standard output
STDOUT = "-"
#: folders of devices and kernel state: nothing is staged in or renamed into them
SPECIAL_FOLDERS = ("/dev", "/proc", "/sys")


class Destination:
    """An output resolved for writing.

    ``option``/``path``: what the user typed; ``real``: the resolved path (None for
    standard output); ``key``: the identity compared with inputs and other outputs."""

    def __init__(self, option, path, real, key):
        self.option, self.path, self.real, self.key = option, path, real, key

    @property
    def stdout(self):
        return self.real is None


def name_max(folder):
    """The longest file name (bytes) the file system of ``folder`` takes."""
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def _special(real):
    return any(real == f or real.startswith(f.rstrip("/") + "/") for f in SPECIAL_FOLDERS)


def _refuse(option, path, why):
    raise InputError(option + " " + why, file=path)     # a Note label stays one


def _unreachable(option, path, folder, why):
    _refuse(option, path, "cannot be written: its folder %s cannot be reached (%s; expected "
                          "an existing folder, as open() needs one: create it first)"
                          % (folder, why))


def _folder(option, path):
    """The real path of ``path``'s folder, resolved by the kernel as ``open()`` resolves it:
    a folder that does not exist (also ``nope/..``, ``file/..``) is an error."""
    folder = os.path.dirname(path) or "."
    try:
        st = os.stat(folder)
    except OSError as exc:
        _unreachable(option, path, folder, exc.strerror)
    if not stat.S_ISDIR(st.st_mode):
        _refuse(option, path, "cannot be written: %s is not a folder" % folder)
    real = os.path.realpath(folder)
    try:
        same = os.stat(real)
    except OSError:
        same = None
    if same is None or (same.st_dev, same.st_ino) != (st.st_dev, st.st_ino):
        _refuse(option, path, "cannot be written: the folder %s changed while it was resolved"
                              % folder)
    return real


def resolve(option, path):
    """The :class:`Destination` of output ``path`` given with ``option``; refuses (exit 2)
    an empty name, a folder, a missing or unreachable folder, a name longer than the file
    system takes, anything in /dev, /proc or /sys, and anything that is not a regular file.
    """
    path = os.fspath(path)
    if path == STDOUT:
        return Destination(option, path, None, ("stdout",))
    if not path:
        raise InputError(option + ": the file name is empty (expected a file name, or - "
                         "for standard output)")
    name = os.path.basename(path)
    if not name:
        _refuse(option, path, "ends with '/' (expected a file name, not a folder)")
    if name in (".", "..") or os.path.isdir(path):
        _refuse(option, path, "is a folder (expected a file name)")
    folder = _folder(option, path)
    real = os.path.join(folder, name)
    if _special(os.path.dirname(real)):
        _refuse(option, path, "is in %s, a folder of devices and kernel state: refusing to "
                              "write there (use - for standard output)"
                              % os.path.dirname(real))
    limit = name_max(folder)
    if len(os.fsencode(name)) > limit:
        _refuse(option, path, "has a name of %d bytes; the file system takes at most %d"
                              % (len(os.fsencode(name)), limit))
    if os.path.islink(real):
        real = _through_link(option, path, real)
    if not os.access(folder, os.W_OK | os.X_OK):
        _refuse(option, path, "cannot be written: no permission to write in %s" % folder)
    try:
        st = os.stat(real)
    except FileNotFoundError:
        return Destination(option, path, real, ("path", real))
    except OSError as exc:
        _refuse(option, path, "cannot be written: %s" % exc.strerror)
    if not stat.S_ISREG(st.st_mode):
        _refuse(option, path, "exists and is not a regular file (a device, pipe or folder); "
                              "refusing to replace it")
    return Destination(option, path, real, ("inode", st.st_dev, st.st_ino))


def _through_link(option, path, real):
    """A name that is a symbolic link: the regular file it leads to (written through the
    link, as ``open()`` would); a dangling link or one to anything else is refused."""
    target = os.path.realpath(real)
    if not os.path.isfile(target):
        _refuse(option, path, "exists and is not a regular file (a device, pipe or broken "
                              "link); refusing to replace it")
    if _special(os.path.dirname(target)):
        _refuse(option, path, "leads to %s, in a folder of devices and kernel state: refusing "
                              "to write there (use - for standard output)" % target)
    return target


def identity(path):
    """What makes an input the same file as an output: (device, inode) of an existing file,
    else its path resolved as for an output (or the text when even that fails)."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        pass
    else:
        return ("inode", st.st_dev, st.st_ino)
    try:
        folder = os.path.realpath(os.path.dirname(path) or ".", strict=True)
    except (OSError, ValueError):
        return ("text", os.path.abspath(path))
    return ("path", os.path.join(folder, os.path.basename(path)))


def shown(path):
    """An output's path as reports state it: absolute, ``-`` for standard output."""
    return path if path == STDOUT else os.path.abspath(path)
