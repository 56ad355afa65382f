# SPDX-License-Identifier: LGPL-2.1-or-later
"""Key press to repaint, measured inside the FreeCAD GUI (imported by GUI sessions and by
bench/bench_filter_panel.py; needs FreeCADGui, pivy and an X server).

Keys are real X input: XTest (``libXtst``, through ctypes) presses them at the X server,
which sends them to the window with the input focus, as a keyboard does; Qt then delivers
them to its focus widget. A key pressed while FreeCAD is busy waits in the X queue as a
user's would, and the time runs from the press.

The repaint is seen by a Coin callback node at the end of the 3D view's scene graph: each
time the view is rendered it records the time and a sample of the map's vertex colours.
The latency of a change is the time from the (last) key press to the first render whose
colours are the final ones.
"""

import ctypes
import ctypes.util
import threading
import time

#: X keysyms of the keys the sessions press
KEYSYMS = {"Up": 0xFF52, "Down": 0xFF54, "BackSpace": 0xFF08, "End": 0xFF57, " ": 0x20,
           ";": 0x3B, ".": 0x2E, "-": 0x2D}
KEYSYMS.update({str(d): 0x30 + d for d in range(10)})


class XKeys:
    """Real key presses through the XTest extension (its own X connection)."""

    def __init__(self):
        self.x11 = ctypes.CDLL(ctypes.util.find_library("X11") or "libX11.so.6")
        self.xtst = ctypes.CDLL(ctypes.util.find_library("Xtst") or "libXtst.so.6")
        self.x11.XOpenDisplay.restype = ctypes.c_void_p
        self.x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
        self.x11.XKeysymToKeycode.restype = ctypes.c_ubyte
        self.x11.XKeysymToKeycode.argtypes = [ctypes.c_void_p, ctypes.c_ulong]
        self.x11.XFlush.argtypes = [ctypes.c_void_p]
        self.x11.XSync.argtypes = [ctypes.c_void_p, ctypes.c_int]
        self.x11.XSetInputFocus.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_int,
                                            ctypes.c_ulong]
        self.x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
        self.xtst.XTestFakeKeyEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int,
                                                ctypes.c_ulong]
        self.display = self.x11.XOpenDisplay(None)
        if not self.display:
            raise RuntimeError("no X display for XTest")
        self.lock = threading.Lock()

    def focus(self, win_id):
        """Give the X input focus to a top-level window (no window manager under Xvfb)."""
        with self.lock:
            self.x11.XSetInputFocus(self.display, int(win_id), 2, 0)   # RevertToParent
            self.x11.XSync(self.display, 0)

    def press(self, key):
        """Press and release ``key`` (a :data:`KEYSYMS` name); returns the time
        (``time.perf_counter``) at which the press left for the X server."""
        code = self.x11.XKeysymToKeycode(self.display, KEYSYMS[key])
        with self.lock:
            t = time.perf_counter()
            self.xtst.XTestFakeKeyEvent(self.display, code, 1, 0)
            self.xtst.XTestFakeKeyEvent(self.display, code, 0, 0)
            self.x11.XFlush(self.display)
        return t

    def type_in_thread(self, keys, interval):
        """Press ``keys`` one by one, ``interval`` seconds apart, from a thread (while the
        caller keeps the event loop running); returns ``(thread, times)``, the press times
        filled in as they happen as ``(time.perf_counter(), time.process_time())``."""
        times = []

        def run():
            for k, key in enumerate(keys):
                if k:
                    time.sleep(interval)
                times.append((self.press(key), time.process_time()))

        th = threading.Thread(target=run, daemon=True)
        th.start()
        return th, times

    def close(self):
        self.x11.XCloseDisplay(self.display)


class RenderProbe:
    """A Coin callback at the end of a view's scene graph recording ``(time, colours)``
    of each render; ``colours`` samples ``field`` (an ``SoMFColor``) at ``every``-th value."""

    def __init__(self, view, field, samples=24):
        from pivy import coin

        self.coin = coin
        self.field = field
        self.samples = samples
        self.renders = []
        self.node = coin.SoCallback()
        self.node.setCallback(self._called)
        self.root = view.getSceneGraph()
        self.root.addChild(self.node)

    def sample(self):
        n = self.field.getNum()
        step = max(1, n // self.samples)
        return tuple(tuple(round(float(c), 6) for c in self.field[i].getValue())
                     for i in range(0, n, step))

    def _called(self, _data, action):
        if action.isOfType(self.coin.SoGLRenderAction.getClassTypeId()):
            self.renders.append((time.perf_counter(), self.sample(), time.process_time()))

    def first_render_with(self, colours, after):
        """``(time, process CPU time)`` of the first render after ``after`` that showed
        ``colours``, or None."""
        for t, c, cpu in self.renders:
            if t >= after and c == colours:
                return t, cpu
        return None

    def remove(self):
        self.root.removeChild(self.node)


class KeyWatch:
    """Counts the key releases that reach the application (an application event filter),
    so a wait can tell a key still in the X queue from one already handled."""

    def __init__(self, app):
        from PySide import QtCore

        watch = self

        class _Filter(QtCore.QObject):
            def eventFilter(self, _obj, event):
                if event.type() == QtCore.QEvent.KeyRelease and event.spontaneous():
                    watch.released.append(time.perf_counter())
                return False

        self.released = []
        self.app = app
        self.filter = _Filter()
        app.installEventFilter(self.filter)

    def remove(self):
        self.app.removeEventFilter(self.filter)


def wait_quiet(app, busy, probe, watch=None, keys=0, quiet=0.4, limit=10.0, shown=False):
    """Run the event loop until ``watch`` has seen ``keys`` key releases, ``busy()`` is
    false, (with ``shown``) the last render showed the map's colours as they are, and
    ``probe`` saw no render for ``quiet`` seconds (at most ``limit`` seconds); returns True
    when it got there, False at the limit."""
    t0 = time.perf_counter()
    last = t0
    while time.perf_counter() - t0 < limit:
        app.processEvents()
        now = time.perf_counter()
        if busy() or (watch is not None and len(watch.released) < keys) or \
                (shown and not (probe.renders and probe.renders[-1][1] == probe.sample())):
            last = now
        elif probe.renders:
            last = max(last, probe.renders[-1][0])
        if now - last >= quiet:
            return True
        time.sleep(0.002)
    return False


#: seconds without a render after which a key's work counts as done, once the panel is
#: idle, every key handled and a render has shown the map's colours as they are (a render
#: follows the map's update within milliseconds; the quiet time is for a late second one)
QUIET = 0.25


def press_latencies(app, keys, probe, watch, busy, presses, quiet=QUIET):
    """Press each key of ``presses`` in turn, the GUI quiet before each (waited for before
    the first, and before any after a press whose wait ran out); returns one dict per
    press: ``key``, ``seconds`` (press to the first render of the final colours; None when
    that render never came), ``cpu`` (FreeCAD's CPU seconds over that time, all its
    threads), ``changed`` (the colours differ from those before the press)."""
    out = []
    settled = False
    for key in presses:
        if not settled:
            wait_quiet(app, busy, probe, watch, len(watch.released), quiet=0.3)
        before = probe.sample()
        n = len(watch.released)
        cpu0 = time.process_time()
        t = keys.press(key)
        settled = wait_quiet(app, busy, probe, watch, n + 1, quiet=quiet, shown=True)
        out.append(_result(key, probe, before, t, cpu0))
    return out


def typing_latency(app, keys, probe, watch, busy, text, interval, quiet=QUIET):
    """Type ``text`` (:data:`KEYSYMS` characters) ``interval`` seconds a key, from a thread
    while the event loop runs; the figures of :func:`press_latencies` from the last key."""
    wait_quiet(app, busy, probe, watch, len(watch.released), quiet=0.3)
    before = probe.sample()
    n = len(watch.released)
    thread, times = keys.type_in_thread(list(text), interval)
    while thread.is_alive():
        app.processEvents()
        time.sleep(0.001)
    wait_quiet(app, busy, probe, watch, n + len(text), quiet=quiet, shown=True)
    return _result(text, probe, before, *times[-1])


def _result(key, probe, before, pressed, cpu0):
    final = probe.sample()
    seen = probe.first_render_with(final, pressed)
    return {"key": key, "seconds": None if seen is None else seen[0] - pressed,
            "cpu": None if seen is None else seen[1] - cpu0, "changed": final != before}


class PanelKeys:
    """Real keys for an open filter panel: the X focus on the main window, the mask's spin
    box focused, the render probe on the map's colours and the key watch installed."""

    def __init__(self, app, main_window, panel, view, scene):
        self.app, self.panel = app, panel
        self.keys = XKeys()
        main_window.activateWindow()
        self.keys.focus(main_window.winId())
        self.focus(panel.mask)
        self.probe = RenderProbe(view, scene.surface_colors.rgb)
        self.watch = KeyWatch(app)

    def focus(self, widget, limit=3.0):
        """Focus ``widget`` and wait until Qt reports it focused (a task panel just opened
        may still be on its way to the screen); True when it is."""
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < limit:
            widget.setFocus()
            for _ in range(5):
                self.app.processEvents()
                time.sleep(0.01)
            if self.app.focusWidget() is widget:
                return True
        return False

    def busy(self):
        return self.panel.timer.isActive() or getattr(self.panel, "_busy", False)

    def presses(self, keys):
        return press_latencies(self.app, self.keys, self.probe, self.watch, self.busy, keys)

    def typing(self, text, interval=0.08):
        """Type ``text`` into the weights field (see :func:`typing_latency`)."""
        self.focus(self.panel.weights)
        return typing_latency(self.app, self.keys, self.probe, self.watch, self.busy, text,
                              interval)

    def close(self):
        self.probe.remove()
        self.watch.remove()
        self.keys.close()
