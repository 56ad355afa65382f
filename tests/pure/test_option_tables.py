# SPDX-License-Identifier: LGPL-2.1-or-later
"""The option registry's other tables (surfcomp.core.option_tables: the job's inputs, the
alignment, the plan, the probing program, the machining model) are the one place those
options are defined: the command-line parsers, the job file, the dataclasses' defaults and
the modules' choices agree with them (the document properties:
tests/app/test_option_tables.py; the panels: tests/gui/test_plan_gui.py, test_filter.py).
Warnings below the command line name options, and each front end shows them its way."""

import dataclasses
import subprocess
import sys

import pytest

from surfcomp.cli import build_parser
from surfcomp.cli.option_flags import flag, shown
from surfcomp.core.option_tables import ALIGN, INPUTS, MODEL, PLAN, PROGRAM, TABLES, find
from surfcomp.core.options import OPTIONS, cli_help
from surfcomp.errors import note
from tests.conftest import ROOT


def _actions(command):
    sub = next(a for a in build_parser(command)._actions if a.choices and command in a.choices)
    return {a.option_strings[0] if a.option_strings else a.dest: a
            for a in sub.choices[command]._actions}


def _agrees(action, name, table, default=True):
    o = table[name]
    assert action.help == cli_help(name, table), name
    assert action.dest == o.arg, name
    assert action.choices == o.choices, name
    if default:
        assert action.default == (False if o.type is bool else o.default), name
    if o.metavar:
        assert action.metavar == o.metavar, name


def test_the_tables_import_without_numpy():
    code = ("import sys; sys.modules['numpy'] = sys.modules['scipy'] = None; "
            "sys.path.insert(0, %r); from surfcomp.core.option_tables import TABLES; "
            "print(*(len(t) for t in TABLES.values()))" % ROOT)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0, out.stderr
    assert [int(n) for n in out.stdout.split()] == [15, 7, 5, 10, 10, 14, 7, 4, 3, 10, 5, 5]
    assert TABLES["compensation"] is OPTIONS


@pytest.mark.parametrize("command", ["compensate", "inspect"])
def test_the_job_parsers_take_inputs_and_alignment_from_the_registry(command):
    acts = _actions(command)
    for table in (INPUTS, ALIGN):
        for name, o in table.items():
            _agrees(acts[o.flag], name, table)
    # the contract: flags and attributes as before
    assert (acts["--format"].dest, acts["--format"].default) == ("fmt", "auto")
    assert acts["--align"].choices == ("none", "bestfit", "rps")
    assert acts["--align-dof"].default is None and acts["--touches"].default == 1


def test_simulate_takes_the_model_and_the_alignment_from_the_registry():
    acts = _actions("simulate")
    for name in ("align", "align_dof", "rps", "transform"):
        _agrees(acts[ALIGN[name].flag], name, ALIGN)
    for name in ("face", "object"):
        _agrees(acts[INPUTS[name].flag], name, INPUTS)
    for name, o in MODEL.items():
        a = acts[o.flag]
        # the preset's value applies when the option is not given: no parser default
        assert (a.dest, a.metavar, a.default) == (name, o.metavar, None), name
        assert a.help.startswith(o.help + " (default "), name
    assert acts["--tilt"].help.endswith("(default 0,0.02, or the preset's)")
    assert acts["--semi-engagement"].help.endswith("(default the stock, or the preset's)")


def test_plan_takes_the_plan_and_the_program_from_the_registry():
    acts = _actions("plan")
    for table in (PLAN, PROGRAM):
        for name, o in table.items():
            _agrees(acts[o.flag], name, table)
    for name in ("face", "object"):
        _agrees(acts[INPUTS[name].flag], name, INPUTS)
    assert (acts["--format"].dest, acts["--probe-log"].dest) == ("plan_format", "probe_log")
    args = build_parser("plan").parse_args(["plan", "n.step", "-o", "p.csv"])
    from surfcomp.cli import plan, plan_program

    assert plan.settings_from_args(args) == plan.PlanSettings()
    assert plan.layout_count(args) == ("grid", (10, 10))
    assert plan_program.settings_from_args(args, 0.0, "") == \
        plan_program.ProbeSettings(safe_z=0.0)


def test_the_dataclasses_default_to_the_registry():
    from surfcomp.core.measurement.planning import PlanSettings
    from surfcomp.core.simulation.process_model import MachiningModel
    from surfcomp.io.probe_path import ProbeSettings

    for f in dataclasses.fields(PlanSettings):
        assert f.default == PLAN[f.name].default, f.name
    probe = {f.name: f.default for f in dataclasses.fields(ProbeSettings)}
    for name, o in PROGRAM.items():
        assert probe[name] == o.default, name
    for name, plan_name in (("tip_radius", "tip_radius"), ("clearance", "clearance"),
                            ("stand_off", "stand_off")):
        assert probe[name] == PLAN[plan_name].default, name
    model = {f.name: f.default for f in dataclasses.fields(MachiningModel)}
    for name, o in MODEL.items():
        assert model[name] == o.default, name
    assert MachiningModel().tilt == (0.0, 0.02)            # the documented Werner-like case


def test_the_modules_choices_are_the_registry():
    from surfcomp.core.measurement import align_report, planning
    from surfcomp.io import plan_file, probe_path

    assert align_report.METHODS == ALIGN["align"].choices
    assert planning.LAYOUTS == PLAN["layout"].choices
    assert planning.ORDERS == PLAN["order"].choices
    assert plan_file.PLAN_FORMATS == PLAN["plan_format"].choices
    assert probe_path.DIALECTS == PROGRAM["dialect"].choices
    assert probe_path.WORK_OFFSETS == PROGRAM["work_offset"].choices
    assert planning.MAX_POINTS == PLAN["points"].high


@pytest.mark.parametrize("name, value", [("points", 0), ("points", PLAN["points"].high + 1),
                                         ("max_tilt", -1.0), ("max_tilt", 90.5)])
def test_the_plan_refuses_just_outside_the_registry_domain(name, value):
    from surfcomp.core.measurement.planning import PlanSettings, check_points
    from surfcomp.errors import InputError

    o = PLAN[name]
    check = check_points if name == "points" else lambda v: PlanSettings(max_tilt=v).check()
    check(o.low)
    check(o.high)
    with pytest.raises(InputError) as exc:
        check(value)
    assert exc.value.options == (name,) and shown(exc.value).startswith(o.flag + " ")


def test_the_job_file_checks_inputs_and_alignment_by_their_registry_type():
    from surfcomp.io.jobfile import KEY_TYPES, NULLABLE

    for table in (INPUTS, ALIGN):
        for name, o in table.items():
            what, ok = KEY_TYPES[name]
            assert (name in NULLABLE) == o.optional, name
            if name == "align":
                assert what == 'one of "none", "bestfit", "rps"'
                assert all(ok(c) for c in o.choices) and not ok("best")
            elif name == "transform":
                assert what == "a file name (a non-empty string)"
            else:
                assert what == {int: "a whole number", str: "a non-empty string"}[o.type], name


def test_every_name_maps_to_its_flag():
    for table in TABLES.values():
        for name, o in table.items():
            if o.flag and find(name) is o:
                assert flag(name) == o.flag, name
    assert (flag("fmt"), flag("plan_format"), flag("log_file"), flag("align_faces")) == \
        ("--format", "--format", "--probe-log", "--align-faces")
    assert flag("lean") == "lean"                 # job files only
    # every option a panel or a property names has a label, a property or both
    for table in (ALIGN, PLAN):
        for name, o in table.items():
            assert o.label or o.prop is None, name


def test_help_names_other_options_as_each_front_end_does():
    from surfcomp.core.options import tooltip

    assert "3-2-1 on the points of --rps" in cli_help("align", ALIGN)
    assert "3-2-1 on the points of AlignRps" in tooltip("align", ALIGN)
    assert cli_help("second_feed", PROGRAM).endswith("(default a fifth of --touch-feed)")
    assert cli_help("align_dof", ALIGN).endswith("(default all)")
    # the property holds the file's content: its own text
    assert tooltip("transform", ALIGN).startswith("Known rigid transform applied first: 16")


# ------------------------------------------------------------------ warnings name options
def test_a_note_is_the_plain_string_everywhere_else():
    import json
    import pickle

    text = note("a larger ", ("refine",), " helps (refine: the knot spans)")
    assert text == "a larger refine helps (refine: the knot spans)"
    assert json.dumps([text]) == '["a larger refine helps (refine: the knot spans)"]'
    assert pickle.loads(pickle.dumps(text)).refs == text.refs == ((9, 15, "refine"),)
    prefixed = "part.csv:3: " + text + note("; see ", ("layout",))
    assert prefixed.options == ("refine", "layout")
    # only the places that name the option: the same word in the prose stays
    assert shown(prefixed) == \
        "part.csv:3: a larger --refine helps (refine: the knot spans); see --layout"
    assert shown("a plain refine") == "a plain refine"
    # a place already in a reader's words stays (a document's warning)
    doc = note("a larger ", ("refine", "the compensation's Refine"), " helps")
    assert shown(doc) == "a larger the compensation's Refine helps"


def test_reader_warnings_name_options_and_the_command_line_shows_flags(tmp_path):
    from surfcomp.io.readers import read_any

    path = tmp_path / "inch.xyz"
    path.write_text("x[in] y[in] z[in]\n0 0 0\n1 0 0\n0 1 0\n")
    ms = read_any(str(path), units="mm", fmt="xyz")
    (warning,) = [w for w in ms.warnings if "the file states its units" in w]
    assert warning.options == ("units",) and "--" not in warning
    assert "(in); units mm applies only to values without units of their own" in warning
    assert "(in); --units mm applies only to values without units of their own" in \
        shown(warning)


def test_the_qif_sample_warning_shows_the_flag():
    import os

    from surfcomp.io.readers import read_any

    ms = read_any(os.path.join(ROOT, "tests", "data", "pointfiles", "two_parts_inch.qif"))
    (warning,) = [w for w in ms.warnings if "measured parts" in w]
    assert warning.endswith("choose another with sample") and warning.options == ("sample",)
    assert shown(warning).endswith("choose another with --sample")


def test_the_alignment_warnings_name_options():
    import numpy as np

    from surfcomp.core.measurement.align_report import _absorbed_warning

    far = _absorbed_warning({}, np.array([[0.0, 0, 1]]), np.array([[0.0, 0, 2]]))
    near = _absorbed_warning({"mean_offset_um": 3.0, "tilt_um": 1.0},
                             np.array([[0.0, 0, 1]]), np.array([[0.0, 0, 0.1]]))
    assert "near with transform, or name datum faces with align_faces" in far
    assert "near with --transform, or name datum faces with --align-faces" in shown(far)
    assert shown(near).endswith("(name datum faces with --align-faces to keep it)")
    # what it absorbed may be the points' frame as much as machining error: said so
    assert ("absorbed a mean offset of 3.000 um and a tilt of 1.000 um, of the machining "
            "error or of the points' frame (the fit cannot tell them apart)") in near


def test_the_readme_model_table_is_the_registry():
    """README's table of the machining-process model lists each model option of the
    registry with its flag, metavar and default."""
    import os
    import re

    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as fh:
        text = fh.read()
    table = text[text.index("| term | option | default |"):]
    table = table[:table.index("\n\n")]
    listed = {}
    for row in table.splitlines()[2:]:
        _term, options, defaults = (c.strip() for c in row.strip("|").split("|"))
        flags = re.findall(r"`(--[a-z-]+) ([^`]+)`", options)
        values = re.split(r"[;]\s*|,\s(?=\d)", defaults) if len(flags) > 1 else [defaults]
        for (flag_, metavar), value in zip(flags, values):
            listed[flag_] = (metavar, value.split(" ")[0])

    def shown_default(o):
        if o.default is None:
            return "the"                                   # "the stock"
        if o.type is tuple:
            return ",".join("%g" % x for x in o.default)
        return "%g" % o.default

    for name, o in MODEL.items():
        assert listed[o.flag] == (o.metavar, shown_default(o)), name
