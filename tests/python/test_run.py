"""airtwin.run_scenario against `airtwin run` on the same scenario and seed."""

import json
import os

import numpy as np
import pytest

import airtwin
from conftest import (CFD_AIR_EQ8, CFD_EQ8_KW, MIRROR, MIRROR_KW, SOURCE_DIR, assert_same_run,
                      expect_cli_error, run_cli)

LINE = os.path.join(SOURCE_DIR, "scenes/line.yaml")


def test_a_run_through_the_module_equals_the_cli_run(tmp_path):
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", LINE, "--seed", 2, *MIRROR, "--quiet", "--out", out)
    assert status == 0, stderr
    result = airtwin.run_scenario(LINE, 2, **MIRROR_KW)
    assert result.success and result.scenario == "line" and result.seed == 2

    # The same run: every frame, command and decision (decision_ms, a wall-clock time, aside).
    cli = assert_same_run(result, out)
    assert cli["success"] and result.completion_time_s == cli["completion_time_s"]
    assert result.n_decisions == cli["decisions"]
    assert result.lost_every_object is False and cli["lost_every_object"] is False

    def strip_ms(text):
        return [line.rsplit(",", 1)[0] for line in text.splitlines()]
    assert strip_ms(result.decisions_csv()) == strip_ms((out / "decisions.csv").read_text())

    # The trajectory as an array: the log's rows of the tracer, at full precision.
    track = result.trajectory("t1")
    assert track.shape[1] == 3 and np.all(np.diff(track[:, 0]) > 0)
    rows = [line.split(",") for line in result.log_csv().splitlines()[1:]]
    assert len(rows) == len(track)
    assert np.max(np.abs(track - np.array([[float(r[2]), float(r[3]), float(r[4])]
                                            for r in rows]))) <= 5e-7
    # The tracer went along the line, from its start to the far end's reference (4 cm).
    assert np.hypot(*(track[-1, 1:] - (0.26, 0.25))) < 0.04 + 1e-9
    with pytest.raises(ValueError, match="no object 't9'"):
        result.trajectory("t9")


def test_the_defaults_are_the_clis_the_physical_twin(tmp_path):
    """With no set-up both front ends run the physical twin (the CFD's air, physical drag), the
    controller planning with the field model fitted to the CFD and the models fitted to the
    twin (docs/twin.md): the same run to the byte, and another than the mirror's."""
    scenario = tmp_path / "line.yaml"
    scenario.write_text(open(LINE).read().replace("time_limit_s: 120", "time_limit_s: 4"))
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 1, "--quiet", "--out", out)
    assert status == 0, stderr
    result = airtwin.run_scenario(str(scenario), 1)
    assert result.log_csv() == (out / "log.csv").read_text()
    assert result.nozzle_csv() == (out / "nozzle.csv").read_text()
    models = os.path.join(SOURCE_DIR, "models/data/twin/extended_model.json")
    assert result.log_csv() == airtwin.run_scenario(str(scenario), 1, air="cfd", drag="physical",
                                                    models=[models]).log_csv()
    assert result.log_csv() != airtwin.run_scenario(str(scenario), 1, **MIRROR_KW).log_csv()


def test_planner_threads_give_the_same_run_as_the_cli(tmp_path):
    """The planner's threads, as --planner-threads: the same run as the CLI's and as one
    thread's; a count out of range is a ValueError naming it."""
    scenario = tmp_path / "line.yaml"
    scenario.write_text(open(LINE).read().replace("time_limit_s: 120", "time_limit_s: 6"))
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 3, "--planner-threads", 2, "--quiet",
                                "--out", out)
    assert status == 0, stderr
    result = airtwin.run_scenario(str(scenario), 3, planner_threads=2)
    assert result.log_csv() == (out / "log.csv").read_text()
    assert result.log_csv() == airtwin.run_scenario(str(scenario), 3).log_csv()
    with pytest.raises(ValueError, match="planner threads"):
        airtwin.run_scenario(str(scenario), 3, planner_threads=0)


def test_a_run_in_the_cfd_air_equals_the_cli_run(tmp_path):
    scenario = tmp_path / "line.yaml"
    scenario.write_text(open(LINE).read().replace("time_limit_s: 120", "time_limit_s: 8"))
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 1, *CFD_AIR_EQ8, "--quiet", "--out", out)
    assert status == 0, stderr
    result = airtwin.run_scenario(str(scenario), 1, cfd=airtwin.CfdField.read_dir(), **CFD_EQ8_KW)
    assert result.log_csv() == (out / "log.csv").read_text()
    assert result.nozzle_csv() == (out / "nozzle.csv").read_text()
    # Another air than the model's: the same run there goes elsewhere.
    assert result.log_csv() != airtwin.run_scenario(str(scenario), 1, **MIRROR_KW).log_csv()


def test_a_run_with_and_without_the_air_formation_equals_the_cli_run(tmp_path):
    scenario = tmp_path / "line.yaml"
    scenario.write_text(open(LINE).read().replace("time_limit_s: 120", "time_limit_s: 8"))
    cfd = airtwin.CfdField.read_dir()
    # The formation is on by default in the CFD's air; asking for it changes nothing.
    formed = airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW)
    assert formed.log_csv() == airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW,
                                                    air_formation=True).log_csv()
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 1, *CFD_AIR_EQ8,
                                "--no-air-formation", "--quiet", "--out", out)
    assert status == 0, stderr
    result = airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW, air_formation=False)
    assert result.log_csv() == (out / "log.csv").read_text()
    # The formation changes the air after every re-aim: the same run with it goes elsewhere.
    assert result.log_csv() != formed.log_csv()
    # Asked for in the model's air: an error in both front ends.
    with pytest.raises(ValueError, match="air_formation"):
        airtwin.run_scenario(str(scenario), 1, air="model", air_formation=True)
    status, _, stderr = run_cli("run", scenario, "--seed", 1, *MIRROR, "--air-formation", "--out",
                                tmp_path / "bad")
    assert status != 0 and "--air-formation needs --air cfd" in stderr


def test_the_integrator_and_the_formation_time_scale_equal_the_cli_run(tmp_path):
    scenario = tmp_path / "line.yaml"
    scenario.write_text(open(LINE).read().replace("time_limit_s: 120", "time_limit_s: 4"))
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 1, *CFD_AIR_EQ8,
                                "--air-formation-time-scale", 0.25, "--integrator", "implicit",
                                "--quiet", "--out", out)
    assert status == 0, stderr
    cfd = airtwin.CfdField.read_dir()
    result = airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW, air_formation_time_scale=0.25,
                                  integrator="implicit")
    assert result.log_csv() == (out / "log.csv").read_text()
    # Each changes the run: the same without either goes elsewhere.
    assert result.log_csv() != airtwin.run_scenario(
        str(scenario), 1, cfd=cfd, **CFD_EQ8_KW, integrator="implicit").log_csv()
    assert result.log_csv() != airtwin.run_scenario(
        str(scenario), 1, cfd=cfd, **CFD_EQ8_KW, air_formation_time_scale=0.25).log_csv()
    with pytest.raises(ValueError, match="integrator: expected euler or implicit, got 'rk4'"):
        airtwin.run_scenario(str(scenario), 1, integrator="rk4")
    with pytest.raises(ValueError, match="air_formation_time_scale"):
        airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW, air_formation=False,
                             air_formation_time_scale=0.25)
    with pytest.raises(ValueError, match="formation_time_scale"):
        airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW, air_formation_time_scale=-1.0)


def test_the_front_of_still_air_equals_the_cli_run(tmp_path):
    """air_front_co_flow 0 is --air-front-co-flow 0 to the byte, and changes the run (the line's
    re-aims meet moving air); bad weights name the keyword, and need the CFD's air."""
    scenario = tmp_path / "line.yaml"
    scenario.write_text(open(LINE).read().replace("time_limit_s: 120", "time_limit_s: 4"))
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 1, *CFD_AIR_EQ8,
                                "--air-front-co-flow", 0, "--quiet", "--out", out)
    assert status == 0, stderr
    cfd = airtwin.CfdField.read_dir()
    still = airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW, air_front_co_flow=0.0)
    assert still.log_csv() == (out / "log.csv").read_text()
    assert still.log_csv() != airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW).log_csv()
    with pytest.raises(ValueError, match="air_front_counter_flow: expected \\[0, 2\\]"):
        airtwin.run_scenario(str(scenario), 1, cfd=cfd, **CFD_EQ8_KW, air_front_counter_flow=3.0)
    with pytest.raises(ValueError, match="air_front_co_flow: the carried front needs the CFD"):
        airtwin.run_scenario(str(scenario), 1, air="model", air_front_co_flow=0.5)
    status, _, stderr = run_cli("run", scenario, "--seed", 1, *MIRROR, "--air-front-co-flow", 0.5,
                                "--out", tmp_path / "bad")
    assert status != 0 and "--air-front-co-flow and --air-front-counter-flow need --air cfd" \
        in stderr


def test_the_lagrangian_turbulence_equals_the_cli_run(tmp_path):
    """air_turbulence_swept=False is --no-air-turbulence-swept to the byte in the physical twin,
    planning with the models fitted to that twin as the CLI does; it changes the run; True is
    the default's and needs the CFD's air."""
    scenario = tmp_path / "line.yaml"
    scenario.write_text(open(LINE).read().replace("time_limit_s: 120", "time_limit_s: 4"))
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 1, "--no-air-turbulence-swept",
                                "--quiet", "--out", out)
    assert status == 0, stderr
    lagrangian = airtwin.run_scenario(str(scenario), 1, air_turbulence_swept=False)
    assert lagrangian.log_csv() == (out / "log.csv").read_text()
    default = airtwin.run_scenario(str(scenario), 1).log_csv()
    assert lagrangian.log_csv() != default
    assert airtwin.run_scenario(str(scenario), 1, air_turbulence_swept=True).log_csv() == default
    with pytest.raises(ValueError, match="air_turbulence_swept: needs the CFD's air"):
        airtwin.run_scenario(str(scenario), 1, air="model", air_turbulence_swept=True)


def test_a_bad_scenario_raises_value_error_with_the_cli_message(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(open(LINE).read().replace("kind: path", "kind: paths"))
    message = expect_cli_error(lambda: airtwin.run_scenario(str(bad), 1), "run", bad, "--seed", 1,
                               "--out", tmp_path / "r")
    assert "task.kind" in message


def test_a_run_with_the_controllers_models_equals_the_cli_run(tmp_path):
    # An identified tracer model (Appendix D trials in the twin) and the CFD-fitted field model.
    data, model = tmp_path / "data.csv", tmp_path / "tracer.json"
    table = os.path.join(SOURCE_DIR, "models/data/cfd_fitted_field_model.json")
    for args in (("collect", "--object", "tracer", "--tilts", "22.5,45", "--per-tilt", 6,
                  "--seed", 1, *MIRROR, "--out", data),
                 ("identify", data, "--object", "tracer", "--terms", "1,v,vair", "--out", model)):
        status, _, stderr = run_cli(*args)
        assert status == 0, stderr
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", LINE, "--seed", 1, *MIRROR, "--model", model, "--table",
                                table, "--quiet", "--out", out)
    assert status == 0, stderr
    result = airtwin.run_scenario(LINE, 1, models=[str(model)], table=table, **MIRROR_KW)
    assert_same_run(result, out)
    # Other models, another run.
    assert result.log_csv() != airtwin.run_scenario(LINE, 1, **MIRROR_KW).log_csv()
    # An unreadable model: the CLI's line.
    missing = tmp_path / "missing.json"
    expect_cli_error(lambda: airtwin.run_scenario(LINE, 1, models=[str(missing)]), "run", LINE,
                     "--model", missing, "--out", tmp_path / "r")


def test_varied_objects_equal_the_cli_run(tmp_path):
    scenario = tmp_path / "line.yaml"
    scenario.write_text(open(LINE).read().replace("time_limit_s: 120", "time_limit_s: 8"))
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 1, "--vary-physics", "0.2", "--quiet",
                                "--out", out)
    assert status == 0, stderr
    cfd = airtwin.CfdField.read_dir()
    result = airtwin.run_scenario(str(scenario), 1, cfd=cfd, vary_physics="0.2")
    assert result.log_csv() == (out / "log.csv").read_text()
    summary = json.loads(result.summary_json())
    cli = json.loads((out / "summary.json").read_text())
    assert summary["physics_variation"] == "0.2"
    assert summary["object_physics"] == cli["object_physics"]
    assert summary["object_physics"]["t1"].startswith("tracer:mass_g=")
    # The type's own tracer runs elsewhere, and its record lists no object physics.
    plain = airtwin.run_scenario(str(scenario), 1, cfd=cfd)
    assert plain.log_csv() != result.log_csv()
    assert "object_physics" not in json.loads(plain.summary_json())
    with pytest.raises(ValueError, match="vary_physics.*'0.7'"):
        airtwin.run_scenario(str(scenario), 1, cfd=cfd, vary_physics="0.7")
