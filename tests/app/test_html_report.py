# SPDX-License-Identifier: LGPL-2.1-or-later
"""The self-contained HTML report (surfcomp.io.html_report) rendered by headless Chromium:
every section in the DOM, every image an embedded PNG that decodes, a non-blank screenshot
showing the colour maps; predicted residuals by hand; atomic writing."""

import base64
import copy
import io
import os
import re
import subprocess

import numpy as np
import pytest
from numpy.testing import assert_allclose
from PIL import Image

from surfcomp.core import colormap
from surfcomp.core.compensation.pipeline import Options, compensate, prepare
from surfcomp.core.measurement_set import MeasurementSet
from surfcomp.core.simulation import presets
from surfcomp.core.simulation import simulate as sm
from surfcomp.core.surface import bspline
from surfcomp.io import report as report_io
from surfcomp.io.html_report import (
    SECTIONS,
    grid_arrays,
    render_html,
    simulation_maps,
    write_html_report,
)
from tests.pure.surfaces import wavy_patch

#: the reports computed so far, by _report's arguments (several tests use the same one)
_REPORTS = {}


def _report(method="filtered", stock=None, n=11, build=True, seed=1):
    """A compensation report of a synthetic smooth field + noise on an n x n grid (a fresh
    copy of the one computed for the same arguments, so a test may change it)."""
    key = (method, stock, n, build, seed)
    if key not in _REPORTS:
        _REPORTS[key] = _compute_report(*key)
    return copy.deepcopy(_REPORTS[key])


def _compute_report(method, stock, n, build, seed):
    surf = wavy_patch()
    us = np.linspace(0.02, 0.98, n)
    S, Su, Sv = bspline.evaluate_grid(surf, us, us, order=1)
    nrm = np.cross(Su, Sv)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    rng = np.random.default_rng(seed)
    d = (0.02 * np.sin(S[..., 0] / 9.0) - 0.01 * (S[..., 1] / 30.0) ** 2
         + rng.normal(0, 0.002, (n, n)))
    d = d + (stock or 0.0)
    rows, cols = np.indices((n, n))
    ms = MeasurementSet(nominal=S.reshape(-1, 3), normal=nrm.reshape(-1, 3),
                        deviation=d.ravel(), row=rows.ravel(), col=cols.ravel())
    opt = Options(method=method, stock=stock)
    comp = compensate(surf, 1, prepare(surf, 1, ms, opt), opt, build=build)
    inputs = {"nominal": {"path": "/data/nominal.step", "sha256": "ab" * 32, "face": "Face1"},
              "measurements": {"path": "/data/m<1>.csv", "sha256": "cd" * 32, "points": n * n}}
    return report_io.build_report("compensate" if build else "inspect", inputs, comp,
                                  ["a <b> warning"])


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """A filtered compensation with a simulation, written and opened in headless Chromium."""
    folder = tmp_path_factory.mktemp("html")
    sim = sm.simulate(wavy_patch(), 1, sm.MachiningModel(), grid=(9, 9), replicas=2, seed=3,
                      specs=sm.method_specs(["none", "offset", "raw", "filtered"])).as_dict()
    rep = _report()
    path = str(folder / "report.html")
    write_html_report(path, rep, sim)
    base = ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
            "--user-data-dir=%s" % (folder / "profile")]
    shot = str(folder / "shot.png")
    screenshot = ["--screenshot=%s" % shot, "--window-size=1200,2600"]
    # one browser start for the DOM and the screenshot (headless Chromium runs both
    # commands); one that ran only the first takes the screenshot in a second start
    dom = subprocess.run(base + ["--dump-dom"] + screenshot + ["file://" + path],
                         capture_output=True, text=True, timeout=120)
    assert dom.returncode == 0, dom.stderr
    if not os.path.isfile(shot):
        out = subprocess.run(base + screenshot + ["file://" + path],
                             capture_output=True, text=True, timeout=120)
        assert out.returncode == 0, out.stderr
    assert os.path.isfile(shot)
    return {"path": path, "dom": dom.stdout, "shot": shot, "report": rep, "sim": sim,
            "folder": folder}


def test_every_section_is_in_the_dom(rendered):
    dom = rendered["dom"]
    for sec in SECTIONS:
        assert re.search(r'<section id="%s">' % sec, dom), sec
    ids = re.findall(r'<section id="([a-z]+)">', dom)
    assert ids == list(SECTIONS)  # document order
    # the texts are escaped, the inputs carry their hashes
    assert "m&lt;1&gt;.csv" in dom and "a &lt;b&gt; warning" in dom and "cd" * 32 in dom
    sim_sec = dom.split('<section id="simulation">')[1].split("</section>")[0]
    for label in ("Before", "none", "offset", "raw", "filtered"):
        assert "<th>%s</th>" % label in sim_sec
    assert "Profile error ISO 1101" in sim_sec


def test_images_are_embedded_pngs_that_decode(rendered):
    srcs = re.findall(r'<img alt="([^"]*)" src="([^"]*)"', rendered["dom"])
    assert len(srcs) == 5 + 3 + 1  # maps, histograms, simulation bar chart
    assert not re.search(r'src="(?!data:)', rendered["dom"])  # nothing loaded from outside
    for alt, src in srcs:
        assert src.startswith("data:image/png;base64,"), alt
        img = Image.open(io.BytesIO(base64.b64decode(src.split(",", 1)[1])))
        img.load()
        assert img.format == "PNG" and img.size[0] > 300 and img.size[1] > 200, alt
    maps = [a for a, _ in srcs if a.startswith("map of ")]
    assert maps == ["map of deviation", "map of determined", "map of random", "map of correction",
                    "map of residual"]


def test_screenshot_shows_the_colour_maps(rendered):
    a = np.asarray(Image.open(rendered["shot"]).convert("RGB")).astype(int)
    assert a.shape[:2] == (2600, 1200)
    nonwhite = np.mean(np.any(a < 245, axis=2))
    assert nonwhite > 0.10, nonwhite
    r, g, b = a[..., 0], a[..., 1], a[..., 2]
    red = np.mean((r > 150) & (g < 90) & (b < 90))       # rainbow positive end
    blue = np.mean((b > 120) & (r < 80) & (g < 130))      # rainbow negative end
    assert red > 0.002 and blue > 0.002, (red, blue)
    assert len(np.unique(a.reshape(-1, 3)[::37], axis=0)) > 200  # pictures, not only text


def test_predicted_residual_by_method():
    """d_f - s - delta, defined for every method: -random for raw and mirror (they copy the
    random scatter into the face), 0 for filtered, d_f - mean for offset; never all zero for
    mirror (issue 13)."""
    for method, stock in (("raw", None), ("mirror", 0.25)):
        arr = grid_arrays(_report(method, stock, n=7, build=False))
        assert_allclose(arr["residual"], -arr["random"], atol=1e-9)
        assert np.nanmax(np.abs(arr["residual"])) > 1e-4, method
    arr = grid_arrays(_report("filtered", n=7, build=False))
    assert_allclose(arr["residual"], 0.0, atol=1e-9)
    arr = grid_arrays(_report("offset", n=7, build=False))
    assert_allclose(arr["residual"], arr["determined"] - np.mean(arr["deviation"]), atol=1e-8)
    # the statistics section as the page holds it (render_html joins the sections; the
    # maps of the rest of the page are drawn by the other tests)
    from surfcomp.io import html_report

    rep = _report("mirror", 0.25, n=7, build=False)
    section = html_report._section_statistics(rep, grid_arrays(rep))
    assert "Expected RMS of the next part" in section


def test_an_iterations_report_predicts_the_residual_of_its_own_round(fresh_doc):
    """A second round's report holds the accumulated correction; its predicted residual is
    what this round's correction leaves, as the GUI's residual map and filter panel show it
    (raw: minus the random component), not d_f minus the accumulated correction."""
    import Part

    from surfcomp.app import features, reports
    from surfcomp.io import html_report
    from tests.conftest import ROOT

    examples = os.path.join(ROOT, "examples")
    EXAMPLE_CSV = os.path.join(examples, "measurements.csv")
    nom = fresh_doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(os.path.join(examples, "nominal.step"))
    first = features.make_compensation(fresh_doc, nom, "Face1",
                                       features.make_measurement(fresh_doc, EXAMPLE_CSV),
                                       method="raw")
    second = features.make_compensation(fresh_doc, nom, "Face1",
                                        features.make_measurement(fresh_doc, EXAMPLE_CSV),
                                        method="raw", base=first, name="Round2")
    fresh_doc.recompute()
    assert second.Round == 2 and "Invalid" not in second.State
    rep = reports.report_of(second)
    arr = grid_arrays(rep)
    assert np.nanmax(np.abs(arr["correction"] - arr["determined"])) > 0.02  # accumulated
    assert_allclose(arr["residual"], reports.quantity_values(second, "residual"), atol=1e-8)
    assert_allclose(arr["residual"], -arr["random"], atol=1e-8)
    section = html_report._section_statistics(rep, arr)
    want = reports.filter_summary(second)["next_part"] * 1e3
    assert "<span class=\"num\">%.2f µm</span>" % want in section


def test_maps_use_the_gui_scheme_and_range():
    """The report's maps use the GUI's rainbow (red at the top of the range) and, when the
    GUI passes its range, grey beyond it (colorbar arrows)."""
    from surfcomp.io import html_figures, html_report

    rep = _report("filtered", n=7, build=False)
    arr = grid_arrays(rep)
    fig = html_figures.map_figure(arr["x"], arr["y"], arr["deviation"] * 1e3, "d",
                                  style={"scheme": "rainbow", "range": (-1e-4, 1e-4)})
    mesh = fig.axes[0].collections[0]
    assert_allclose(mesh.cmap(1.0)[:3], (1, 0, 0))
    assert_allclose(mesh.cmap(0.5)[:3], (0, 1, 0), atol=0.01)
    assert_allclose(mesh.cmap.get_over()[:3], colormap.OUT_OF_RANGE_COLORS["above"])
    assert_allclose(mesh.get_clim(), (-0.1, 0.1))
    # the maps section as the page holds it (render_html joins the sections)
    maps = html_report._section_maps(arr, style={"scheme": "rainbow", "range": (-0.02, 0.02)})
    assert "range -20.0 .. 20.0 µm as in the GUI" in maps


def test_inspection_report_without_simulation_and_atomic_write(tmp_path):
    rep = _report("filtered", n=7, build=False)
    page = render_html(rep)
    assert '<section id="simulation">' not in page
    assert "No corrected face was built (inspect)" in page
    path = tmp_path / "r.html"
    path.write_text("old")
    write_html_report(str(path), rep)
    assert path.read_text() == page  # rendering is deterministic for one report dict
    assert os.listdir(tmp_path) == ["r.html"]  # no temporary file left


def test_preset_simulation_shows_the_papers_table_and_the_parts_maps():
    """A preset run: the paper's Tab. 3-4 figures beside the simulated ones in the same rows,
    the model's contents and omissions, and one map per simulated part."""
    res = presets.run_preset("mirror2019-s2", replicas=1, keep=True)
    page = render_html(_report(), dict(res.as_dict(), maps=simulation_maps(res)))
    assert re.findall(r'<section id="([a-z]+)">', page) == list(SECTIONS)
    side = page.split('<div id="side-by-side">')[1].split("</div>")[0]
    rows = dict(re.findall(r"<tr><th>([a-z-]+)</th>((?:<td[^>]*>[^<]*</td>){10})</tr>", side))
    cells = {k: re.findall(r">([^<]*)</td>", v) for k, v in rows.items()}
    assert list(cells) == ["none", "offset", "raw", "filtered", "semi-finished", "mirror"]
    assert cells["none"][:5] == ["17.2", "3.8", "-", "-", "52.3"]
    assert cells["mirror"][:5] == ["0.7", "1.5", "-", "-", "8.3"]
    assert cells["raw"][:5] == ["-"] * 5
    sim_none = res.side_rows("grid")["none"][1]
    assert cells["none"][5:7] == ["%.1f" % (sim_none[k] * 1e3) for k in ("mean", "std")]
    assert "What the model contains and leaves out" in page and "Left out: The correction" in page
    alts = re.findall(r'<img alt="simulated map of ([^"]*)" src="data:image/png;base64,([^"]*)"',
                      page)
    assert [a for a, _ in alts] == ["before", "none", "offset", "raw", "filtered",
                                    "semi-finished", "mirror"]
    for _, src in alts:
        img = Image.open(io.BytesIO(base64.b64decode(src)))
        img.load()
        assert img.format == "PNG" and img.size[0] > 300
    # without maps (the JSON alone) the section has the tables but no map block (the
    # section alone: the rest of the page is the same as above, its figures drawn once)
    from surfcomp.io import html_report

    bare = html_report._section_simulation(res.as_dict())
    assert bare.startswith('<section id="simulation">') and 'id="side-by-side"' in bare
    assert 'id="simulated-maps"' not in bare


def test_checks_state_the_poles_and_the_written_file_size(rendered):
    """The corrected face's checks give its poles, and the written file's size when there
    is one (``output_shape.file_bytes``, set when the job writes the face)."""
    # the fixture's page is that of _report() with no output shape, hence no file size
    assert "output_shape" not in rendered["report"]
    with open(rendered["path"], encoding="utf-8") as f:
        checks = f.read().split('<section id="checks">')[1].split("</section>")[0]
    assert "poles" in checks and "Written file size" not in checks
    rep = _report()
    rep["output_shape"] = {"kind": "face", "file_bytes": 238855}
    # the checks section as the page holds it (render_html joins the sections; the page
    # around it, its figures drawn, is the fixture's)
    from surfcomp.io import html_report

    checks = html_report._section_checks(rep).split('<section id="checks">')[1].split(
        "</section>")[0]
    assert "Written file size" in checks and "238855 bytes" in checks


def test_checks_are_in_words_not_python():
    """The checks name the corrected face's normal turn in a sentence and its counts and
    flags in words (the page showed the dict ``{'largest_normal_turn_deg': ...}``,
    ``[49, 49]`` and ``False``)."""
    from surfcomp.io import html_report

    rep = _report()
    rep["corrected_face"]["normal_turn"] = {
        "largest_normal_turn_deg": 0.20944, "folds": False, "at_mm": [25.5471, 39.8085, 4.6556],
        "at_uv": [0.6, 0.93], "folded_share": 0.0, "samples": 9409}
    rep["corrected_face"]["poles"] = [49, 49]
    rep["corrected_face"]["rational"] = False
    checks = html_report._section_checks(rep)
    assert "{" not in checks and "[" not in checks and "False" not in checks, checks
    assert ("0.209 deg at (25.547, 39.809, 4.656) mm; folds over itself: no (0 % of 9409 "
            "samples past the fold angle)") in checks
    assert "<th>poles</th><td>49 x 49</td>" in checks
    assert "<th>rational</th><td>no</td>" in checks
