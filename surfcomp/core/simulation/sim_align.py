# SPDX-License-Identifier: LGPL-2.1-or-later
"""Alignment in the virtual machining loop: what an alignment of the measured part absorbs
(no FreeCAD).

The loop measures its parts in the nominal's frame (the machine's): the measured points
are ``nominal + deviation * normal``. With ``simulate --align`` (or ``--transform``), before
every compensation those points are

1. moved into the measuring frame by the inverse of the known transform, when one is given
   (the part measured in another frame; without one they stay where they are), then
2. aligned back exactly as ``compensate --align`` aligns a measured file
   (:func:`surfcomp.core.measurement.align_report.align`: the known transform, then the best fit or
   the 3-2-1 alignment on the nominal face),

and the compensation gets the signed distances of the aligned points from the face (their
exact projection), at the same nodes. The corrected part is still machined and judged in
the nominal's frame, so the tables show what the alignment cost: a best fit on the
compensated face takes the machining error's mean offset and tilt out of the measurement,
and the corrected face leaves them in the part. The mirror method measures its
semi-finished part with the stock on it; a best fit on the face absorbs that stock too.
"""

import numpy as np

from ..measurement.align import Reference, apply
from ..measurement.align_report import align, summary_lines
from ..surface.projection import Projector


class SimAligner:
    """The ``aligner`` of :func:`surfcomp.core.simulation.simulate.simulate`: aligns every simulated
    measurement and keeps the records (``records``: ``(method label, replica, Alignment)``
    in the loop's order).

    Parameters
    ----------
    surface : bspline.Surface
        The nominal face, the only reference face.
    outward : {1, -1}
    options : surfcomp.core.measurement.align_report.AlignOptions
        Checked here; ``faces`` must be empty (the loop has one face).
    name : str
        The face's name in the records.
    """

    def __init__(self, surface, outward, options, name="Face1"):
        self.options = options.validate()
        self.refs = [Reference(name, surface, outward)]
        self.projector = Projector(surface)
        self.outward = outward
        self.records = []

    def __call__(self, label, nominal, normal, deviation):
        d = np.asarray(deviation, dtype=float)
        flat = d.reshape(-1)
        good = np.isfinite(flat)
        P = nominal[good] + flat[good, None] * normal[good]
        if self.options.transform is not None:
            P = apply(np.linalg.inv(self.options.transform), P)
        aligned, rec = align(P, self.options, self.refs, 0)
        replica = sum(1 for lab, _r, _a in self.records if lab == label)
        self.records.append((label, replica, rec))
        out = np.full(flat.shape, np.nan)
        out[good] = self.projector.project(aligned).distance * self.outward
        return out.reshape(d.shape)

    def as_dict(self):
        """The report's ``"alignment"`` object: the first fit's (first replica, first
        compensating method) as ``compensate`` writes it, and ``"simulated"``: every
        fit's method label, replica (0-based), convergence and what it absorbed."""
        if not self.records:
            return None
        out = self.records[0][2].as_dict()
        out["simulated"] = {
            "first_fit": {"method": self.records[0][0], "replica": 0},
            "fits": [{"method": lab, "replica": r, "converged": a.converged,
                      "iterations": a.iterations, "absorbed": a.absorbed,
                      "matrix": [[float(x) for x in row] for row in a.matrix]}
                     for lab, r, a in self.records]}
        return out

    def summary(self):
        """Lines for the command's output: the first fit's summary and, per method, the
        mean offset and tilt the fits absorbed (mean over the replicas)."""
        d = self.as_dict()
        if d is None:
            return []
        lines = summary_lines(d)
        lines[0] += " (replica 1, %s)" % self.records[0][0]
        for label in dict.fromkeys(lab for lab, _r, _a in self.records):
            fits = [a for lab, _r, a in self.records if lab == label]
            absorbed = [a.absorbed for a in fits if a.absorbed]
            text = ("; absorbed mean offset %.3f um, tilt %.3f um (mean of %d)"
                    % (np.mean([x["mean_offset_um"] for x in absorbed]),
                       np.mean([x["tilt_um"] for x in absorbed]), len(absorbed))
                    if absorbed else "")
            lines.append("  %s: %d fit(s), %d converged%s"
                         % (label, len(fits), sum(a.converged for a in fits), text))
        return lines
