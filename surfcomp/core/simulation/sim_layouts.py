# SPDX-License-Identifier: LGPL-2.1-or-later
"""Adaptive against uniform measurement points in the virtual machining loop (no FreeCAD).

The mirror paper (2019, section 2.3) placed its points where the slope changes fast, on the
view that this fits the surface better. :func:`compare_layouts` tests that claim in the
simulation: the same parts (same model, seed and replicas; the evaluation grid's random
draws are shared, so the comparison is paired) are measured at N adaptive points and at N
uniform points (:mod:`surfcomp.core.measurement.planning`, the adaptive layout and its uniform
twin), compensated, machined again and evaluated over the whole face. For every compensating
method the residual's standard deviation (mean over the replicas) is compared; a difference
counts when it exceeds twice its standard error over the replicas.
"""

from dataclasses import dataclass, field

import numpy as np

from ..measurement.planning import PlanSettings, plan_points
from .simulate import simulate

#: a difference counts when it exceeds this many standard errors
SIGNIFICANCE = 2.0


@dataclass
class LayoutComparison:
    """Results of :func:`compare_layouts`: ``results[layout]`` a
    :class:`~surfcomp.core.simulation.simulate.SimulationResult`, ``plans[layout]`` the plan."""

    points: int
    results: dict = field(default_factory=dict)
    plans: dict = field(default_factory=dict)

    def rows(self, key="std", where="all"):
        """Per compensating method ``(label, uniform mean, uniform se, adaptive mean,
        adaptive se, verdict)`` (mm): mean and standard error over the replicas."""
        out = []
        uni, ada = self.results["uniform"], self.results["adaptive"]
        for spec in uni.specs:
            if spec.method == "none":
                continue
            a, b = uni.values(spec.label, key, where), ada.values(spec.label, key, where)
            ma, mb = float(a.mean()), float(b.mean())
            sa = float(a.std(ddof=1) / np.sqrt(a.size)) if a.size > 1 else 0.0
            sb = float(b.std(ddof=1) / np.sqrt(b.size)) if b.size > 1 else 0.0
            se = float(np.hypot(sa, sb))
            if mb < ma - SIGNIFICANCE * se:
                verdict = "adaptive lower"
            elif mb > ma + SIGNIFICANCE * se:
                verdict = "uniform lower"
            else:
                verdict = "no difference beyond the replicas' scatter"
            out.append((spec.label, ma, sa, mb, sb, verdict))
        return out

    def verdict(self):
        """``'reproduced'`` when the adaptive points leave the lower residual for most
        compensating methods and the higher for none; else ``'not supported'``."""
        v = [r[-1] for r in self.rows()]
        better, worse = v.count("adaptive lower"), v.count("uniform lower")
        return "reproduced" if better > len(v) / 2 and not worse else "not supported"

    def table(self):
        """The comparison as text (um)."""
        lines = ["Adaptive vs uniform measurement points, %d each: residual std after "
                 "compensation over the whole face (um; mean +- standard error over %d "
                 "replicas)" % (self.points, self.results["uniform"].replicas),
                 "%-12s %16s %16s  %s" % ("method", "uniform", "adaptive", "")]
        for label, ma, sa, mb, sb, verdict in self.rows():
            lines.append("%-12s %9.2f +- %-4.2f %9.2f +- %-4.2f  %s"
                         % (label, ma * 1e3, sa * 1e3, mb * 1e3, sb * 1e3, verdict))
        lines.append("The mirror paper's claim (denser points where the slope changes fast "
                     "give the better compensation): %s." % self.verdict())
        return "\n".join(lines)

    def as_dict(self):
        return {"points": self.points, "verdict": self.verdict(),
                "methods": [dict(zip(("label", "uniform_std_mm", "uniform_se_mm",
                                      "adaptive_std_mm", "adaptive_se_mm", "verdict"), r))
                            for r in self.rows()],
                "placed": {k: len(p) for k, p in self.plans.items()},
                "significance_standard_errors": SIGNIFICANCE}


def compare_layouts(domain, model, points, settings=None, progress=None, **loop):
    """Run the loop of :func:`surfcomp.core.simulation.simulate.simulate` at ``points`` uniform and
    ``points`` adaptive measurement points on ``domain`` (a
    :class:`~surfcomp.core.measurement.planning_face.FaceDomain`); ``loop``: its other arguments
    (``grid`` the evaluation grid, ``specs``, ``replicas``, ``seed``, ``between``, ...).

    Returns
    -------
    LayoutComparison
    """
    out = LayoutComparison(points=int(points))
    for k, layout in enumerate(("uniform", "adaptive")):
        plan = plan_points(domain, layout, int(points), settings or PlanSettings())
        out.plans[layout] = plan
        sub = None if progress is None else (
            lambda f, m, k=k: progress((k + f) / 2, "%s points: %s" % (("uniform", "adaptive")[k],
                                                                       m)))
        out.results[layout] = simulate(domain.surface, domain.outward, model,
                                       points=plan.points, progress=sub, **loop)
    return out
