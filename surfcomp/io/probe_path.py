# SPDX-License-Identifier: LGPL-2.1-or-later
"""The moves of an on-machine probing program, before any dialect is chosen (no FreeCAD).

Every position is the stylus tip CENTRE (the controlled point when the tool length is set
to the ball's centre), which is what LinuxCNC's probe log records. For a planned surface
point ``p`` with unit outward normal ``n`` and a ball of radius ``R`` the tip centre at
contact is ``c = p + R n``. Per point, in the plan's order:

1. traverse at the safe height ``Zs = safe_z + R + clearance`` (the ball's lowest point
   ``clearance`` above the part's top ``safe_z``) to above the retract point
   ``r = c + max(clearance, stand_off) n``, then traverse down to ``r``;
2. feed at the fast feed to the stand-off point ``s = c + stand_off n`` (the fast
   approach; left out when ``stand_off >= clearance``: then ``r`` is ``s``);
3. probe at the touch feed from there along ``-n`` to ``e = c - overtravel n``, the
   overtravel past the nominal contact (the probe stops at the contact);
4. with ``second_touch``: back off ``backoff`` along ``n`` from where the probe stopped
   and probe again to ``e`` at the slower ``second_feed``;
5. feed back along ``n`` to ``r`` and traverse up to ``Zs``.

The traverses at the safe height keep the ball ``clearance`` above the part's top. The
rapid moves down to ``r`` and back up keep it ``clearance`` away from the part only for the
points a plan kept: this module has no solid to check that against; ``plan`` drops every
point whose rapid descent would come closer (:mod:`surfcomp.core.measurement.planning_reach`,
:mod:`surfcomp.app.plan_reach`; ``tests/app/test_probe_loop.py`` checks the moves rs274
reads against the solid with OpenCASCADE). The moves along the normal (steps 2 to 5, at
the feeds) only keep the ball off the part: they end at the contact.
"""

import math
from dataclasses import dataclass, fields

import numpy as np

from ..core.choices import PROBE_DIALECTS as DIALECTS
from ..core.choices import WORK_OFFSETS  # noqa: F401
from ..core.option_tables import PLAN, PROGRAM
from ..errors import InputError

#: largest accepted | |n| - 1 | of a plan's normal
NORMAL_TOL = 1e-6
#: largest coordinate (mm) a program may hold (LinuxCNC and Fanuc both take more; a larger
#: value is a unit mistake)
MAX_COORDINATE = 1e5


@dataclass(frozen=True)
class ProbeSettings:
    """How a plan is probed; lengths in mm, feeds in mm/min.

    Attributes
    ----------
    dialect : {"linuxcnc", "fanuc"}
    tip_radius : float
        Radius ``R`` of the stylus ball; program positions are tip centres.
    tool : int
        Tool number of the probe (``T.. M6``, ``G43 H..``; its length is set to the tip
        centre).
    work_offset : str
        ``G54`` .. ``G59``: the work offset the part was machined in.
    safe_z : float
        The part's top (highest Z of the part in the work offset).
    clearance : float
        How far the ball stays from the part during traverses.
    stand_off : float
        Distance along the normal from the nominal contact at which the probe move starts.
    overtravel : float
        How far past the nominal contact the probe move is programmed to end.
    feed : float
        Fast feed (the approach to the stand-off and the retract).
    touch_feed : float
        Feed of the (first) probe move.
    second_touch : bool
        Back off and touch again at ``second_feed`` (the log then holds two lines per
        point on LinuxCNC, the second one the measurement; one line on Fanuc).
    second_feed : float or None
        Feed of the second touch (None: a fifth of ``touch_feed``); only with
        ``second_touch``.
    backoff : float or None
        Back-off distance before the second touch (None: 1 mm, :meth:`backoff_length`);
        only with ``second_touch``.
    plan_hash : str
        Hex SHA-256 of the plan file, recorded in the header.
    log_file : str or None
        File LinuxCNC writes the probe log to (``PROBEOPEN``; None: ``probe.log``,
        :meth:`log_name`); the linuxcnc dialect only (Fanuc's DPRNT writes to the control's
        output device).

    A setting that cannot take effect (``second_feed`` or ``backoff`` without
    ``second_touch``, ``log_file`` with the fanuc dialect) is refused by :meth:`validate`,
    never dropped without notice.
    program_number : int
        Fanuc program number (``O....``).
    """

    dialect: str = PROGRAM["dialect"].default
    tip_radius: float = PLAN["tip_radius"].default
    tool: int = PROGRAM["tool"].default
    work_offset: str = PROGRAM["work_offset"].default
    safe_z: float = None
    clearance: float = PLAN["clearance"].default
    stand_off: float = PLAN["stand_off"].default
    overtravel: float = PROGRAM["overtravel"].default
    feed: float = PROGRAM["feed"].default
    touch_feed: float = PROGRAM["touch_feed"].default
    second_touch: bool = PROGRAM["second_touch"].default
    second_feed: float = PROGRAM["second_feed"].default
    backoff: float = PROGRAM["backoff"].default
    plan_hash: str = ""
    log_file: str = PROGRAM["log_file"].default
    program_number: int = 1000

    def touch2_feed(self):
        return self.second_feed if self.second_feed is not None else self.touch_feed / 5.0

    def backoff_length(self):
        """The back-off (mm) before the second touch: ``backoff``, or 1 mm when unset."""
        return PROGRAM["backoff"].stored if self.backoff is None else self.backoff

    def log_name(self):
        """The file LinuxCNC writes the probe log to: ``log_file``, or ``probe.log``."""
        return PROGRAM["log_file"].stored if self.log_file is None else self.log_file

    def safe_height(self):
        """Tip-centre Z of the traverses: the ball ``clearance`` above the part's top."""
        return self.safe_z + self.tip_radius + self.clearance

    def validate(self):
        """Refuse settings no program can be written with, or that would not take effect
        (InputError naming the options: the command line shows them as flags, the GUI as
        labels)."""
        if self.dialect not in DIALECTS:
            raise InputError("dialect %r is not known (expected %s)"
                             % (self.dialect, " or ".join(DIALECTS)), options=("dialect",))
        if self.work_offset not in WORK_OFFSETS:
            raise InputError("work_offset %r is not known (expected one of %s)"
                             % (self.work_offset, ", ".join(WORK_OFFSETS)),
                             options=("work_offset",))
        if (isinstance(self.tool, bool) or not isinstance(self.tool, int)
                or not 1 <= self.tool <= 9999):
            raise InputError("tool %r: expected a whole number from 1 to 9999" % (self.tool,),
                             options=("tool",))
        self._check_unused()
        if self.safe_z is None:
            raise InputError("safe_z (the part's top) is needed for the safe height")
        _finite("safe_z", self.safe_z, -MAX_COORDINATE, MAX_COORDINATE)
        _finite("tip_radius", self.tip_radius, 0.0, 50.0, low_open=True)
        for name in ("clearance", "stand_off", "overtravel"):
            _finite(name, getattr(self, name), 0.0, 1000.0, low_open=True)
        _finite("backoff", self.backoff_length(), 0.0, 1000.0, low_open=True)
        for name in ("feed", "touch_feed"):
            _finite(name, getattr(self, name), 0.0, 1e6, low_open=True)
        _finite("second_feed", self.touch2_feed(), 0.0, self.touch_feed, low_open=True)
        if self.touch_feed > self.feed:
            raise InputError("touch_feed %g mm/min is above feed %g mm/min (expected a slow "
                             "touch after a fast approach)" % (self.touch_feed, self.feed),
                             options=("touch_feed", "feed"))
        if self.second_touch and self.backoff_length() > self.stand_off:
            raise InputError("backoff %g mm is larger than stand_off %g mm (expected the "
                             "second touch to start inside the first one's approach)"
                             % (self.backoff_length(), self.stand_off),
                             options=("backoff", "stand_off"))
        self._check_log()
        if not all(ch in "0123456789abcdefABCDEF" for ch in self.plan_hash):
            raise InputError("plan_hash %r: expected a hexadecimal digest" % self.plan_hash)
        if not 1 <= int(self.program_number) <= 9999:
            raise InputError("program_number %r: expected 1 to 9999" % (self.program_number,))
        return self

    def _check_unused(self):
        """Refuse a setting that the program would not use."""
        if not self.second_touch:
            for name, unit in (("second_feed", "mm/min"), ("backoff", "mm")):
                value = getattr(self, name)
                if value is not None:
                    raise InputError(
                        "%s %s %s applies to the second touch only (expected second_touch "
                        "with it, or no %s)" % (name, _g(value), unit, name),
                        options=(name, "second_touch"))
        if self.dialect != "linuxcnc" and self.log_file is not None:
            raise InputError("log_file %r applies to dialect linuxcnc only (expected no "
                             "log_file with dialect %s: its DPRNT writes to the control's "
                             "output device)" % (self.log_file, self.dialect),
                             options=("log_file", "dialect"))

    def _check_log(self):
        name = self.log_name()
        if not isinstance(name, str) or not name.strip():
            raise InputError("log_file %r: expected the name of the file LinuxCNC writes the "
                             "probe log to" % (name,), options=("log_file",))
        if any(ch in name for ch in "()\r\n;"):
            raise InputError("log_file %r: a file name in a G-code comment cannot hold "
                             "parentheses, ';' or line breaks" % name, options=("log_file",))

    def as_dict(self):
        return {f.name: getattr(self, f.name) for f in fields(self)}


def _g(value):
    return "%g" % value if isinstance(value, (int, float)) else repr(value)


def _finite(name, value, low, high, low_open=False):
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if ok and (value > low if low_open else value >= low) and value <= high:
        return
    raise InputError("%s %r: expected a number %s %g and at most %g"
                     % (name, value, "above" if low_open else "from", low, high),
                     options=(name,) if name in PLAN or name in PROGRAM else ())


@dataclass
class ProbePath:
    """The moves of a probing program in tip-centre coordinates (mm).

    ``points``/``normals``: the plan's (N, 3); ``contact``: ``p + R n``; ``retract``,
    ``standoff``, ``end``: the points of the module docstring (N, 3); ``approach``:
    whether a fast approach ``retract -> standoff`` is programmed; ``safe``: the safe
    height; ``backoff``: the second touch's back-off (0: one touch).
    """

    ids: list
    points: np.ndarray
    normals: np.ndarray
    contact: np.ndarray
    retract: np.ndarray
    standoff: np.ndarray
    end: np.ndarray
    approach: bool
    safe: float
    backoff: float = 0.0

    def polyline(self):
        """The tip centre's planned path: ``(positions (M, 3), kinds (M,))`` with kinds
        ``traverse``, ``feed`` and ``probe`` (a probe ends at the nominal contact, where
        it stops on a part of nominal shape); each kind is that of the move ending at the
        position. Starts above the first point."""
        above = self.retract.copy()
        above[:, 2] = self.safe
        seq = [(above, "traverse"), (self.retract, "traverse")]
        if self.approach:
            seq.append((self.standoff, "feed"))
        seq.append((self.contact, "probe"))
        if self.backoff:
            seq += [(self.contact + self.backoff * self.normals, "feed"),
                    (self.contact, "probe")]
        seq += [(self.retract, "feed"), (above, "traverse")]
        pos = np.stack([p for p, _k in seq], axis=1).reshape(-1, 3)
        return pos, [k for _p, k in seq] * len(self.ids)


def probe_path(ids, points, normals, settings):
    """The moves of :func:`surfcomp.io.probe_program.write_probe_program` (module
    docstring); checks the plan.

    Parameters
    ----------
    ids : list of str (N,)
    points : array_like (N, 3)
        Nominal surface points, mm.
    normals : array_like (N, 3)
        Unit outward normals.
    settings : ProbeSettings

    Raises
    ------
    InputError
        Empty plan, mismatched lengths, non-finite or huge coordinates, normals not of
        unit length or pointing down (no 3-axis approach from above), a point above
        ``safe_z``; the message names the point's id.
    """
    s = settings.validate()
    ids = [str(i) for i in ids]
    P = np.asarray(points, dtype=float)
    N = np.asarray(normals, dtype=float)
    if P.ndim != 2 or P.shape[1:] != (3,) or N.shape != P.shape or len(ids) != len(P):
        raise InputError("the plan needs as many ids, points (N, 3) and normals (N, 3): got "
                         "%d ids, points %s, normals %s" % (len(ids), P.shape, N.shape))
    if not len(P):
        raise InputError("the plan holds no point to probe")
    _check_rows(ids, ~(np.isfinite(P).all(axis=1) & (np.abs(P) <= MAX_COORDINATE).all(axis=1)),
                "its point is not finite or beyond %g mm" % MAX_COORDINATE)
    _check_rows(ids, ~(np.abs(np.linalg.norm(N, axis=1) - 1.0) <= NORMAL_TOL),
                "its normal is not of unit length (expected |n| = 1 within %g)" % NORMAL_TOL)
    _check_rows(ids, N[:, 2] < 0.0, "its normal points down (a 3-axis probe reaches it "
                "only from above: expected a normal with k >= 0)")
    _check_rows(ids, P[:, 2] > s.safe_z + 1e-9,
                "it lies above safe_z %g mm (expected safe_z at the part's top)" % s.safe_z)
    R = s.tip_radius
    contact = P + R * N
    return ProbePath(ids=ids, points=P, normals=N, contact=contact,
                     retract=contact + max(s.clearance, s.stand_off) * N,
                     standoff=contact + s.stand_off * N,
                     end=contact - s.overtravel * N, approach=s.stand_off < s.clearance,
                     safe=s.safe_height(),
                     backoff=s.backoff_length() if s.second_touch else 0.0)


def _check_rows(ids, bad, why):
    bad = np.nonzero(bad)[0]
    if bad.size:
        raise InputError("plan point %s (number %d) cannot be probed: %s (%d point(s))"
                         % (ids[bad[0]], bad[0] + 1, why, bad.size))


def travel_summary(path):
    """Lengths (mm) of the tip centre's planned path: ``traverse``, ``feed``, ``probe``
    (to the nominal contacts) and ``total``."""
    pos, kind = path.polyline()
    seg = np.linalg.norm(np.diff(pos, axis=0), axis=1)
    kinds = np.array(kind[1:])
    out = {k: float(seg[kinds == k].sum()) for k in ("traverse", "feed", "probe")}
    out["total"] = float(seg.sum())
    return out
