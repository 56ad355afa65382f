# SPDX-License-Identifier: LGPL-2.1-or-later
"""What the command line's help and the docs say about the options is what the parsers and
the option registry take: the options a command's help names are that command's, and the
values the README and docs give an option lie in the registry's domain."""

import glob
import os
import re

from surfcomp.cli import build_parser
from surfcomp.core.options import OPTIONS
from tests.conftest import ROOT

#: flags a command's help names although the command has no such option: another
#: command's option it refers to (``plan --second-touch`` writes the logs that
#: ``--touches`` reads) or a value (the post-processor's argument)
OTHER_COMMANDS = {("compensate", "--second-touch"), ("inspect", "--second-touch"),
                  ("plan", "--touches"), ("compensate", "--no-show-editor")}

_FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def _parsers():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.choices and "compensate" in a.choices)
    return sub.choices


def _texts(parser):
    """Every help text of ``parser``: the options', the groups', description and epilog."""
    for a in parser._actions:
        yield (a.option_strings or [a.dest])[0], a.help or ""
    for g in parser._action_groups:
        yield g.title, g.description or ""
    yield "description", parser.description or ""
    yield "epilog", parser.epilog or ""


def test_the_help_names_the_commands_own_options():
    """inspect's --weights said its default was --mask-kind and --mask, and simulate's
    --mask-kind spoke of custom --weights: neither command has that option."""
    wrong = []
    for command, parser in _parsers().items():
        own = {s for a in parser._actions for s in a.option_strings}
        for where, text in _texts(parser):
            wrong += [(command, where, flag) for flag in _FLAG.findall(text)
                      if flag not in own and (command, flag) not in OTHER_COMMANDS]
    assert not wrong


def _docs():
    """README and docs/*.md but the benchmarks (whose flags are the bench scripts')."""
    paths = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs",
                                                                              "*.md")))
    return [p for p in paths if not p.endswith("benchmarks.md")]


def test_the_docs_give_the_compensation_options_values_in_their_domain():
    """README said '--smoothing 0 switches it off': the registry's domain starts at 0.001 mm,
    and the run is refused."""
    numeric = {o.flag: o for o in OPTIONS.values() if o.flag and o.low is not None}
    outside = []
    for path in _docs():
        with open(path, encoding="utf-8") as fh:
            for number, line in enumerate(fh, 1):
                if "bench/" in line:
                    continue
                for flag, value in re.findall(r"(--[a-z-]+)[ =](-?\d[\d.]*(?:e-?\d+)?)\b", line):
                    o = numeric.get(flag)
                    if o is not None and not o.low <= float(value) <= o.high:
                        outside.append((os.path.basename(path), number, flag, value))
    assert not outside


def test_inspect_takes_the_filter_options_its_determined_component_needs():
    """inspect's --weights help named --mask-kind, which inspect did not have: its
    determined component could not be compensate's with a Gaussian mask or another edge."""
    from surfcomp.cli.common import options_from_args

    args = build_parser("inspect").parse_args(
        ["inspect", "n.step", "m.csv", "--mask", "7", "--mask-kind", "gaussian", "--sigma",
         "1.5", "--edge", "nearest"])
    o = options_from_args(args)
    assert (o.mask_size, o.mask_kind, o.sigma, o.edge) == (7, "gaussian", 1.5, "nearest")


def test_the_faces_help_says_what_smoothing_is_for_a_region():
    """With --faces, --smoothing is the correction field's radius, by default the larger of
    4 point spacings and 5 % of the shape's diagonal (surfcomp.app.region_route); the help
    only gave the one-face meaning, a fit whose default cross-validation chooses."""
    from surfcomp.core import limits
    from surfcomp.core.command_options import COMPENSATE
    from surfcomp.core.options import cli_help

    text = " ".join(cli_help("faces", COMPENSATE).split())
    assert ("--smoothing is then the radius in mm of the correction field (default the "
            "larger of %g point spacings and %g x the shape's diagonal)"
            % (limits.FIELD_SPACINGS, limits.FIELD_SHARE)) in text
    assert (limits.FIELD_SPACINGS, limits.FIELD_SHARE) == (4.0, 0.05)


def test_the_document_route_refuses_touches_it_would_not_read(tmp_path, capsys):
    """--touches K (probe moves per point of a log read with --plan) was taken and ignored
    on the shop-document route, which refuses --plan."""
    from surfcomp.cli import main

    doc = tmp_path / "shop.FCStd"
    doc.write_bytes(b"not read")
    rc = main(["compensate", str(doc), os.path.join(ROOT, "examples", "measurements.csv"),
               "--object", "Part", "--save", str(tmp_path / "out.FCStd"), "--touches", "2"])
    assert rc == 2
    assert "--touches reads a probe log with --plan" in capsys.readouterr().err
    assert not (tmp_path / "out.FCStd").exists()


def test_the_axis_docs_give_the_reference_default_the_code_uses(tmp_path, capsys):
    """docs/axis_errors.md said --reference defaults to the program zero: it is 0,0,0 in the
    error file's coordinates, which --work-offset moves away from the program zero (the
    program below comes out as with --reference 0,0,0, not as with the program zero)."""
    from surfcomp.cli import main
    from surfcomp.core.command_options import GCODE

    err = tmp_path / "err.csv"
    err.write_text("axis,position,ex,ey,ez\nX,0,0,0,0\nX,100,0.01,0.002,0\nX,200,0.03,0.001,0\n"
                   "X,300,0.02,0.004,0.001\nY,0,0,0,0\nY,100,0.001,-0.01,0\n"
                   "Y,200,0.003,-0.03,0.002\nY,300,0.001,-0.02,0.001\n")
    program = tmp_path / "p.ngc"
    program.write_text("G21 G90\nG0 X0 Y0 Z5\nG1 X50 Y20 Z0 F100\nG1 X80 Y60\n")

    def out(*extra):
        path = tmp_path / ("out%d.ngc" % len(list(tmp_path.iterdir())))
        assert main(["gcode", str(program), "--axis-errors", str(err), "--model", "quadratic",
                     "--work-offset", "100,50,0", "-o", str(path), *extra]) == 0
        capsys.readouterr()
        return path.read_text()

    default = out()
    assert default == out("--reference", GCODE["reference"].default)
    assert default != out("--reference", "100,50,0")            # the program zero
    with open(os.path.join(ROOT, "docs", "axis_errors.md"), encoding="utf-8") as fh:
        text = " ".join(fh.read().split())
    said = re.findall(r"\(`--reference`[^)]*?default ([^ ,;)]+(?:,[^ ,;)]+)*)", text)
    assert said == [GCODE["reference"].default]


def test_plan_says_which_layouts_take_points():
    """--points N is the count of the adaptive and the uniform layout (its help says so);
    the refusal with a grid said the adaptive layout alone took it."""
    import pytest

    from surfcomp.cli.plan import layout_count
    from surfcomp.errors import InputError

    args = build_parser("plan").parse_args(["plan", "n.step", "-o", "p.csv", "--points", "50"])
    with pytest.raises(InputError) as exc:
        layout_count(args)
    assert exc.value.message.startswith("--points applies to the adaptive and uniform layouts;")
    args.layout = "uniform"
    assert layout_count(args) == ("uniform", 50)
