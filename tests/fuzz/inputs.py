# SPDX-License-Identifier: LGPL-2.1-or-later
"""The inputs of the bad-input cases: good files to start from and the ways to damage them.

A setup is a callable ``setup(sandbox)``; :func:`setup` chains the small steps below
(``put`` a file, ``copy`` one, make a symbolic or hard ``link``, a ``folder``).
"""

import io
import os
import re
import shutil
import tempfile
import zipfile

from .harness import EXAMPLE_CSV, EXAMPLE_STEP, QIF_DIR, ROOT, WAVE

HEADER = "id,x_nom,y_nom,z_nom,i,j,k,dev"


# --------------------------------------------------------------------------- set-up steps

def setup(*steps):
    """One set-up running ``steps`` in order."""
    def run(sandbox):
        for step in steps:
            step(sandbox)
    return run


def put(name, data):
    """Write ``data`` (str as UTF-8, bytes as is, or a callable returning either) to ``name``."""
    def step(sandbox):
        value = data() if callable(data) else data
        path = os.path.join(sandbox, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as fh:
            fh.write(value.encode("utf-8") if isinstance(value, str) else value)
    return step


def copy(name, src):
    def step(sandbox):
        path = os.path.join(sandbox, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        shutil.copyfile(src, path)
    return step


def link(name, target):
    """A symbolic link ``name`` -> ``target`` (relative to the link's folder)."""
    def step(sandbox):
        os.symlink(target, os.path.join(sandbox, name))
    return step


def hardlink(name, existing):
    def step(sandbox):
        os.link(os.path.join(sandbox, existing), os.path.join(sandbox, name))
    return step


def folder(name):
    def step(sandbox):
        os.makedirs(os.path.join(sandbox, name))
    return step


# --------------------------------------------------------------------------- measurements

def _example_rows():
    with open(EXAMPLE_CSV, encoding="utf-8") as fh:
        lines = [t for t in fh.read().splitlines() if t and not t.startswith("#")]
    assert lines[0] == HEADER
    return [t.split(",") for t in lines[1:]]


_ROWS = _example_rows()


def rows(step=3):
    """The example's 45 x 45 CMM grid, every ``step``-th node in both directions (15 x 15
    by default): lists of the fields of ``HEADER``. Row ``k`` is on line ``k + 2``."""
    return [list(r) for k, r in enumerate(_ROWS) if (k % 45) % step == 0
            and (k // 45) % step == 0]


def csv(table=None, header=HEADER, sep=",", end="\n"):
    """CSV text of ``table`` (default :func:`rows`)."""
    table = rows() if table is None else table
    return end.join([header] + [sep.join(r) for r in table]) + end


def csv_with(changes, header=HEADER, keep=None):
    """CSV of :func:`rows` with ``changes``: ``{(row, column name): text}``; ``keep`` a
    function choosing rows by index."""
    table = rows()
    names = HEADER.split(",")
    for (k, name), text in changes.items():
        table[k][names.index(name)] = text
    if keep is not None:
        table = [r for k, r in enumerate(table) if keep(k)]
    return csv(table, header)


def csv_all(name, text):
    """Every row's column ``name`` set to ``text``."""
    table = rows()
    col = HEADER.split(",").index(name)
    for r in table:
        r[col] = text
    return csv(table)


def line_of(row):
    """File line (1-based) of :func:`rows`' row ``row`` in :func:`csv`."""
    return row + 2


# --------------------------------------------------------------------------- CAD files

def step_text():
    with open(EXAMPLE_STEP, encoding="utf-8") as fh:
        return fh.read()


def step_without(entity):
    """The example STEP without the entity ``#N`` (all its lines)."""
    out, skip = [], False
    for line in step_text().split("\n"):
        if line.startswith("#%d =" % entity):
            skip = True
            continue
        if skip and (line.startswith("#") or line.startswith("ENDSEC")):
            skip = False
        if not skip:
            out.append(line)
    return "\n".join(out)


# --------------------------------------------------------------------------- FCStd

def rezip(document_xml=None, drop=(), extra=(), src=None):
    """:func:`document_bytes` (or the FCStd bytes ``src``) with ``Document.xml`` replaced
    (bytes, or a function of the old text), members ``drop`` left out and ``extra``
    (name, bytes) added."""
    buf = io.BytesIO()
    src = document_bytes() if src is None else src
    with zipfile.ZipFile(io.BytesIO(src)) as zin, \
            zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            if info.filename in drop:
                continue
            data = zin.read(info.filename)
            if info.filename == "Document.xml" and document_xml is not None:
                data = (document_xml(data.decode("utf-8")).encode("utf-8")
                        if callable(document_xml) else document_xml)
            zout.writestr(info.filename, data)
        for name, data in extra:
            zout.writestr(name, data)
    return buf.getvalue()


BILLION_LAUGHS = (
    '<?xml version="1.0"?>\n<!DOCTYPE Document [\n<!ENTITY a "lollollollollollol">\n'
    + "".join('<!ENTITY %s "%s">\n' % (chr(ord("a") + k + 1), ("&%s;" % chr(ord("a") + k)) * 10)
              for k in range(9))
    + ']>\n<Document SchemaVersion="4">&j;</Document>\n')


def declared_encoding(text, encoding):
    """XML ``text`` (str or bytes) whose declaration names ``encoding``."""
    if isinstance(text, bytes):
        return declared_encoding(text.decode("utf-8"), encoding).encode("utf-8")
    new, count = re.subn(r"encoding=(['\"])[^'\"]*\1", 'encoding="%s"' % encoding, text, count=1)
    assert count == 1
    return new


def proxy_module(text, module, cls="P"):
    """``Document.xml`` text whose Python proxy names ``module``.``cls``."""
    new, count = re.subn(r'module="surfcomp\.app\.proxies"', 'module="%s"' % module, text)
    assert count == 1, "no proxy of surfcomp.app.proxies in Document.xml"
    return re.sub(r'class="Proxy"', 'class="%s"' % cls, new)


_DOCUMENT = []


def document_bytes():
    """A small FreeCAD document (made once): ``Nominal``, a Part::Feature holding the example
    face, ``Mirror``, a feature using it, and ``Helper``, an App::FeaturePython with
    surfcomp's plain proxy, whose module name the hostile variants replace."""
    if not _DOCUMENT:
        from surfcomp.app import fcenv

        FreeCAD = fcenv.import_freecad()
        import Part

        from surfcomp.app.proxies import Proxy

        tmp = tempfile.mkdtemp(prefix="surfcomp-fuzz-doc-")
        path = os.path.join(tmp, "shop.FCStd")
        doc = FreeCAD.newDocument("FuzzShop")
        try:
            nominal = doc.addObject("Part::Feature", "Nominal")
            nominal.Shape = Part.read(EXAMPLE_STEP)
            # a user of the nominal (the document route refuses documents without one)
            doc.addObject("Part::Mirroring", "Mirror").Source = nominal
            Proxy(doc.addObject("App::FeaturePython", "Helper"))
            doc.recompute()
            doc.saveAs(path)
        finally:
            FreeCAD.closeDocument(doc.Name)
        with open(path, "rb") as fh:
            _DOCUMENT.append(fh.read())
        shutil.rmtree(tmp)
    return _DOCUMENT[0]


#: a module in the working directory that a hostile document names: importing it writes
#: the marker file
MARKER_MODULE = ("import os\nwith open(os.path.join(os.path.dirname(os.path.abspath(__file__)),"
                 " 'MARKER'), 'w') as fh:\n    fh.write('imported')\n\n\nclass P:\n    pass\n")


# --------------------------------------------------------------------------- G-code

def wave():
    with open(WAVE, "rb") as fh:
        return fh.read()


#: X scale 100 um/m and a Y straightness: some um over the programs
AXIS_CSV = "axis,position,ex,ey,ez\nX,0,0,0,0\nX,100,0.01,0.002,0\nY,0,0,0,0\nY,100,0,-0.01,0\n"
SMALL_PROGRAM = "G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F100\nG1 X10 Y5\nG2 X20 Y5 I5 J0\nG0 Z5\nM2\n"

__all__ = ["ROOT", "QIF_DIR"]
