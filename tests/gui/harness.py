# SPDX-License-Identifier: LGPL-2.1-or-later
"""Run a script inside the real FreeCAD GUI (``freecad script.py``) and collect its results.

Each run gets its own FreeCAD user home (``FREECAD_USER_HOME``): a fresh user.cfg (whose one
setting turns the splash screen off), its own Qt settings (``XDG_CONFIG_HOME``: the main
window's layout), and a ``Mod`` folder that holds only what the test puts
there (a link to this checkout, or an Addon-Manager-like clone). The script writes a JSON
report to ``$SURFCOMP_GUI_OUT``; the report view's text and the process output come back
too, for the "no traceback" checks. Without a DISPLAY, or in a worker of a parallel run,
the run is wrapped in ``xvfb-run`` (its own X server).
"""

import json
import os
import shutil
import subprocess

from tests.conftest import ROOT

FREECAD = shutil.which("freecad") or "/usr/bin/freecad"
SCREEN = "1600x1200x24"

#: prologue/epilogue wrapped around every GUI script: results dict, report view text,
#: clean shut-down (documents closed without asking, then the main window)
PROLOGUE = r'''
import json, os, sys, traceback
import FreeCAD, FreeCADGui
from PySide import QtGui, QtCore
RESULTS = {"errors": []}
OUT = os.environ["SURFCOMP_GUI_OUT"]

def report_view_text():
    mw = FreeCADGui.getMainWindow()
    for w in mw.findChildren(QtGui.QTextEdit):
        if w.objectName() == "Report view" or type(w).__name__ == "ReportOutput":
            return w.toPlainText()
    texts = [w.toPlainText() for w in mw.findChildren(QtGui.QTextEdit)]
    return "\n".join(texts)

def _finish():
    RESULTS["report_view"] = report_view_text()
    with open(OUT, "w") as f:
        json.dump(RESULTS, f, indent=1, default=str)
    for name in list(FreeCAD.listDocuments()):
        FreeCAD.closeDocument(name)
    FreeCADGui.getMainWindow().close()
    QtGui.QApplication.instance().quit()

try:
'''

EPILOGUE = r'''
except BaseException:
    RESULTS["errors"].append(traceback.format_exc())
_finish()
'''


#: a new user's settings but for the splash screen: with it FreeCAD runs the script only
#: after the splash has waited for the main window to be exposed, which under Xvfb (no
#: window manager) costs some 3 s a start; nothing of surfcomp shows on it
USER_CFG = """<?xml version="1.0" encoding="UTF-8" standalone="no" ?>
<FCParameters>
  <FCParamGroup Name="Root">
    <FCParamGroup Name="BaseApp">
      <FCParamGroup Name="Preferences">
        <FCParamGroup Name="General">
          <FCBool Name="ShowSplasher" Value="0"/>
        </FCParamGroup>
      </FCParamGroup>
    </FCParamGroup>
  </FCParamGroup>
</FCParameters>
"""


def make_home(tmp_path, link_checkout=True):
    """A FreeCAD user home under ``tmp_path`` (:data:`USER_CFG` its settings); with
    ``link_checkout`` its Mod folder links this checkout (as tools/install.sh does for the
    real user)."""
    home = tmp_path / "fchome"
    (home / "Mod").mkdir(parents=True, exist_ok=True)
    if not (home / "user.cfg").exists():
        (home / "user.cfg").write_text(USER_CFG)
    if link_checkout:
        os.symlink(ROOT, home / "Mod" / "surfcomp")
    return home


def first_server(worker):
    """Where ``xvfb-run -a`` starts looking for a free X server number: in a parallel run
    each worker's sessions get their own X server (a session sharing one with another
    would see its windows and input), searched from 5, 10 ... above ``SURFCOMP_XVFB_FROM``
    (tools/test.sh), so that two workers do not race for one and the version matrix's roots
    (20 numbers apart, tools/matrix.sh) keep to their ranges."""
    base = int(os.environ.get("SURFCOMP_XVFB_FROM", "99"))
    if not worker:
        return base
    return base + 5 * (1 + int("".join(c for c in worker if c.isdigit()) or 0))


def run_gui(body, tmp_path, home=None, timeout=240, env=None):
    """Run ``body`` (Python code, indented by the caller's ``textwrap`` as top level) in
    the FreeCAD GUI; return ``(results, output)``.

    ``body`` sees ``RESULTS`` (a dict written to JSON at the end), ``FreeCAD``,
    ``FreeCADGui``, ``QtGui``, ``QtCore``. Any exception lands in ``RESULTS['errors']``.
    """
    home = home or make_home(tmp_path)
    script = tmp_path / "gui_script.py"
    indented = "\n".join(("    " + line) if line.strip() else line for line in body.splitlines())
    script.write_text(PROLOGUE + indented + "\n    pass\n" + EPILOGUE)
    out = tmp_path / "gui_results.json"
    e = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    # Qt's settings (FreeCAD keeps its main window's toolbar layout and size there, in
    # $XDG_CONFIG_HOME/FreeCAD/FreeCAD.conf, not in the user home) belong to the session's
    # home too: a layout an earlier session on this machine left (a toolbar moved off the
    # window) hid a toolbar button from later sessions
    e.update({"FREECAD_USER_HOME": str(home), "XDG_CONFIG_HOME": str(home / "xdg-config"),
              "SURFCOMP_GUI_OUT": str(out),
              "SURFCOMP_ROOT": ROOT, "SURFCOMP_TMP": str(tmp_path),
              "QTWEBENGINE_CHROMIUM_FLAGS": e.get("QTWEBENGINE_CHROMIUM_FLAGS", "--no-sandbox")})
    e.update(env or {})
    cmd = [FREECAD, str(script)]
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if not e.get("DISPLAY") or worker:
        cmd = ["xvfb-run", "-a", "-n", str(first_server(worker)), "-s",
               "-screen 0 " + SCREEN] + cmd
    proc = subprocess.run(cmd, env=e, cwd=str(tmp_path), capture_output=True, text=True,
                          timeout=timeout)
    output = proc.stdout + proc.stderr
    if not out.exists():
        raise AssertionError("the GUI script wrote no results (exit %d):\n%s"
                             % (proc.returncode, output[-4000:]))
    with open(out) as f:
        results = json.load(f)
    return results, output


def build_document(tmp, make, shop, csv):
    """Run the script text ``make`` in ``freecadcmd`` (in ``tmp``), with SURFCOMP_ROOT,
    SURFCOMP_DOC=``shop`` and SURFCOMP_CSV=``csv`` set: how the GUI tests build their
    documents headless, so the session opens them from disk."""
    env = dict(os.environ, SURFCOMP_ROOT=ROOT, SURFCOMP_DOC=shop, SURFCOMP_CSV=csv)
    script = tmp / "make.py"
    script.write_text(make)
    return subprocess.run(["freecadcmd", str(script)], env=env, capture_output=True,
                          text=True, timeout=300, cwd=str(tmp))


def read_image(path):
    """An RGB image as floats in [0, 1], shape (H, W, 3)."""
    import matplotlib.image as mpimg

    img = mpimg.imread(str(path))
    if img.dtype.kind in "ui":
        img = img / 255.0
    return img[..., :3]


def with_common(body):
    """``body`` after the shared prologue ``gui_common.py`` (dialog recorders,
    ``load_example``, ``make_map``, ...), for :func:`run_gui`."""
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "gui_common.py"), encoding="utf-8") as f:
        return f.read() + "\n" + body


def run_session(name, tmp_path, home=None, timeout=300, env=None):
    """Run ``tests/gui/session_<name>.py`` after the shared prologue ``gui_common.py``
    (``env``: more environment variables); return the results dict with the process output
    under ``'output'``."""
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "session_%s.py" % name), encoding="utf-8") as f:
        body = f.read()
    results, output = run_gui(with_common(body), tmp_path, home=home, timeout=timeout,
                              env=env)
    results["output"] = output
    return results
