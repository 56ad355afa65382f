# SPDX-License-Identifier: LGPL-2.1-or-later
"""Named virtual-machining cases that imitate the seed papers (no FreeCAD).

A preset is a nominal surface (built here as a core :class:`~surfcomp.core.surface.bspline.Surface`,
so no file is needed), the parameters of the machining-process model
(:mod:`surfcomp.core.simulation.process_model`), a measurement grid, a replica count and the paper's
published table (:class:`~surfcomp.core.simulation.sim_tables.PaperTable`) to print beside the
simulated one.

``werner2022``
    Werner 2022, "Method for enhanced accuracy in machining free-form surfaces on CNC
    milling machines": the bicubic NURBS patch of Fig. 4 (49 control points, 45 x 45 mm;
    the bundled example face), the 45 x 45 CMM grid of Fig. 6 (the parts are evaluated
    at those 2025 points only, ``between = 1``, as Werner measured them), 0.3 mm left for
    the finishing cutter (Sec. 3), Tab. 1-5.
``mirror2019-s1``, ``-s2``, ``-s3``
    The mirror paper (2019; mirror compensation of free-form surfaces with on-machine
    measurement data): the three quadratic surfaces of Fig. 2-4 on the 75 x 63 mm
    workpiece, 0.2 mm stock after semi-finishing (Sec. 2.6), 70, 49 and 68 measured
    points, four replicas, Tab. 2-4. The text gives the figures' shapes in words only,
    so the pole heights below are this module's choice; Surface one's 70 points are the
    paper's 10 points on each of 7 curves (Fig. 5), the 49 of Surface two 7 x 7, and the
    68 of Surface three 17 x 4 (the paper gives only the count).

What is calibrated and what is predicted: the deflection coefficients and geometric
terms of each preset were chosen so that the uncompensated parts match the paper's
"before" figures (mean and std: Werner's finished part, Tab. 1 and 5; the mirror paper's
semi-finished parts, Tab. 3), solving ``mean = a mean(g)`` and ``var = a^2 var(g) + sigma^2 +
probe_sigma^2`` at the measured points for the mirror surfaces. The random scatter is
calibrated too: Werner's to his corrected parts (Tab. 5: 1.8 and 1.4 um), the mirror
presets' to the average of the paper's three mirror-after stds (Tab. 3: 2.0 um), one
value for the three surfaces (the same tool, cutting data and probe, Sec. 2.6). What
the model then predicts: the offset, raw and filtered figures, the mirror figures'
differences between the surfaces and their means, every maximum, minimum and ISO 1101
profile.
"""

from dataclasses import dataclass, field

import numpy as np

from ...errors import lookup
from ..surface import bspline
from .process_model import MachiningModel
from .sim_tables import PaperRow, PaperTable

#: heights (mm) of the 7 x 7 poles of the Werner-like face on a regular 45 mm x-y grid
WERNER_HEIGHTS = np.array([[0.0, 1.5, 3.0, 3.5, 3.0, 2.0, 1.0],
                           [1.0, 3.0, 5.5, 6.0, 5.0, 3.5, 2.0],
                           [2.0, 4.5, 8.0, 9.0, 7.5, 5.0, 3.0],
                           [2.5, 5.0, 8.5, 10.0, 8.0, 5.5, 3.5],
                           [2.0, 4.0, 7.0, 8.0, 7.0, 5.0, 3.0],
                           [1.0, 2.5, 4.5, 5.5, 4.5, 3.5, 2.0],
                           [0.0, 1.0, 2.5, 3.0, 2.5, 1.5, 1.0]])
#: the mirror paper's workpiece (mm): along u (x) and along v (y)
MIRROR_SIZE = (75.0, 63.0)
#: pole heights (mm) of the three quadratic surfaces, poles indexed [u][v]
MIRROR_HEIGHTS = {
    # Fig. 2: every u-curve the same quadratic, v-lines straight and horizontal
    "s1": np.array([[10.0, 10.0], [26.0, 26.0], [14.0, 14.0]]),
    # Fig. 3: u-lines straight with different slopes; v-curves quadratic, convex at
    # u = 0 turning concave at u = 1
    "s2": np.array([[10.0, 20.0, 10.0], [16.0, 8.0, 16.0]]),
    # Fig. 4: u- and v-curves quadratic, each convex on one side and concave on the other
    "s3": np.array([[12.0, 20.0, 12.0], [20.0, 15.0, 10.0], [12.0, 10.0, 18.0]]),
}


def werner_surface():
    """The Werner-like face (the bundled example): 7 x 7 poles over 45 x 45 mm, bicubic,
    interior knots 0.25, 0.5, 0.75 (Werner 2022, Fig. 4: 49 control points, degree 3).
    Outward normal ``Su x Sv`` (+z)."""
    x = np.linspace(0.0, 45.0, 7)
    P = np.stack([*np.meshgrid(x, x, indexing="ij"), WERNER_HEIGHTS], axis=-1)
    k = np.array([0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1.0])
    return bspline.Surface(P, k, k, 3, 3)


def mirror_surface(which):
    """One of the mirror paper's quadratic surfaces (Fig. 2-4) as a single Bezier patch.

    Parameters
    ----------
    which : {'s1', 's2', 's3'}

    Returns
    -------
    bspline.Surface
        u along x (0 .. 75 mm), v along y (0 .. 63 mm), z the pole heights of
        ``MIRROR_HEIGHTS`` (degree = poles - 1 in each direction, so every parameter
        line is a straight line or a parabola); outward normal ``Su x Sv`` (+z).
    """
    Z = MIRROR_HEIGHTS[which]
    nu, nv = Z.shape
    x = np.linspace(0.0, MIRROR_SIZE[0], nu)
    y = np.linspace(0.0, MIRROR_SIZE[1], nv)
    P = np.stack([*np.meshgrid(x, y, indexing="ij"), Z], axis=-1)
    return bspline.Surface(P, _bezier_knots(nu - 1), _bezier_knots(nv - 1), nu - 1, nv - 1)


def _bezier_knots(degree):
    return np.r_[np.zeros(degree + 1), np.ones(degree + 1)]


@dataclass(frozen=True)
class Preset:
    """A named case: ``surface()`` builds the nominal, ``machining_model()`` the model."""

    name: str
    imitates: str
    build: object
    model: dict
    grid: tuple
    paper: PaperTable
    replicas: int = 4
    between: int = 2
    calibrated: str = ""
    notes: tuple = field(default_factory=tuple)

    def surface(self):
        """The nominal surface and its outward sign: (bspline.Surface, +1)."""
        return self.build(), 1

    def machining_model(self, **overrides):
        """The preset's :class:`MachiningModel`, with ``overrides`` (field -> value)."""
        kw = dict(self.model)
        kw.update(overrides)
        return MachiningModel(**kw)

    def as_dict(self):
        return {"name": self.name, "imitates": self.imitates, "grid": list(self.grid),
                "replicas": self.replicas, "between": self.between,
                "model": self.machining_model().as_dict(),
                "calibrated": self.calibrated, "notes": list(self.notes)}


_UM = 1e-3
_MIRROR_CITATION = ("mirror paper (2019), mirror compensation of free-form surfaces with "
                    "on-machine measurement data, Tab. 3 (mean, std of the 4 replicas' errors "
                    "pooled) and Tab. 4 (ISO 1101 profile)")
_MIRROR_NOTES = (
    "The paper machines no uncompensated finish: its 'before' parts are semi-finished. "
    "Row none holds the tool-radius experiment's before, row semi-finished the mirror "
    "experiment's (other parts). The paper measures gains against them; the simulation "
    "against its own rows of the same name.",
    "Max and min per part are not given (Fig. 10-12 plot replica one only).",
    "Tab. 4 gives Surface three's tool-radius gain as 54.8 - 24.5 = 30.3 um (55 %); the "
    "text says 30.5 um (56 %). Tab. 2's Surface three tool-radius 'after' stds (3.2, 3.2, "
    "3.2, 3.0) lie above the pooled 3.1 of Tab. 3, which pooling cannot give (rounding).",
)


def _mirror_table(surface, before, offset, semi, mirror):
    """``before`` etc.: (mean, std, profile) in um from Tab. 3 and 4."""
    def row(method, vals, source, reference=None):
        mean, std, profile = (v * _UM for v in vals)
        return PaperRow(method, mean=mean, std=std, profile=profile, reference=reference,
                        source="%s; %s" % (surface, source))

    return PaperTable(_MIRROR_CITATION, (
        row("none", before, "tool radius compensation, before (semi-finished)"),
        row("offset", offset, "tool radius compensation, after", "none"),
        row("semi-finished", semi, "mirror compensation, before"),
        row("mirror", mirror, "mirror compensation, after", "semi-finished")), _MIRROR_NOTES)


WERNER_TABLE = PaperTable(
    "Werner 2022, Tab. 5 (one part per stage; Tab. 1, 2 and 4 give the same figures)",
    (PaperRow("none", mean=0.0022, std=0.0173, max=0.045, min=-0.030,
              source="Tab. 5 'raw' deviations (Tab. 1 gives the mean as 0.0021 mm)"),
     PaperRow("raw", mean=0.0023, std=0.0018, max=0.009, min=-0.005, reference="none",
              source="Tab. 5 correction 1, 'raw' deviations (Tab. 2)"),
     PaperRow("filtered", mean=0.0013, std=0.0014, max=0.007, min=-0.004, reference="none",
              source="Tab. 5 correction 2, filtered deviations, 5x5 box (Tab. 4)")),
    ("Werner gives no ISO 1101 profile; its maxima and minima are a single part's.",
     "Werner's mean stays at about 2 um after correction, a sign of some change between "
     "parts (the paper does not say which); the model leaves such changes out."))

_MIRROR_CALIBRATED = ("deflection: the semi-finished mean and std of Tab. 3 (mirror 'before'); "
                      "sigma 1.3 um, shared by the three surfaces: the average of Tab. 3's "
                      "mirror-after stds (2.0 um)")
#: one machine for the three mirror surfaces: random scatter and probe (0.25 um at 2
#: sigma, Sec. 2.1), stock 0.2 mm after semi-finishing, roughing 0.4 mm (Sec. 2.6)
_MIRROR_MACHINE = dict(sigma=0.0013, probe_sigma=0.000125, stock=0.2, semi_engagement=0.2,
                       slope_gain=0.0, abs_slope_gain=0.0, tilt=(0.0, 0.0), bow=(0.0, 0.0))

PRESETS = {p.name: p for p in (
    Preset("werner2022", "Werner 2022, Fig. 4-7 and Tab. 1-5", werner_surface,
           dict(offset=-0.012, slope_gain=0.0, abs_slope_gain=0.0, tilt=(0.0, 0.02),
                bow=(0.0, 0.0), deflection=(0.02, 0.2, 0.15), stock=0.3, sigma=0.0012,
                probe_sigma=0.0005),
           (45, 45), WERNER_TABLE, between=1,
           calibrated="offset, deflection and tilt_c: the uncompensated mean and std of "
                      "Tab. 1 and 5 (the range only roughly); sigma: Tab. 5's corrected parts; "
                      "probe_sigma 0.5 um (the CMM's MPE is 1.5 + L/333 um)"),
    Preset("mirror2019-s1", "mirror paper 2019, Surface one (Fig. 2, 5, 10; Tab. 2-4)",
           lambda: mirror_surface("s1"),
           dict(_MIRROR_MACHINE, deflection=(0.0685, 0.132, 0.0)),
           (10, 7), _mirror_table("Surface one", (14.1, 6.2, 54.9), (2.0, 6.1, 30.1),
                                  (15.1, 6.2, 57.6), (0.1, 2.4, 12.8)),
           calibrated=_MIRROR_CALIBRATED),
    Preset("mirror2019-s2", "mirror paper 2019, Surface two (Fig. 3, 11; Tab. 2-4)",
           lambda: mirror_surface("s2"),
           dict(_MIRROR_MACHINE, deflection=(0.082, 0.415, 0.0)),
           (7, 7), _mirror_table("Surface two", (17.2, 3.8, 52.3), (0.9, 3.7, 20.0),
                                 (17.2, 3.8, 52.7), (0.7, 1.5, 8.3)),
           calibrated=_MIRROR_CALIBRATED),
    Preset("mirror2019-s3", "mirror paper 2019, Surface three (Fig. 4, 12; Tab. 2-4)",
           lambda: mirror_surface("s3"),
           dict(_MIRROR_MACHINE, deflection=(0.084, 0.159, 0.0)),
           (17, 4), _mirror_table("Surface three", (16.5, 3.2, 54.8), (-0.3, 3.1, 24.5),
                                  (16.8, 3.1, 53.2), (0.3, 2.1, 12.0)),
           calibrated=_MIRROR_CALIBRATED),
)}


def get_preset(name):
    """The :class:`Preset` called ``name``; InputError naming the known ones otherwise."""
    return lookup(PRESETS, name, "preset")


def run_preset(name, surface=None, outward=1, model=None, grid=None, replicas=None, seed=0,
               specs=None, **kw):
    """Simulate a preset (:func:`surfcomp.core.simulation.simulate.simulate`) and attach it to the
    result.

    ``surface``/``outward`` replace the preset's nominal, ``model`` (a
    :class:`MachiningModel`) its parameters, ``grid``/``replicas``/``between`` its
    layout; other keywords go to ``simulate``.
    """
    from .simulate import simulate

    preset = get_preset(name) if isinstance(name, str) else name
    if surface is None:
        surface, outward = preset.surface()
    kw.setdefault("between", preset.between)
    res = simulate(surface, outward, model or preset.machining_model(),
                   grid=grid or preset.grid, specs=specs,
                   replicas=replicas or preset.replicas, seed=seed, **kw)
    res.preset = preset
    return res
