# SPDX-License-Identifier: LGPL-2.1-or-later
"""Tables of virtual machining: spread over replicas, the papers' table form, and the
papers' published values beside the simulated ones (no FreeCAD).

Statistics are :class:`~surfcomp.core.compensation.deviations.Statistics` in mm; the formatted
tables print um. The side-by-side table follows the papers' rows (the methods) and columns
(mean, std, max, min, ISO 1101 profile): the mirror paper (2019) pools the errors of its
four replicas for the mean and standard deviation (Tab. 3: 280 errors for Surface one),
so the simulated mean and std are pooled over the replicas too; max, min and the profile
are a part's figures, so the simulated ones are averaged over the parts.
"""

from dataclasses import dataclass

import numpy as np

#: statistics shown in the papers' table form (key, label)
TABLE_ROWS = (("max_negative", "Max. negative"), ("max_positive", "Max. positive"),
              ("mean", "Average value"), ("std", "Standard deviation (ddof=1)"),
              ("profile", "Profile error ISO 1101 (2 max|d|)"))
STAT_KEYS = ("count", "max_negative", "max_positive", "mean", "std", "rms", "profile", "min",
             "max")
#: columns of the side-by-side table: (key in the row dicts, header)
SIDE_COLUMNS = (("mean", "mean"), ("std", "std"), ("max", "max"), ("min", "min"),
                ("profile", "ISO 1101"))
#: rows of the side-by-side table, in order (the mirror method's semi-finished input
#: sits just before it)
SIDE_ROWS = ("none", "offset", "raw", "filtered", "semi-finished", "mirror")


def spread(stats_list):
    """Spread over replicas of each statistic: ``{key: {mean, min, max, range, std}}`` (mm).

    ``std`` over replicas uses ddof=1 (0 for one replica).
    """
    out = {}
    for key in STAT_KEYS:
        a = np.array([getattr(s, key) for s in stats_list], dtype=float)
        out[key] = {"mean": float(a.mean()), "min": float(a.min()), "max": float(a.max()),
                    "range": float(np.ptp(a)), "std": float(a.std(ddof=1)) if a.size > 1 else 0.0}
    return out


def pooled(stats_list):
    """Mean and sample standard deviation (ddof=1) of all replicas' values taken together.

    Parameters
    ----------
    stats_list : list of Statistics
        One per replica (``count``, ``mean``, ``std`` with ddof=1).

    Returns
    -------
    (float, float)
        ``M = sum(n_i m_i) / N`` and ``sqrt(sum((n_i - 1) s_i^2 + n_i (m_i - M)^2) / (N - 1))``
        (mm): exactly the statistics of the concatenated values.
    """
    n = np.array([s.count for s in stats_list], dtype=float)
    m = np.array([s.mean for s in stats_list], dtype=float)
    sd = np.array([s.std for s in stats_list], dtype=float)
    total = n.sum()
    mean = float(np.sum(n * m) / total)
    if total < 2:
        return mean, 0.0
    ss = np.sum((n - 1.0) * sd ** 2 + n * (m - mean) ** 2)
    return mean, float(np.sqrt(ss / (total - 1.0)))


def side_values(stats_list):
    """The side-by-side row of replicas' statistics (mm): pooled ``mean`` and ``std``;
    ``max``, ``min`` and ``profile`` averaged over the parts; ``replicas``, ``count``."""
    mean, std = pooled(stats_list)
    return {"mean": mean, "std": std,
            "max": float(np.mean([s.max for s in stats_list])),
            "min": float(np.mean([s.min for s in stats_list])),
            "profile": float(np.mean([s.profile for s in stats_list])),
            "replicas": len(stats_list), "count": int(stats_list[0].count)}


@dataclass(frozen=True)
class PaperRow:
    """One method's published values (mm; None where the paper gives none) and where they
    are printed; ``reference`` is the row the paper measures its gain against."""

    method: str
    mean: float = None
    std: float = None
    max: float = None
    min: float = None
    profile: float = None
    source: str = ""
    reference: str = None

    def value(self, key):
        return getattr(self, key)

    def as_dict(self):
        d = {k: self.value(k) for k, _ in SIDE_COLUMNS}
        d.update(method=self.method, source=self.source, reference=self.reference)
        return d


@dataclass(frozen=True)
class PaperTable:
    """A paper's published results in the side-by-side rows."""

    citation: str
    rows: tuple
    notes: tuple = ()

    def row(self, method):
        return next((r for r in self.rows if r.method == method), None)

    def as_dict(self):
        return {"citation": self.citation, "units": "mm", "notes": list(self.notes),
                "rows": [r.as_dict() for r in self.rows]}


def _gain(after, before):
    if after is None or before is None or not before:
        return None
    return 1.0 - after / before


def side_by_side(rows, paper):
    """The paper's and the simulated values in the same rows, and both gains.

    Parameters
    ----------
    rows : dict
        ``method -> (label, side_values dict)`` for the simulated methods (``SIDE_ROWS``
        names; ``label`` the simulation's column).
    paper : PaperTable

    Returns
    -------
    dict
        ``rows``: per ``SIDE_ROWS`` method present in either, ``{method, label, paper,
        simulated}`` (None for a side that has no such row); ``gains``: per paper row
        with a ``reference``, ``{method, reference, std: {paper, simulated}, profile:
        {...}}``, the gain ``1 - after / before`` of each against the same reference row.
    """
    out, gains = [], []
    for method in SIDE_ROWS:
        prow = paper.row(method)
        label, sim = rows.get(method, (None, None))
        if prow is None and sim is None:
            continue
        out.append({"method": method, "label": label,
                    "paper": None if prow is None else prow.as_dict(), "simulated": sim})
        if prow is not None and prow.reference:
            ref_p = paper.row(prow.reference)
            ref_s = rows.get(prow.reference, (None, None))[1]
            g = {"method": method, "reference": prow.reference}
            for key in ("std", "profile"):
                g[key] = {"paper": _gain(prow.value(key), ref_p and ref_p.value(key)),
                          "simulated": (None if sim is None or ref_s is None
                                        else _gain(sim[key], ref_s[key]))}
            gains.append(g)
    return {"citation": paper.citation, "rows": out, "gains": gains}


def _cells(row):
    return "".join("%9s" % ("-" if row is None or row[k] is None else "%.1f" % (row[k] * 1e3))
                   for k, _ in SIDE_COLUMNS)


def format_side_by_side(table, title, detail=""):
    """The :func:`side_by_side` dict as text (um; gains in %)."""
    head = "".join("%9s" % h for _, h in SIDE_COLUMNS)
    width = len(head)
    lines = [title, "Paper: %s" % table["citation"]]
    if detail:
        lines.append(detail)
    lines += ["%-14s |%s |%s" % ("", "paper".center(width), "simulated".center(width)),
              "%-14s |%s |%s" % ("method (um)", head, head)]
    for r in table["rows"]:
        lines.append("%-14s |%s |%s" % (r["method"], _cells(r["paper"]), _cells(r["simulated"])))
    if table["gains"]:
        lines.append("Gain 1 - after/before (%%)%s  std: paper simulated   ISO 1101: paper "
                     "simulated" % (" " * 4))
        for g in table["gains"]:
            cells = []
            for key in ("std", "profile"):
                for side in ("paper", "simulated"):
                    v = g[key][side]
                    cells.append("%5s" % ("-" if v is None else "%.0f" % (100.0 * v)))
            lines.append("%-30s %10s %9s %16s %9s"
                         % ("%s (vs %s)" % (g["method"], g["reference"]), *cells))
    return "\n".join(lines)


def format_simulation_table(columns, replicas, unit="um"):
    """Format ``[(header, [Statistics per replica])]`` as rows of ``mean (range)``.

    Returns
    -------
    str
        Rows Max. negative, Max. positive, Average value, Standard deviation, Profile
        error ISO 1101; every cell the mean over replicas and, in parentheses, the range
        (max - min) over them (mirror paper Tab. 2-4 form).
    """
    f = 1000.0 if unit == "um" else 1.0
    fmt = "%.2f (%.2f)" if unit == "um" else "%.4f (%.4f)"
    labels = [lab for _, lab in TABLE_ROWS]
    width = max(len(s) for s in labels) + 2
    cells = [[fmt % (np.mean([getattr(s, key) for s in lst]) * f,
                     np.ptp([getattr(s, key) for s in lst]) * f) for key, _ in TABLE_ROWS]
             for _, lst in columns]
    colw = max(14, max(len(h) for h, _ in columns) + 2,
               max(len(c) for col in cells for c in col) + 2)
    out = ["Simulated machining, %d replica(s): mean (range) over replicas, %s"
           % (replicas, "µm" if unit == "um" else "mm"),
           "Deviations".ljust(width) + "".join(h.rjust(colw) for h, _ in columns)]
    for k, lab in enumerate(labels):
        out.append(lab.ljust(width) + "".join(col[k].rjust(colw) for col in cells))
    return "\n".join(out)

