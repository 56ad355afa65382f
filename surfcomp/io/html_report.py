# SPDX-License-Identifier: LGPL-2.1-or-later
"""One self-contained HTML inspection report per compensation (no FreeCAD).

Input: the JSON report dict of :func:`surfcomp.io.report.build_report` (schema
``surfcomp-report/1``) and optionally the virtual-machining result
(:meth:`surfcomp.core.simulation.simulate.SimulationResult.as_dict`, schema
``surfcomp-simulation/1``). Output: one HTML file, images embedded as base64 PNG
(matplotlib's Agg canvas, no pyplot state, so it is safe inside a Qt application),
no external resources. Sections carry stable ids for tools and tests:

``inputs``      input files with SHA-256, the nominal face
``method``      method, mask, edge handling, stock, grid
``alignment``   the transform applied to the measured points, RMS before/after per face,
                what a fit on the compensated face absorbed (or that none was applied)
``maps``        raw deviation, determined, random, correction, predicted residual (um)
``histograms``  distributions of raw deviation, random component, predicted residual
``statistics``  the papers' table (Werner 2022 Tab. 1 and 3) for every quantity
``checks``      the corrected face's check figures (or why there are none)
``simulation``  the before/after table over replicas (only with a simulation result); with
                a preset the paper's table beside the simulated one (``id="side-by-side"``),
                what the model contains and leaves out, and the simulated parts' maps
                (``id="simulated-maps"``, :func:`simulation_maps`)
``warnings``    messages of the run

The predicted residual is what the correction leaves of the systematic (determined)
error when the next part is cut: ``d_f - s - delta`` (``s`` the stock for the mirror
method, else 0); the next part's new random scatter comes on top. It is defined for every
method: zero for filtered, ``-(d - d_f)`` for raw and mirror (they copy this part's random
scatter into the face), ``d_f - mean(d)`` for offset. The statistics add the expected RMS of
the next part, ``sqrt(rms(residual)^2 + rms(random)^2)``.

Maps use the colour scheme of :mod:`surfcomp.core.colormap` (the GUI's, default rainbow)
and, when given, the GUI map's range, values beyond it in the out-of-range colours.
"""

import html

import numpy as np

from ..core.compensation.deviations import Statistics, cell_text, statistics
from ..core.compensation.methods import predicted_residual
from .atomic import write_text
from .html_figures import (
    DEFAULT_STYLE,
    HistPainter,
    MapPainter,
    bar_chart,
    png,
    simulation_maps_figure,
)

__all__ = ["DEFAULT_STYLE", "SECTIONS", "grid_arrays", "render_html", "simulation_maps",
           "simulation_maps_figure", "write_html_report"]

#: section ids in document order
SECTIONS = ("inputs", "method", "alignment", "maps", "histograms", "statistics", "checks",
            "simulation", "warnings")

_STAT_ROWS = (("count", "Points", None), ("max_negative", "Max. negative", 1e3),
              ("max_positive", "Max. positive", 1e3), ("mean", "Average value", 1e3),
              ("std", "Standard deviation (ddof=1)", 1e3), ("rms", "RMS", 1e3),
              ("profile", "Profile error ISO 1101 (2 max|d|)", 1e3))

_CSS = """
body{font-family:DejaVu Sans,Arial,sans-serif;margin:24px;color:#222;max-width:1200px}
h1{font-size:22px}h2{font-size:18px;border-bottom:1px solid #999;margin-top:28px}
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #bbb;padding:3px 8px}
th{background:#eee}td.num{text-align:right;font-family:DejaVu Sans Mono,monospace}
code{font-size:12px;word-break:break-all}.figs{display:flex;flex-wrap:wrap;gap:12px}
figure{margin:0}figcaption{font-size:13px;text-align:center}
"""


def _e(x):
    """``x`` as HTML text; characters that UTF-8 cannot hold (the surrogates by which Python
    keeps the bytes of a file name that is not UTF-8) as ``\\udcff`` escapes."""
    text = html.escape(str(x), quote=True)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        text = text.encode("utf-8", "backslashreplace").decode("utf-8")
    return text


def _img(fig, alt, caption):
    """``fig`` (a Figure or its base64 PNG) as a figure element."""
    return ('<figure><img alt="%s" src="data:image/png;base64,%s"><figcaption>%s</figcaption>'
            "</figure>" % (_e(alt), fig if isinstance(fig, str) else png(fig), _e(caption)))


def _kv_table(rows):
    out = ["<table>"]
    for k, v in rows:
        out.append("<tr><th>%s</th><td>%s</td></tr>" % (_e(k), v))
    out.append("</table>")
    return "".join(out)


def grid_arrays(report):
    """Per-point arrays of the report back on the measurement grid.

    Returns
    -------
    dict
        ``'x'``, ``'y'`` (n, m) nominal coordinates (mm) and ``'deviation'``,
        ``'determined'``, ``'random'``, ``'correction'``, ``'residual'`` (n, m) in mm
        (NaN where no point fell); (N,) per point for a scattered layout. The residual is
        that of this round's own correction: the points' ``increment`` when the report has
        one (an iteration's, whose ``correction`` is the accumulated one).
    """
    pts = report["points"]
    out = {}
    if pts.get("row") is None:  # scattered layout: per-point arrays (N,)
        def put(values):
            return np.asarray(values, dtype=float)
    else:
        n, m = report["grid"]["shape"]
        row, col = np.asarray(pts["row"], dtype=int), np.asarray(pts["col"], dtype=int)

        def put(values):
            a = np.full((n, m), np.nan)
            a[row, col] = np.asarray(values, dtype=float)
            return a

    nominal = np.asarray(pts["nominal"], dtype=float)
    out["x"], out["y"] = put(nominal[:, 0]), put(nominal[:, 1])
    for key in ("deviation", "determined", "random", "correction"):
        out[key] = put(pts[key])
    meth = report.get("method", {})
    # an iteration's report (``increment``): its correction is the accumulated one, and
    # what the next part keeps is what this round's own correction leaves
    own = out["correction"] if pts.get("increment") is None else put(pts["increment"])
    out["residual"] = predicted_residual(out["determined"], own, meth.get("name"),
                                         meth.get("stock_mm"))
    return out


def _stat_table(columns):
    """``columns``: list of (header, statistics dict in mm), shown as
    :meth:`surfcomp.core.compensation.deviations.Statistics.rows` gives them."""
    rows = [Statistics.from_dict(st).rows("um") for _, st in columns]
    out = ["<table><tr><th>Deviations (µm)</th>%s</tr>"
           % "".join("<th>%s</th>" % _e(h) for h, _ in columns)]
    for k, (label, _v) in enumerate(rows[0]):
        cells = "".join('<td class="num">%s</td>' % cell_text(r[k][1], k) for r in rows)
        out.append("<tr><th>%s</th>%s</tr>" % (_e(label), cells))
    out.append("</table>")
    return "".join(out)


def _section_inputs(report):
    rows = []
    for name, d in report.get("inputs", {}).items():
        info = ["<b>%s</b>" % _e(d.get("path", ""))]
        if d.get("sha256"):
            info.append("SHA-256 <code>%s</code>" % _e(d["sha256"]))
        extra = {k: v for k, v in d.items()
                 if k not in ("path", "sha256") and v not in (None, [], {})}
        if extra:
            info.append(", ".join("%s: %s" % (_e(k), _e(v)) for k, v in extra.items()))
        rows.append((name, "<br>".join(info)))
    rows.append(("surfcomp", _e("%s, %s, created %s" % (report.get("surfcomp_version", "?"),
                                                         report.get("command", "?"),
                                                         report.get("created", "?")))))
    return '<section id="inputs"><h2>Inputs</h2>%s</section>' % _kv_table(rows)


def _section_method(report):
    m = report.get("method", {})
    g = report.get("grid", {})
    fit = report.get("scattered_fit")
    if fit is not None:
        filt = ("Smoothing fit (scattered points)",
                _e("%s, smoothing length %.3g mm (%s); fit residual RMS %.2f µm, "
                   "leave-one-out RMS %.2f µm, estimated field error RMS %.2f µm"
                   % ("thin-plate spline" if fit.get("method") == "tps" else "penalised B-spline",
                      fit["smoothing"], fit["chosen_by"], fit["fit_rms"] * 1e3,
                      fit["loo_rms"] * 1e3, (fit.get("field_error_rms") or 0.0) * 1e3)))
    else:
        mask = np.asarray(m.get("mask") or [[1]], dtype=float)
        mask_html = "<table>%s</table>" % "".join(
            "<tr>%s</tr>" % "".join('<td class="num">%g</td>' % w for w in row) for row in mask)
        filt = ("Mask", "%dx%d %s (Werner 2022 eq. 4-5)%s" % (mask.shape[0], mask.shape[1],
                                                              _e(m.get("mask_kind")), mask_html))
    layout = ("%d scattered points (%s)" % (g.get("shape", ["?"])[0], g.get("found_from", ""))
              if g.get("layout") == "scattered" else
              "%s x %s (%s)" % (tuple(g.get("shape", ["?", "?"])) + (g.get("found_from", ""),)))
    rows = [("Method", _e(m.get("name"))),
            filt,
            ("Edge handling", _e(m.get("edge"))),
            ("Stock (mirror)",
             _e("%s mm" % m["stock_mm"] if m.get("stock_mm") is not None else "-")),
            ("Refinement", _e("at most %s knot spans per grid step" % m.get("refine"))),
            ("Layout", _e(layout))]
    return '<section id="method"><h2>Method and parameters</h2>%s</section>' % _kv_table(rows)


def _signed(xs):
    return " ".join("%+.6f" % x for x in xs)


def _section_alignment(report):
    a = report.get("alignment")
    if not a:
        body = "<p>None: the measured points were taken in the nominal's frame.</p>"
        return '<section id="alignment"><h2>Alignment</h2>%s</section>' % body
    rows = [("Method", _e(a["method"])),
            ("Matrix (measured to nominal)", "<br>".join(
                "<code>%s</code>" % _e(" ".join("%.9f" % x for x in r)) for r in a["matrix"])),
            ("Translation (mm)", _e(_signed(a["translation_mm"]))),
            ("Rotation about X, Y, Z (deg)", _e("%s (%.6f in all)" % (_signed(a["rotation_deg"]),
                                                                      a["angle_deg"])))]
    if a["method"] != "none":
        rows += [("Reference faces", _e(", ".join(a["faces"]))),
                 ("Degrees of freedom", _e(" ".join(a["dof"]))),
                 ("Iterations", _e("%d, %s" % (a["iterations"], "converged" if a["converged"]
                                               else "NOT converged")))]
        for name, after in (a["rms_after_um"] or {}).items():
            rows.append(("RMS distance %s (um)" % name, _e(
                "%.3f before, %.3f after (%d points)"
                % (a["rms_before_um"].get(name, float("nan")), after, a["points"][name]))))
    if a.get("absorbed"):
        where = a["absorbed"].get("where", "face")
        rows.append(("Absorbed on the compensated " + where, _e(
            "mean offset %.3f um, tilt %.3f um across the %s"
            % (a["absorbed"]["mean_offset_um"], a["absorbed"]["tilt_um"], where))))
    return '<section id="alignment"><h2>Alignment</h2>%s</section>' % _kv_table(rows)


def _section_maps(arrays, style=None, painter=None):
    painter = painter or MapPainter()
    figs = []
    for key, title in (("deviation", "Raw deviation d"),
                       ("determined", "Determined (filtered) d_f"),
                       ("random", "Random d - d_f"), ("correction", "Correction applied delta"),
                       ("residual", "Predicted residual")):
        figs.append(_img(painter.png(arrays["x"], arrays["y"], arrays[key] * 1e3,
                                     title + " [µm]", style=style), "map of " + key, title))
    return ('<section id="maps"><h2>Maps</h2><p>Values along the outward normal in µm; '
            'positive = material left; correction positive = material removed (the face moves '
            'inwards by it). Predicted residual = d_f - stock - delta: what the correction '
            'leaves of the systematic error; the next part\'s random scatter comes on top. '
            'Colour scheme %s%s.</p><div class="figs">%s</div></section>'
            % (_e((style or DEFAULT_STYLE)["scheme"]), _range_note(style), "".join(figs)))


def _range_note(style):
    if not style or style.get("range") is None:
        return ", each map on its own symmetric range"
    lo, hi = style["range"]
    return ", range %.1f .. %.1f µm as in the GUI (beyond it: grey)" % (1e3 * lo, 1e3 * hi)


def _section_histograms(arrays):
    painter = HistPainter()
    figs = [_img(painter.figure(arrays[k] * 1e3, t, c), "histogram of " + k, t)
            for k, t, c in (("deviation", "Raw deviation", "#4477aa"),
                            ("random", "Random component", "#cc6677"),
                            ("residual", "Predicted residual", "#228833"))]
    return ('<section id="histograms"><h2>Histograms</h2><div class="figs">%s</div></section>'
            % "".join(figs))


def _section_statistics(report, arrays):
    st = report.get("statistics", {})
    cols = [(h, st[k]) for k, h in (("deviation", "Raw deviations"), ("determined", "Determined"),
                                    ("random", "Random"),
                                    ("correction", "Correction"))] if st else []
    res = arrays["residual"][np.isfinite(arrays["residual"])]
    note = ""
    if res.size:
        res_stats = statistics(res)
        rms_res = res_stats.rms
        cols.append(("Predicted residual", res_stats.as_dict()))
        rnd = arrays["random"][np.isfinite(arrays["random"])]
        rms_rnd = float(np.sqrt(np.mean(rnd ** 2))) if rnd.size else 0.0
        note = ("<p>Expected RMS of the next part (predicted residual plus a new random scatter "
                'like this one): <span class="num">%.2f µm</span>.</p>'
                % (1e3 * float(np.hypot(rms_res, rms_rnd))))
        absorbed = (report.get("alignment") or {}).get("absorbed")
        if absorbed:
            # the prediction is in the fitted frame: what the fit absorbed stays in the part
            note += ("<p>That figure is in the best fit's frame: the mean offset (%.3f µm) and "
                     "tilt (%.3f µm) the fit absorbed on the compensated face are not in it, and "
                     "what of them is machining error stays in the next part.</p>"
                     % (absorbed["mean_offset_um"], absorbed["tilt_um"]))
    assumes = report.get("method", {}).get("residual_assumes")
    if assumes:
        note += "<p>Predicted residual: %s.</p>" % _e(assumes)
    check = report.get("method", {}).get("stock_check")
    if check:
        note += ("<p>Stock check: mean deviation %.1f µm, spread %.1f µm, a part measured with "
                 "this stock should lie within %.1f µm of it: %s.</p>"
                 % (1e3 * check["mean_mm"], 1e3 * check["spread_mm"],
                    1e3 * check["tolerance_mm"],
                    "consistent" if check["consistent"] else
                    "<strong>inconsistent</strong>, used as confirmed (--accept-stock)"))
    return ('<section id="statistics"><h2>Statistics</h2><p>Werner 2022 Tab. 1 and 3 form; '
            'standard deviation with ddof=%s.</p>%s%s</section>'
            % (_e(report.get("statistics_ddof", 1)), _stat_table(cols), note))


def _section_checks(report):
    ch = report.get("corrected_face")
    if not ch:
        body = "<p>No corrected face was built (%s).</p>" % _e(report.get("command", "inspection"))
    else:
        labels = {"max_error_at_points_mm":
                      ("Realised - intended correction at the measured points, max", 1e3, "µm"),
                  "max_deviation_from_nominal_with_zero_correction_mm":
                      ("Zero correction reproduces the nominal within", 1e3, "µm"),
                  "max_abs_realised_correction_on_face_mm":
                      ("Largest correction anywhere on the face", 1e3, "µm"),
                  "max_abs_intended_correction_mm": ("Largest intended correction", 1e3, "µm")}
        rows = []
        for key, val in ch.items():
            if key in labels:
                text, f, unit = labels[key]
                rows.append((text, '<span class="num">%.4f %s</span>' % (val * f, unit)))
            elif key == "normal_turn" and isinstance(val, dict):
                rows.append(("Largest turn of the normal from the nominal's",
                             _e(_normal_turn(val))))
            else:
                rows.append((key.replace("_", " "), _e(_plain(val))))
        size = (report.get("output_shape") or {}).get("file_bytes")
        if size is not None:
            rows.append(("Written file size", '<span class="num">%d bytes</span>' % size))
        body = _kv_table(rows)
    return '<section id="checks"><h2>Corrected face checks</h2>%s</section>' % body


def _plain(value):
    """A check figure in words: yes/no, ``49 x 49`` for a pair of counts, else as it is
    (not Python's ``False`` and ``[49, 49]``)."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (list, tuple)) and value and all(
            isinstance(v, int) and not isinstance(v, bool) for v in value):
        return " x ".join(str(v) for v in value)
    return value


def _normal_turn(turn):
    """The corrected face's ``normal_turn`` (:class:`surfcomp.core.compensation.folds.Fold`)
    as a sentence."""
    text = "%.3f deg" % turn.get("largest_normal_turn_deg", float("nan"))
    at = turn.get("at_mm")
    if at and all(np.isfinite(at)):
        text += " at (%.3f, %.3f, %.3f) mm" % tuple(at)
    text += "; folds over itself: %s" % ("yes" if turn.get("folds") else "no")
    if turn.get("samples"):
        text += " (%.2g %% of %d samples past the fold angle)" % (
            100.0 * turn.get("folded_share", 0.0), turn["samples"])
    return text


def simulation_maps(result):
    """The first replica's simulated parts as maps for :func:`render_html` (``sim['maps']``).

    Parameters
    ----------
    result : surfcomp.core.simulation.simulate.SimulationResult
        Run with ``keep=True``.

    Returns
    -------
    list of dict
        ``{'key', 'title', 'x', 'y', 'values'}``: nominal x, y (mm) and deviations along the
        outward normal (mm) of the first machined part, the mirror method's semi-finished
        part (its measured deviation minus the stock, at the grid nodes) and every method's
        corrected part (on the evaluation grid).
    """
    if result.points is None:
        return []
    P = np.asarray(result.points)
    b = result.between
    out = [{"key": "before", "title": "Machined from the nominal", "x": P[..., 0],
            "y": P[..., 1], "values": result.maps["before"]["after"]}]
    for spec in result.specs:
        mp = result.maps.get(spec.label)
        if mp is None:
            continue
        if spec.label in result.semi_error:
            out.append({"key": "semi-finished", "title": "Semi-finished (minus the stock)",
                        "x": P[::b, ::b, 0], "y": P[::b, ::b, 1],
                        "values": np.asarray(mp["measured"]) - result.model.stock})
        out.append({"key": spec.label, "title": "After %s" % spec.label, "x": P[..., 0],
                    "y": P[..., 1], "values": mp["after"]})
    return out


def _side_by_side_html(side):
    cols = (("mean", "mean"), ("std", "std"), ("max", "max"), ("min", "min"),
            ("profile", "ISO 1101"))
    head = "".join("<th>%s</th>" % h for _, h in cols)
    rows = ["<tr><th rowspan=\"2\">Method (µm)</th><th colspan=\"5\">Paper</th>"
            "<th colspan=\"5\">Simulated</th></tr><tr>%s%s</tr>" % (head, head)]
    for r in side["rows"]:
        cells = []
        for part in (r["paper"], r["simulated"]):
            for key, _ in cols:
                v = None if part is None else part.get(key)
                cells.append('<td class="num">%s</td>' % ("-" if v is None else "%.1f" % (v * 1e3)))
        rows.append("<tr><th>%s</th>%s</tr>" % (_e(r["method"]), "".join(cells)))
    gains = ["<tr><th>Gain 1 - after/before</th><th>std, paper</th><th>std, simulated</th>"
             "<th>ISO 1101, paper</th><th>ISO 1101, simulated</th></tr>"]
    for g in side["gains"]:
        vals = [g[k][w] for k in ("std", "profile") for w in ("paper", "simulated")]
        gains.append("<tr><th>%s (vs %s)</th>%s</tr>" % (
            _e(g["method"]), _e(g["reference"]),
            "".join('<td class="num">%s</td>' % ("-" if v is None else "%.0f %%" % (100 * v))
                    for v in vals)))
    return ('<div id="side-by-side"><h3>Paper vs simulated</h3><p>Paper: %s. Simulated: at the '
            'measured points; mean and std pooled over the replicas, max, min and ISO 1101 '
            'averaged over them.</p><table>%s</table><table>%s</table></div>'
            % (_e(side["citation"]), "".join(rows), "".join(gains)))


def _preset_html(sim):
    preset, paper = sim.get("preset"), sim.get("paper") or {}
    notes = list(paper.get("notes", [])) + list((preset or {}).get("notes", []))
    summary = sim.get("model_summary") or {}
    out = []
    if preset:
        out.append("<h3>Preset %s</h3><p>Imitates %s. Calibrated: %s.</p>"
                   % (_e(preset["name"]), _e(preset["imitates"]), _e(preset["calibrated"])))
    if sim.get("side_by_side"):
        out.append(_side_by_side_html(sim["side_by_side"]))
    if notes:
        out.append("<ul>%s</ul>" % "".join("<li>%s</li>" % _e(n) for n in notes))
    if summary:
        out.append("<h3>What the model contains and leaves out</h3><p>%s</p><p>Left out: %s</p>"
                   % (_e(summary.get("contains", "")), _e(summary.get("leaves_out", ""))))
    return "".join(out)


def _simulated_maps_html(maps, painter=None):
    if not maps:
        return ""
    painter = painter or MapPainter()
    figs = [_img(painter.png(np.asarray(m["x"]), np.asarray(m["y"]),
                             np.asarray(m["values"]) * 1e3, "%s [µm]" % m["title"]),
                 "simulated map of " + m["key"],
                 "%s (std %.2f µm)" % (m["title"], np.std(np.asarray(m["values"]) * 1e3, ddof=1)))
            for m in maps]
    return ('<div id="simulated-maps"><h3>Simulated parts, replica 1</h3><p>Deviation from the '
            'nominal along the outward normal, µm; each map on its own symmetric scale.</p>'
            '<div class="figs">%s</div></div>' % "".join(figs))


def _section_simulation(sim, painter=None):
    if not sim:
        return ""
    cols = [("Before", sim["before"])] + [(m["label"], m) for m in sim["methods"]]
    head = "".join("<th>%s</th>" % _e(h) for h, _ in cols)
    rows = []
    for key, label, f in _STAT_ROWS[1:]:
        if key == "rms":
            continue
        cells = []
        for _, c in cols:
            sp = c["spread"]["all"][key]
            cells.append('<td class="num">%.2f (%.2f)</td>' % (sp["mean"] * f, sp["range"] * f))
        rows.append("<tr><th>%s</th>%s</tr>" % (_e(label), "".join(cells)))
    table = "<table><tr><th>Deviations (µm)</th>%s</tr>%s</table>" % (head, "".join(rows))
    rep = ["<table><tr><th>Std per replica (µm)</th><th>values</th><th>range</th></tr>"]
    for h, c in cols:
        v = np.array([r["all"]["std"] for r in c["replicas"]]) * 1e3
        rep.append('<tr><th>%s</th><td class="num">%s</td><td class="num">%.2f</td></tr>'
                   % (_e(h), ", ".join("%.2f" % x for x in v), np.ptp(v)))
    rep.append("</table>")
    model = sim.get("model", {})
    params = _kv_table([(k, _e(v)) for k, v in model.items() if k != "axis_errors"]
                       + [("axis_errors", _e("yes" if model.get("axis_errors") else "none"))])
    return ('<section id="simulation"><h2>Simulated machining: before / after</h2>'
            '<p>%d replica(s), seed %s, measured on a %s grid and evaluated on %s points (grid '
            'nodes and between). Cells: mean over replicas (range max - min), µm; mirror paper '
            'Tab. 2-4 form.</p>%s%s<div class="figs">%s</div>%s%s<h3>Model parameters</h3>%s'
            '</section>'
            % (sim.get("replicas", 0), _e(sim.get("seed")),
               _e("x".join(map(str, sim.get("grid", [])))),
               _e("x".join(map(str, sim.get("evaluation_grid", [])))), table, "".join(rep),
               _img(bar_chart(sim), "before and after bar chart", "Spread per method"),
               _preset_html(sim), _simulated_maps_html(sim.get("maps"), painter), params))


def render_html(report, simulation=None, style=None):
    """The report as one HTML document (str).

    Parameters
    ----------
    report : dict
        From :func:`surfcomp.io.report.build_report` (schema ``surfcomp-report/1``).
    simulation : dict, optional
        From :meth:`SimulationResult.as_dict` (adds the ``simulation`` section); a
        ``'maps'`` entry (:func:`simulation_maps`) adds the simulated parts' maps.
    style : dict, optional
        ``scheme`` and ``range`` ((lo, hi) mm or None) of the maps (default
        :data:`DEFAULT_STYLE`): the GUI passes its map's so both show the same colours.
    """
    arrays = grid_arrays(report)
    painter = MapPainter()  # one figure for all the maps of a kind
    warn = report.get("warnings") or []
    warn_html = (("<ul>%s</ul>" % "".join("<li>%s</li>" % _e(w) for w in warn)) if warn
                 else "<p>None.</p>")
    title = "surfcomp report: %s, method %s" % (report.get("command", ""),
                                                report.get("method", {}).get("name", ""))
    parts = ['<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">',
             "<title>%s</title><style>%s</style></head><body>" % (_e(title), _CSS),
             "<h1>%s</h1>" % _e(title),
             _section_inputs(report), _section_method(report), _section_alignment(report),
             _section_maps(arrays, style, painter),
             _section_histograms(arrays), _section_statistics(report, arrays),
             _section_checks(report), _section_simulation(simulation, painter),
             '<section id="warnings"><h2>Warnings</h2>%s</section>' % warn_html,
             "</body></html>\n"]
    return "\n".join(parts)


def write_html_report(path, report, simulation=None, style=None):
    """Write :func:`render_html` to ``path`` atomically (temporary file, then rename)."""
    write_text(path, render_html(report, simulation, style))
    return path
