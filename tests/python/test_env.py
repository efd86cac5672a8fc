"""airtwin.env.AirJetEnv against the C++ closed loop (`airtwin run`), and its API's contract:
spaces, seeding, rewards from eq. (10), options with the library's error messages."""

import os

import numpy as np
import pytest

import airtwin
from airtwin.env import AirJetEnv, Box, CemPolicy
from conftest import MIRROR, MIRROR_KW, SOURCE_DIR, assert_same_run, expect_cli_error, run_cli

LINE = os.path.join(SOURCE_DIR, "scenes/line.yaml")
OCTAGON = os.path.join(SOURCE_DIR, "scenes/octagon.yaml")


def rollout(env, policy, seed):
    """Steps `policy(obs, info)` to the end of an episode; (rewards, final info, terminated)."""
    obs, info = env.reset(seed=seed)
    rewards = []
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs, info))
        rewards.append(reward)
        if terminated or truncated:
            return np.array(rewards), info, terminated


def test_the_controllers_actions_through_the_env_are_the_cli_run(tmp_path):
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", LINE, "--seed", 2, *MIRROR, "--quiet", "--out", out)
    assert status == 0, stderr
    env = AirJetEnv("line", seed=2, **MIRROR_KW)
    actions = []

    def controller(obs, info):
        actions.append(env.controller_action())
        return actions[-1]
    rewards, info, terminated = rollout(env, controller, 2)
    assert terminated and info["success"]
    result = env.result()
    # The same run: every frame, command and decision (decision_ms, a wall-clock time, aside).
    assert_same_run(result, out)

    # The same actions as plain numbers (the env's own aim, not the controller's records): the
    # objects go through the same states, frame by frame.
    replay = AirJetEnv("line", seed=2, **MIRROR_KW)
    replay.reset()
    for a in actions:
        replay.step(np.array(a))
    assert replay.result().log_csv() == result.log_csv()
    assert replay.result().nozzle_csv() == result.nozzle_csv()
    # Rewards are eq. (10) on where the tracer got to: minus its distance to the reference of
    # the step (the planner's own cost of that outcome).
    assert np.all(rewards < 0) and np.all(rewards > -1.0)


def test_reward_is_eq10_on_the_reached_positions():
    env = AirJetEnv("octagon", seed=3, **MIRROR_KW)
    obs, info = env.reset()
    # s inside the group's near side: the objects lie in the wall jet that spreads from it.
    a = np.mean(obs["positions"], axis=0) + [-0.15, 0.0]
    assert np.min(np.hypot(*(obs["positions"] - a).T)) > 0.1
    obs2, reward, _, _, _ = env.step(a)
    # The sum of each object's distance from where it got to to the reference of the step.
    expected = np.sum(np.hypot(*(obs2["positions"] - obs["references"]).T))
    assert reward == pytest.approx(-expected, abs=1e-12)
    assert np.any(np.abs(obs2["positions"] - obs["positions"]) > 0.01)  # the jet moved them
    # s within delta_min (10 cm) of an object: J_P, the scenario's penalty.
    _, reward, _, _, _ = env.step(obs2["positions"][0] + [0.05, 0.0])
    assert reward == -1000.0
    # Beyond the nozzle's reach: J_P, the nozzle held at the farthest point on the ray.
    _, reward, _, _, info = env.step(np.array([5.0, 0.0]))
    assert reward == -1000.0 and info["stagnation_point"][0] == 5.0


def test_cem_through_the_env_reaches_the_goal_and_a_random_policy_does_not():
    env = AirJetEnv("line", seed=1, **MIRROR_KW)
    rewards, info, terminated = rollout(env, CemPolicy(env, seed=1), 1)
    assert terminated and info["success"]
    assert info["time_s"] < env.scenario.time_limit_s
    rng = np.random.default_rng(1)
    random_rewards, random_info, random_terminated = rollout(
        env, lambda obs, info: env.action_space.sample(rng), 1)
    assert not random_terminated and not random_info["success"]
    assert np.mean(rewards) > np.mean(random_rewards)


def test_spaces_shapes_and_dtypes():
    for action_type in ("stagnation", "orientation"):
        env = AirJetEnv("octagon", seed=1, action_type=action_type, **MIRROR_KW)
        obs, info = env.reset()
        assert env.observation_space.contains(obs)
        assert obs["positions"].shape == (4, 2) and obs["positions"].dtype == np.float64
        assert obs["references"].shape == (4, 2) and obs["visible"].dtype == np.int8
        assert obs["nozzle_deg"].shape == (2,) and obs["time_s"].shape == (1,)
        assert info["ids"] == sorted(env.scenario.ids)
        rng = np.random.default_rng(0)
        a = env.action_space.sample(rng)
        assert a.shape == (2,) and a.dtype == np.float64 and env.action_space.contains(a)
        obs, reward, terminated, truncated, info = env.step(a)
        assert env.observation_space.contains(obs)
        assert isinstance(reward, float) and not terminated and not truncated
        assert obs["time_s"][0] == pytest.approx(1.8 + env.reset()[0]["time_s"][0], abs=0.03)
    stag = AirJetEnv("line", action_type="stagnation").action_space
    r = stag.high[0]
    # eq. (2) at the servos' 60 deg with the default model's a1, a2: 2.477 - 0.181 2.477^1.34.
    assert r == pytest.approx(2.4768 - 0.181083 * 2.4768**1.340571, abs=1e-3)
    assert np.all(stag.low == -r)
    orient = AirJetEnv("line", action_type="orientation").action_space
    assert np.allclose(orient.low, [-180.0, 0.0]) and np.allclose(orient.high, [180.0, 60.0])
    box = Box([0, 0], [1, 2])
    assert box.contains([1, 2]) and not box.contains([1, 2.1]) and not box.contains([1])


def test_same_seed_same_bytes_and_other_seeds_differ():
    def bytes_of(seed, env_seed):
        env = AirJetEnv("octagon", seed=env_seed, **MIRROR_KW)
        rng = np.random.default_rng(seed)
        obs, _ = env.reset(seed=env_seed)
        out = [obs["positions"].tobytes()]
        for _ in range(5):
            obs, reward, *_ = env.step(env.action_space.sample(rng))
            out += [obs["positions"].tobytes(), np.float64(reward).tobytes()]
        return b"".join(out)
    assert bytes_of(1, 7) == bytes_of(1, 7)
    assert bytes_of(1, 7) != bytes_of(1, 8)
    # reset() without a seed: the next seed; with the same seed again: the same start.
    env = AirJetEnv("octagon", seed=7, **MIRROR_KW)
    first, _ = env.reset()
    env.step(env.action_space.sample(np.random.default_rng(0)))
    _, info = env.reset()
    assert info["seed"] == 8
    again, _ = env.reset(seed=7)
    assert again["positions"].tobytes() == first["positions"].tobytes()


def test_twin_set_up_options_change_the_physics_as_the_cli_flags_do(tmp_path):
    # A user's MJCF scene: `airtwin scene`'s export is the built scene to the last bit.
    status, _, stderr = run_cli("scene", LINE, "--seed", 1, *MIRROR, "--out", tmp_path / "scene")
    assert status == 0, stderr
    mjcf = str(tmp_path / "scene/scene.xml")
    built = airtwin.Twin(LINE, 1, 30.0, 20.0, **MIRROR_KW)
    loaded = airtwin.Twin(LINE, 1, 30.0, 20.0, mjcf=mjcf, **MIRROR_KW)
    for _ in range(40):
        assert built.step(30.0, 20.0).tobytes() == loaded.step(30.0, 20.0).tobytes()
    # Physical drag and an effect move the tracer otherwise than eq. (8) in the model's air
    # (s 19 cm from it: the air starts every one but the 3 g tracer).
    ends = {}
    for name, kwargs in (("eq8", {}), ("physical", {"drag": "physical"}),
                         ("slope", {"effects": ["floor_slope"]}),
                         ("mass", {"drag": "physical", "object_physics": ["tracer:mass_g=3"]})):
        twin = airtwin.Twin(LINE, 1, 150.0, 20.0, **{**MIRROR_KW, **kwargs})
        for _ in range(40):
            states = twin.step(150.0, 20.0)
        ends[name] = states[0, :2]
    for name in ("physical", "slope", "mass"):
        assert np.hypot(*(ends[name] - ends["eq8"])) > 0.01, name
    # The env takes the same options; a run with them through the module equals the CLI's.
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", LINE, "--seed", 1, "--air", "model", "--drag", "physical",
                                "--effect", "floor_slope", "--quiet", "--out", out)
    assert status == 0, stderr
    env = AirJetEnv("line", seed=1, air="model", drag="physical", effects=["floor_slope"])
    rollout(env, lambda obs, info: env.controller_action(), 1)
    assert env.result().log_csv() == (out / "log.csv").read_text()


def test_bad_options_raise_value_error_with_the_librarys_message(tmp_path):
    def cli_usage_line(*args):
        status, _, stderr = run_cli("run", LINE, "--out", tmp_path / "r", *args)
        assert status == 2, stderr
        line = stderr.strip()
        assert line.startswith("airtwin run: usage error: ") and line.endswith(
            " (see 'airtwin run --help')"), stderr
        return line[len("airtwin run: usage error: "):-len(" (see 'airtwin run --help')")]

    # The library's message: the CLI's names the flag.
    for kwargs, flag in (({"drag": "stokes"}, ("--drag", "stokes")),
                         ({"effects": ["floor_slope:deg=200"]}, ("--effect", "floor_slope:deg=200")),
                         ({"object_physics": ["tracer:mass_g=-1"]},
                          ("--object-physics", "tracer:mass_g=-1"))):
        with pytest.raises(ValueError) as raised:
            AirJetEnv("line", **kwargs)
        # A FieldError names the field, which the CLI replaces with its flag ("drag: ..." and
        # "--drag: ..."); other errors get the flag in front.
        message = str(raised.value)
        assert cli_usage_line(*flag) in (flag[0] + ": " + message, "--" + message)
        with pytest.raises(ValueError) as again:
            airtwin.Twin(LINE, 1, **kwargs)
        assert str(again.value) == str(raised.value)
    # Objects that differ: the library's field is the CLI's flag.
    with pytest.raises(ValueError) as raised:
        AirJetEnv("line", vary_physics="lots")
    flag_message = "--" + str(raised.value).replace("_", "-", 1)
    assert cli_usage_line("--vary-physics", "lots") == flag_message
    # A user's MJCF that is not a scene: the CLI's line.
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody/></mujoco>")
    expect_cli_error(lambda: AirJetEnv("line", mjcf=str(bad)), "run", LINE, "--mjcf", bad,
                     "--out", tmp_path / "r2")
    with pytest.raises(ValueError, match="air: expected cfd or model, got 'wind'"):
        AirJetEnv("line", air="wind")
    with pytest.raises(ValueError, match="action_type: expected stagnation or orientation"):
        AirJetEnv("line", action_type="pan")
    with pytest.raises(ValueError, match="task: expected a scenario file or one of"):
        AirJetEnv("lines")
    env = AirJetEnv("line", seed=1, action_type="orientation")
    env.reset()
    with pytest.raises(ValueError, match="action: expected 2 numbers"):
        env.step([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="tilt"):
        env.step([0.0, 75.0])
    with pytest.raises(ValueError, match="finite"):
        AirJetEnv("line").step([np.nan, 0.0])


def test_vision_observations_are_the_cli_vision_run(tmp_path):
    scenario = tmp_path / "octagon.yaml"
    scenario.write_text(open(OCTAGON).read().replace("time_limit_s: 450", "time_limit_s: 5"))
    env = AirJetEnv(str(scenario), seed=1, vision=True, **MIRROR_KW)
    obs, info = env.reset()
    # Tracks of the detection pipeline, each within 5 mm of a tracer of the twin's truth.
    assert info["ids"] == ["v1", "v2", "v3", "v4"] and np.all(obs["visible"] == 1)
    truth = env._episode.states()[:, :2]
    gaps = np.hypot(*(obs["positions"][:, None, :] - truth[None, :, :]).transpose(2, 0, 1))
    assert np.all(gaps.min(axis=1) < 0.005)
    rollout(env, lambda obs, info: env.controller_action(), 1)
    # The run of `airtwin run --vision` with the camera model the env calibrated.
    out = tmp_path / "run"
    status, _, stderr = run_cli("run", scenario, "--seed", 1, *MIRROR, "--vision", "--calib",
                                env._vision["calib"], "--quiet", "--out", out)
    assert status == 0, stderr
    assert_same_run(env.result(), out)
    frame = env.render()
    assert frame.shape == (1024, 1024, 3) and frame.dtype == np.uint8
