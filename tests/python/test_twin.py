"""airtwin.Twin and airtwin.Scenario against `airtwin run` and `airtwin render` on the same
scenario and seed."""

import csv
import os
import threading

import numpy as np
import pytest

import airtwin
from conftest import CONSTRUCTED, MIRROR, MIRROR_KW, SOURCE_DIR, expect_cli_error, run_cli

OCTAGON = os.path.join(SOURCE_DIR, "scenes/octagon.yaml")


def short_copy(tmp_path, scenario, time_limit_s):
    """The scenario with a shorter time limit, to keep the CLI's run to a few seconds."""
    text = open(scenario).read()
    path = tmp_path / os.path.basename(scenario)
    path.write_text(text.replace("time_limit_s: 450", f"time_limit_s: {time_limit_s}"))
    return str(path)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_scenario_loads_the_file():
    scenario = airtwin.Scenario.load(OCTAGON)
    assert scenario.name == "octagon" and scenario.ids == ["t1", "t2", "t3", "t4"]
    assert scenario.types == ["tracer"] * 4 and scenario.time_limit_s == 450
    assert np.array_equal(scenario.positions, [[0.275, -0.025], [0.325, -0.025],
                                               [0.275, 0.025], [0.325, 0.025]])


def test_replaying_a_runs_commands_gives_its_trajectories(tmp_path):
    """`airtwin run` logs every camera frame's truth and the commands it sent: the same commands
    sent through the module move the objects the same way. In the model's air only: in the CFD's,
    a 1e-6 deg change of the start orientation moves these objects by 10 mm within 6 s, so the
    files' printed angles cannot replay it (test_run.py compares a CFD run exactly)."""
    scenario = short_copy(tmp_path, OCTAGON, 6)
    out = tmp_path / "run"
    # The constructed table's air: in the default model's, the upstream air is too weak for the
    # first decisions to move these objects within the 6 s.
    status, _, stderr = run_cli("run", scenario, "--seed", 3, *MIRROR, "--table", CONSTRUCTED,
                                "--quiet", "--out", out)
    assert status == 0, stderr
    commands = [(float(r["t"]), float(r["pan_deg"]), float(r["tilt_deg"]))
                for r in read_csv(out / "nozzle.csv")]
    log = read_csv(out / "log.csv")
    assert len(commands) > 2  # the controller decided several times

    # The log's pan_deg, tilt_deg: the command in force at each frame; at t = 0 the start
    # orientation (the servos at rest there), before the first decision's command.
    frames = sorted({float(r["t"]) for r in log})

    def replay(offset_deg, check_log):
        """Positions at every frame with `offset_deg` added to every angle sent."""
        twin = airtwin.Twin(scenario, 3, float(log[0]["pan_deg"]) + offset_deg,
                            float(log[0]["tilt_deg"]) + offset_deg,
                            field=airtwin.Field.constructed(), **MIRROR_KW)
        assert twin.ids == ["t1", "t2", "t3", "t4"]
        pending = list(commands)
        positions = []
        for t in frames:
            twin.advance_to(t)
            states = twin.states()
            positions.append(states[:, :2].copy())
            # The frame at a decision's time is taken before its command is sent.
            truth = {r["traj"]: r for r in log if float(r["t"]) == t}
            for object_id in twin.ids if check_log else []:
                assert np.allclose(twin.commanded_deg, (float(truth[object_id]["pan_deg"]),
                                                     float(truth[object_id]["tilt_deg"])),
                                   rtol=0, atol=1e-6)
            while pending and pending[0][0] <= t + 1e-9:
                twin.command(pending[0][1] + offset_deg, pending[0][2] + offset_deg)
                pending.pop(0)
        assert not pending
        return twin, np.array(positions)

    twin, replayed = replay(0.0, True)
    ids = twin.ids
    logged = np.array([[[float(r["x"]), float(r["y"])] for i in ids for r in log
                        if float(r["t"]) == t and r["traj"] == i] for t in frames])
    worst = np.max(np.abs(replayed - logged))
    # Not to the last bit: the files print angles to 1e-6 deg. Before the tracers touch (~2.4 s)
    # the replay agrees within 1e-6 m; from then on the contact amplifies any 1e-6 deg change of
    # the angles to millimetres (measured: 4.8 mm for the replay, 1.8-3.1 mm for every angle
    # moved by +-1e-6 deg). So the replay's error is bounded by what the files' precision alone
    # does to the run: three times the larger of those two shifts (a wrong command or time gives
    # centimetres).
    shifted = max(np.max(np.abs(replay(d, False)[1] - replayed)) for d in (1e-6, -1e-6))
    print(f"replay against the log: {worst:.2e} m; angles moved by 1e-6 deg: {shifted:.2e} m")
    assert worst <= max(2e-5, 3.0 * shifted)
    moved = np.hypot(*(twin.states()[:, :2] - airtwin.Scenario.load(scenario).positions).T)
    assert np.max(moved) > 0.01  # the air moved them


def test_reset_starts_over_to_the_last_bit():
    twin = airtwin.Twin(OCTAGON, 5, 30.0, 20.0)
    start = twin.states()
    first = [twin.step(40.0, 25.0, 0.1) for _ in range(10)]
    assert twin.time_s == pytest.approx(1.0, abs=1e-12)
    twin.reset()
    assert twin.time_s == 0.0 and np.array_equal(twin.states(), start)
    again = [twin.step(40.0, 25.0, 0.1) for _ in range(10)]
    assert all(np.array_equal(a, b) for a, b in zip(first, again))
    fresh = airtwin.Twin(OCTAGON, 5, 30.0, 20.0)
    fresh.advance_to(1.0)
    assert not np.array_equal(fresh.states(), again[-1])  # the command made a difference
    # Settling moves the placed objects by less than ~1 mm (docs/twin.md).
    assert np.max(np.abs(start[:, :2] - airtwin.Scenario.load(OCTAGON).positions)) < 1e-3
    assert start.shape == (4, 4) and start.dtype == np.float64


def test_poses_say_how_the_objects_sit():
    # Settled tracers lie on their flat face: the root bodies at the states' x, y (a tracer is
    # one body), their origins (the face's centre) on the floor within MuJoCo's soft contact's
    # fraction of a millimetre, turned about z alone.
    twin = airtwin.Twin(OCTAGON, 5, 30.0, 20.0, jet_on=False)
    poses, states = twin.poses(), twin.states()
    assert poses.shape == (4, 7) and poses.dtype == np.float64
    np.testing.assert_allclose(poses[:, :2], states[:, :2], atol=1e-12)
    assert np.max(np.abs(poses[:, 2])) < 1e-3
    assert np.ptp(poses[:, 2]) < 1e-4
    np.testing.assert_allclose(np.linalg.norm(poses[:, 3:], axis=1), 1.0, atol=1e-9)
    assert np.max(np.abs(poses[:, 4:6])) < 0.01  # tilted by under ~1 deg
    # The jet on them: they slide, and their poses follow.
    twin.set_jet(True)
    twin.advance_to(0.5)
    np.testing.assert_allclose(twin.poses()[:, :2], twin.states()[:, :2], atol=1e-12)


def test_twins_in_python_threads_step_as_they_do_alone():
    """The GIL is released while a twin steps: twins in threads run side by side, each as alone."""
    def run(seed, out):
        twin = airtwin.Twin(OCTAGON, seed, 30.0, 20.0)
        for _ in range(40):
            out.append(twin.step(35.0, 25.0))
    alone = {seed: [] for seed in (1, 2, 3)}
    for seed, out in alone.items():
        run(seed, out)
    threaded = {seed: [] for seed in alone}
    threads = [threading.Thread(target=run, args=(seed, out)) for seed, out in threaded.items()]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for seed in alone:
        assert all(np.array_equal(a, b) for a, b in zip(alone[seed], threaded[seed]))
        assert len(threaded[seed]) == 40
    assert not np.array_equal(alone[1][-1], alone[2][-1])  # the seeds differ


@pytest.mark.parametrize("air", ["model", "cfd"])
def test_render_shows_the_same_frames_as_the_cli(tmp_path, air):
    """`airtwin render` with the jet settled at one orientation: the module's twin has the objects
    where the CLI's truth has them at every frame time, and its frame shows them there."""
    out = tmp_path / "render"
    frames = 21
    pan_deg, tilt_deg = airtwin.aim(0.15, 0.0)  # s beside the group: the jet moves it
    status, _, stderr = run_cli("render", OCTAGON, "--frames", frames, "--seed", 2, "--pan",
                                repr(pan_deg), "--tilt", repr(tilt_deg), "--air", air,
                                "--drag", "eq8", "--quiet", "--out", out)
    assert status == 0, stderr
    cfd = airtwin.CfdField.read_dir() if air == "cfd" else None
    twin = airtwin.Twin(OCTAGON, 2, pan_deg, tilt_deg, cfd=cfd, air=air, drag="eq8")
    rows = read_csv(out / "truth.csv")
    for k in range(frames):
        twin.advance_to(k / 40)
        states = twin.states()
        truth = [r for r in rows if r["frame"] == str(k)]
        for i, row in enumerate(truth):
            assert row["id"] == twin.ids[i]
            assert np.max(np.abs(states[i, :2] - (float(row["x"]), float(row["y"])))) <= 5e-7
    start = airtwin.Twin(OCTAGON, 2, pan_deg, tilt_deg, cfd=cfd, air=air, drag="eq8").states()
    assert np.max(np.abs(states[:, :2] - start[:, :2])) > 0.01  # the jet moved them
    frame = twin.render(frames - 1)
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert np.array_equal(frame, twin.render(frames - 1))
    floor = np.median(frame.reshape(-1, 3), axis=0)
    for row in truth:
        x_px, y_px = round(float(row["x_px"])), round(float(row["y_px"]))
        assert np.abs(frame[y_px, x_px].astype(int) - floor).sum() > 60  # an object, not floor


def test_bad_input_raises_value_error_with_the_cli_message(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(open(OCTAGON).read().replace("x: 0.275, y: -0.025", "x: nan, y: -0.025"))
    cli_args = ("run", bad, "--seed", 1, "--out", tmp_path / "r")
    assert "nan" in expect_cli_error(lambda: airtwin.Twin(str(bad), 1), *cli_args)
    expect_cli_error(lambda: airtwin.Scenario.load(str(bad)), *cli_args)
    twin = airtwin.Twin(OCTAGON, 1)
    with pytest.raises(ValueError):
        twin.command(0.0, 80.0)
