# SPDX-License-Identifier: LGPL-2.1-or-later
"""Messages of a whole job (``surfcomp.Job``, a job file) name its files as the job's keys
(``output``, ``report``, ``plan``), and the command line shows the same messages with its
flags (``-o``, ``--report``, ``--plan``) and argument names (``NOMINAL``)."""

import pytest

from surfcomp.app.file_route import (
    OUTPUT_OPTIONS,
    Job,
    cad_format,
    declared_inputs,
    declared_outputs,
    read_measured,
)
from surfcomp.cli.option_flags import shown
from surfcomp.errors import InputError
from surfcomp.io.atomic import check_outputs


def _refused(outputs, inputs):
    with pytest.raises(InputError) as exc:
        check_outputs(outputs, inputs)
    return exc.value


def test_output_over_an_input_names_the_job_keys_and_the_flags(tmp_path):
    meas = tmp_path / "m.csv"
    meas.write_text("x\n")
    job = Job(nominal=str(tmp_path / "n.step"), measurements=str(meas), report=str(meas))
    err = _refused(declared_outputs(job), declared_inputs(job))
    assert err.message == ("report would overwrite the input measurements %s; nothing was "
                           "written" % meas)
    assert shown(err) == ("%s: --report would overwrite the input MEASUREMENTS %s; nothing "
                          "was written" % (meas, meas))


def test_two_outputs_on_one_file_or_standard_output(tmp_path):
    job = Job(nominal="n.step", measurements="m.csv", output=str(tmp_path / "a.step"),
              curves=str(tmp_path / "a.step"))
    err = _refused(declared_outputs(job), [])
    assert err.message == "output and curves name the same file; give each output its own name"
    assert "-o and --curves name the same file" in shown(err)
    job = Job(nominal="n.step", measurements="m.csv", report="-", html="-")
    err = _refused(declared_outputs(job), [])
    # the word "output" of "standard output" is prose, not the option
    assert err.message.startswith("report and html name the same standard output;")
    assert shown(err).startswith("-: --report and --html name the same standard output;")


def test_an_unreachable_folder_names_the_key(tmp_path):
    job = Job(nominal="n.step", measurements="m.csv", points=str(tmp_path / "no" / "p.csv"))
    err = _refused(declared_outputs(job), [])
    assert err.message.startswith("points cannot be written: its folder")
    assert shown(err).startswith("%s: --points cannot be written" % (tmp_path / "no" / "p.csv"))


def test_cad_file_type_names_the_key():
    with pytest.raises(InputError) as exc:
        cad_format("c.txt", dict(OUTPUT_OPTIONS)["output"])
    assert exc.value.message == "output: unsupported file type '.txt' (expected .step, " \
                                ".iges or .brep)"
    assert shown(exc.value) == "c.txt: -o: unsupported file type '.txt' (expected .step, " \
                               ".iges or .brep)"


def test_touches_without_a_plan_names_both_options(tmp_path):
    with pytest.raises(InputError) as exc:
        read_measured(Job(nominal="n.step", measurements=str(tmp_path / "log"), touches=2))
    assert str(exc.value) == "touches applies to a probe log read with a measurement plan (plan)"
    assert shown(exc.value) == ("--touches applies to a probe log read with a measurement "
                                "plan (--plan)")
