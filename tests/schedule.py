# SPDX-License-Identifier: LGPL-2.1-or-later
"""Work units and their order for a parallel run (``pytest -n 2 --dist loadgroup``).

pytest-xdist's ``loadgroup`` hands a worker one unit at a time, in the order the units
first appear in the collection: a test of its own, or every test of one ``xdist_group``.
Two rules keep both workers busy to the end:

- **small units**: a test that uses a module-scoped fixture (a shop document, a FreeCAD
  GUI session, a simulated part) runs on the worker that built it,
  together with every other test of its module sharing one of its module fixtures (so each
  fixture is still built once, and tests that hand results on through a fixture keep their
  order); a session-scoped fixture ties its tests of every module into one unit; a test
  without such a fixture is a unit of its own. In a parallel run each
  worker's GUI sessions have their own X server (tests/gui/harness.py); the sessions that
  measure the GUI's response time (marked ``latency``) run after the parallel part, alone
  on the machine (tools/test.sh).
- **longest first**: units are ordered by their expected time, from
  ``tests/durations.json`` (seconds per test of the last recorded run, the tests that took
  at least :data:`RECORD_FROM`), a new test counting :data:`DEFAULT` of its folder. A long
  unit handed out last would leave one core idle while the other finishes it.

``SURFCOMP_RECORD_DURATIONS=1`` rewrites ``tests/durations.json`` from a run's tests (the
entries of tests that did not run are kept).
"""

import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
DURATIONS = os.path.join(HERE, "durations.json")
#: expected seconds of a test not in ``durations.json``, by its folder under tests/
DEFAULT = {"app": 1.5, "gui": 2.0}
#: expected seconds of a test of any other folder not in ``durations.json``
DEFAULT_OTHER = 0.1
#: the shortest test (s) that ``SURFCOMP_RECORD_DURATIONS`` records
RECORD_FROM = 0.5
#: the fixture scopes that tie the tests using them to one worker
SHARED_SCOPES = ("module", "package", "session", "class")


def _folder(nodeid):
    parts = nodeid.split("/")
    return parts[1] if len(parts) > 2 and parts[0] == "tests" else ""


def _shared_fixtures(item):
    """Names of the module- (or wider) scoped fixtures that this checkout's tests define and
    ``item`` uses, directly or through another fixture, each with its scope."""
    info = getattr(item, "_fixtureinfo", None)
    names = []
    for name, defs in (info.name2fixturedefs.items() if info else ()):
        fixture = defs[-1]
        if fixture.scope in SHARED_SCOPES and getattr(fixture, "baseid", ""):
            names.append((name, fixture.scope))
    return sorted(names)


def _fixture_groups(items):
    """``{nodeid: group}`` for the tests that share a module fixture: per module,
    the tests connected through the module fixtures they use form one group; a
    session-scoped fixture joins its tests of every module (it is built once a worker)."""
    parent = {}

    def find(key):
        while parent.setdefault(key, key) != key:
            parent[key] = parent[parent[key]]
            key = parent[key]
        return key

    members = {}
    for item in items:
        module = item.nodeid.split("::")[0]
        keys = [name if scope == "session" else module + "::" + name
                for name, scope in _shared_fixtures(item)]
        if keys:
            members[item.nodeid] = keys[0]
            for key in keys[1:]:
                parent[find(key)] = find(keys[0])
    return {nodeid: find(key) for nodeid, key in members.items()}


def load_durations(path=DURATIONS):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def assign(items, parallel, durations=None):
    """Mark the work units (``xdist_group``) and, when ``parallel``, order ``items`` in
    place longest unit first (stable: the tests of a unit keep their order)."""
    import pytest

    groups = _fixture_groups(items)
    unit = {}
    for item in items:
        group = groups.get(item.nodeid)
        if group:
            item.add_marker(pytest.mark.xdist_group(group))
        unit[item.nodeid] = group or item.nodeid
    if not parallel:
        return
    durations = load_durations() if durations is None else durations
    cost = {}
    for item in items:
        default = DEFAULT.get(_folder(item.nodeid), DEFAULT_OTHER)
        key = unit[item.nodeid]
        cost[key] = cost.get(key, 0.0) + durations.get(item.nodeid, default)
    first = {}
    for k, item in enumerate(items):
        first.setdefault(unit[item.nodeid], k)
    items.sort(key=lambda i: (-cost[unit[i.nodeid]], first[unit[i.nodeid]]))


def plain_nodeid(nodeid):
    """``nodeid`` without the ``@group`` that pytest-xdist appends to a grouped test's."""
    at = nodeid.rfind("@")
    return nodeid[:at] if at > nodeid.rfind("]") else nodeid


class Recorder:
    """Collects each test's time (set-up, call and tear-down) and writes ``durations.json``."""

    def __init__(self):
        self.seconds = {}

    def pytest_runtest_logreport(self, report):
        nodeid = plain_nodeid(report.nodeid)
        self.seconds[nodeid] = self.seconds.get(nodeid, 0.0) + report.duration

    def pytest_sessionfinish(self, session):
        old = load_durations()
        for nodeid in self.seconds:
            old.pop(nodeid, None)
        old.update({k: round(v, 1) for k, v in self.seconds.items() if v >= RECORD_FROM})
        part = DURATIONS + ".%d" % os.getpid()
        with open(part, "w", encoding="utf-8") as f:
            json.dump(dict(sorted(old.items())), f, indent=0, ensure_ascii=True)
            f.write("\n")
        os.replace(part, DURATIONS)
