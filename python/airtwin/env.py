"""AirJetEnv: a scenario of the air-jet rig as a reinforcement-learning environment.

Gymnasium's API by convention, without depending on the package: reset(seed=None, options=None)
-> (obs, info); step(action) -> (obs, reward, terminated, truncated, info); observation_space and
action_space as shapes, dtypes and bounds (Box, Dict below).

One step is one turn of the C++ closed loop (runs/scenario_episode.h, controller/closed_loop.h):
the nozzle is aimed at the action, the air acts for the controller's Delta T plus the scenario's
settle time (1.8 s for the shipped scenarios; camera frame by camera frame), the perception
observes and the task (controller/task.h) advances the references exactly as `airtwin run`
advances them. The episode starts as `airtwin run` starts (the nozzle resting at the
controller's first aim, the jet settled). An episode whose actions are the shipped controller's
(controller_action()) is `airtwin run SCENARIO --seed N` to the last bit.

Reward: minus eq. (10) on the positions the objects reached: the sum of their distances (m) to the
references in force when the step began (with the task's weights and reaches when sorting in
stages), or minus J_P (the scenario's penalty, 1000) when the action's stagnation point was within
delta_min (10 cm) of an object or beyond the nozzle's reach. terminated: the task is done (as the
controller sees it; info['success'] adds the truth's verdict for zone tasks); truncated: the
scenario's time limit came first.

Units: SI (m, s); actions in degrees only with action_type='orientation' (pan_deg, tilt_deg).
"""

import os
import tempfile

import numpy as np

from . import _core


class Box:
    """A box in R^shape: low <= x <= high elementwise, dtype float64 unless given."""

    def __init__(self, low, high, shape=None, dtype=np.float64):
        self.dtype = np.dtype(dtype)
        shape = tuple(shape) if shape is not None else np.shape(low)
        self.shape = shape
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), shape).copy()
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), shape).copy()

    def sample(self, rng):
        """A uniform draw from `rng` (a numpy Generator); infinite bounds are drawn as normal."""
        finite = np.isfinite(self.low) & np.isfinite(self.high)
        low = np.where(finite, self.low, 0.0)
        high = np.where(finite, self.high, 1.0)
        x = rng.uniform(low, high, size=self.shape)
        x = np.where(finite, x, rng.normal(size=self.shape))
        return x.astype(self.dtype)

    def contains(self, x):
        x = np.asarray(x)
        if x.shape != self.shape:
            return False
        with np.errstate(invalid="ignore"):
            inside = (x >= self.low) & (x <= self.high)
        # NaN marks a row the perception has not filled (vision observations).
        return bool(np.all(inside | np.isnan(x)))

    def __repr__(self):
        return "Box(%s, %s, %s)" % (self.low.min(), self.high.max(), self.shape)


class Dict:
    """A dict of spaces; sample and contains key by key."""

    def __init__(self, spaces):
        self.spaces = dict(spaces)

    def sample(self, rng):
        return {k: s.sample(rng) for k, s in self.spaces.items()}

    def contains(self, x):
        return (isinstance(x, dict) and x.keys() == self.spaces.keys()
                and all(s.contains(x[k]) for k, s in self.spaces.items()))

    def __getitem__(self, key):
        return self.spaces[key]

    def __repr__(self):
        return "Dict(%s)" % ", ".join("%s: %r" % kv for kv in self.spaces.items())


# The shipped scenarios, by name (scenes/*.yaml beside the build tree's source).
TASKS = ("line", "square", "letter_A", "octagon", "aggregation", "sorting")


def scenario_path(task):
    """The file of a shipped task name, or `task` itself when it names a file."""
    if os.path.exists(task):
        return task
    if task in TASKS:
        return os.path.join(_core.SCENES_DIR, task + ".yaml")
    raise ValueError("task: expected a scenario file or one of %s, got '%s'"
                     % (", ".join(TASKS), task))


class AirJetEnv:
    """A scenario of the rig, one step per turn of the closed loop (module docstring).

    task: a shipped scenario's name (TASKS) or a scenario file. seed: the twin's and the
    controller's, as `airtwin run --seed`. action_type: 'stagnation' (s = (x, y) m) or
    'orientation' ((pan_deg, tilt_deg)). vision: observations from the detection pipeline on
    rendered frames, as `airtwin run --vision` (calib: a calib.yaml; without it the twin's camera
    is calibrated once, at the first reset, with that reset's seed). The twin's set-up as the
    CLI's flags and Twin's, with their defaults (the physical twin): air ('cfd' | 'model'), cfd
    (a CfdField), drag ('physical' | 'eq8'),
    object_physics and effects (lists of 'NAME:key=value,...'), mjcf (a user's MJCF scene),
    air_formation (the wall jet's formation in the CFD's air: None on where the cases have it,
    True --air-formation, False --no-air-formation), air_formation_time_scale
    (--air-formation-time-scale), integrator ('euler' | 'implicit'), air_front_co_flow and
    air_front_counter_flow (the new wall jet's front carried by the old air:
    --air-front-co-flow, --air-front-counter-flow), air_turbulence_swept (the eddies swept past
    the objects in the CFD's air: None on, True --air-turbulence-swept, False
    --no-air-turbulence-swept), vary_physics (each object its own physics drawn from the
    episode's seed: 'none', 'documented' or a spread in (0, 0.5], as --vary-physics; a new draw
    at every reset with a new seed: domain randomisation), planner_threads (threads that predict
    each decision's candidates, as --planner-threads: the same decisions for any number);
    the controller's as --table and --model: table (a table CSV or field-model JSON: the
    controller's field model and the twin's analytical air; default the one fitted to the CFD),
    models (model.json or extended_model.json files; controller_action() plans with them;
    default, as the CLI's, the models fitted to the physical twin in it, else eq. (8)). Bad values raise
    ValueError with the library's message.

    Observation (a dict; rows are the objects the controller knows, in id order; info['ids']
    names them): positions, velocities (N x 2; m, m/s), references (N x 2, m: r_j of eq. (10)),
    visible (N, int8: 1 in the last observation), nozzle_deg (2: the commanded pan, tilt),
    time_s (1). N is the scenario's object count; with vision, rows beyond the objects known are
    NaN (visible 0) and objects beyond N are left out.
    """

    metadata = {"render_modes": ["rgb_array"]}

    def __init__(self, task="line", seed=0, action_type="stagnation", vision=False, calib=None,
                 vision_rate_hz=10.0, noise_sigma_grey=0.0, blur_sigma_px=0.0, air="cfd",
                 cfd=None, drag="physical", object_physics=(), effects=(), mjcf="", table="",
                 models=(), air_formation=None, air_formation_time_scale=0.5,
                 integrator="euler", air_front_co_flow=1.0, air_front_counter_flow=0.0,
                 air_turbulence_swept=None, vary_physics="none", planner_threads=1):
        if action_type not in ("stagnation", "orientation"):
            raise ValueError("action_type: expected stagnation or orientation, got '%s'"
                             % action_type)
        self.scenario_path = scenario_path(task)
        self.scenario = _core.Scenario.load(self.scenario_path)
        self.action_type = action_type
        self._seed = int(seed)
        self._setup = dict(cfd=cfd, air=air, drag=drag, object_physics=list(object_physics),
                           effects=list(effects), mjcf=mjcf or "", table=table or "",
                           models=list(models),
                           air_formation=None if air_formation is None else bool(air_formation),
                           air_formation_time_scale=float(air_formation_time_scale),
                           integrator=str(integrator),
                           air_front_co_flow=float(air_front_co_flow),
                           air_front_counter_flow=float(air_front_counter_flow),
                           air_turbulence_swept=None if air_turbulence_swept is None
                           else bool(air_turbulence_swept),
                           vary_physics=str(vary_physics),
                           planner_threads=int(planner_threads))
        self._vision = dict(vision=bool(vision), calib=calib or "", vision_rate_hz=vision_rate_hz,
                            noise_sigma_grey=noise_sigma_grey, blur_sigma_px=blur_sigma_px)
        self._calib_dir = None
        self.n_objects = len(self.scenario.ids)
        # A first episode checks the set-up (ValueError now, not at reset) and gives the ranges.
        self._episode = self._new_episode(self._seed)
        self._episode_seed = self._seed
        self._controller_decision = None
        pan_min, tilt_min, pan_max, tilt_max = self._episode.servo_range_deg
        r = self._episode.max_stagnation_radius_m
        if action_type == "stagnation":
            self.action_space = Box([-r, -r], [r, r])
        else:
            self.action_space = Box([pan_min, tilt_min], [pan_max, tilt_max])
        n = self.n_objects
        inf = np.inf
        self.observation_space = Dict({
            "positions": Box(-inf, inf, (n, 2)),
            "velocities": Box(-inf, inf, (n, 2)),
            "references": Box(-inf, inf, (n, 2)),
            "visible": Box(0, 1, (n,), dtype=np.int8),
            "nozzle_deg": Box([pan_min, tilt_min], [pan_max, tilt_max]),
            "time_s": Box(0.0, self.scenario.time_limit_s, (1,)),
        })
        self._fresh = True  # the episode built here has not been stepped

    # --- Gymnasium's API ---------------------------------------------------------------------

    def reset(self, seed=None, options=None):
        """A new episode: with `seed`, the twin's and the controller's seed (same seed, same
        bytes); without, the previous episode's seed plus one (the first: the constructor's).
        options: unused (Gymnasium's signature)."""
        if seed is not None:
            next_seed = int(seed)
        elif self._fresh:
            next_seed = self._episode_seed
        else:
            next_seed = self._episode_seed + 1
        if not (self._fresh and next_seed == self._episode_seed):
            self._episode = self._new_episode(next_seed)
            self._episode_seed = next_seed
        self._fresh = False
        self._controller_decision = None
        obs = self._observation()
        return obs, self._info()

    def step(self, action):
        """One turn with `action` (action_space's); (obs, reward, terminated, truncated, info)."""
        self._fresh = False
        ep = self._episode
        if ep.finished:
            raise ValueError("step: the episode is over (terminated or truncated); call reset()")
        a = np.asarray(action, dtype=np.float64)
        if a.shape != (2,):
            raise ValueError("action: expected 2 numbers, got shape %s" % (a.shape,))
        decision = self._controller_decision
        self._controller_decision = None
        if decision is not None and np.array_equal(a, decision[0]):
            ep.step_decision(decision[1])
        elif self.action_type == "stagnation":
            ep.step_at(a[0], a[1])
        else:
            ep.step_deg(a[0], a[1])
        reward = -ep.last_cost
        terminated = ep.done
        truncated = ep.finished and not terminated
        obs = self._observation()
        info = self._info()
        if ep.finished:
            info["success"] = ep.result().success
        return obs, reward, terminated, truncated, info

    def render(self):
        """The top camera's frame of the twin now: H x W x 3 uint8 RGB (render from one thread:
        the renderer's OpenGL context belongs to the first that renders)."""
        return self._episode.render()

    def close(self):
        self._episode = None

    # --- the shipped controller ----------------------------------------------------------------

    def controller_action(self):
        """The shipped CEM controller's action now (its random stream advances): stepping with
        it (unchanged) is the closed loop of `airtwin run`, its decision recorded as its own."""
        d = self._episode.decide()
        a = np.array(d.stagnation_point if self.action_type == "stagnation"
                     else (d.pan_deg, d.tilt_deg), dtype=np.float64)
        self._controller_decision = (a, d)
        return a.copy()

    def result(self):
        """The episode so far as a RunResult (summary_json(), log_csv(), ... as `airtwin run`
        writes them)."""
        return self._episode.result()

    @property
    def seed(self):
        return self._episode_seed

    # --- internals ----------------------------------------------------------------------------

    def _new_episode(self, seed):
        vision = dict(self._vision)
        if vision["vision"] and not vision["calib"]:
            # The twin's camera calibrated once (as `airtwin run --vision` does per run), kept.
            self._calib_dir = tempfile.TemporaryDirectory(prefix="airtwin_env_calib_")
            vision["calib_dir"] = self._calib_dir.name
            episode = _core.Episode(self.scenario_path, seed, **self._setup, **vision)
            self._vision["calib"] = os.path.join(self._calib_dir.name, "calib.yaml")
            return episode
        return _core.Episode(self.scenario_path, seed, **self._setup, **vision)

    def _observation(self):
        ep = self._episode
        known = ep.known()
        n = self.n_objects
        k = min(len(known["ids"]), n)
        obs = {
            "positions": np.full((n, 2), np.nan),
            "velocities": np.full((n, 2), np.nan),
            "references": np.full((n, 2), np.nan),
            "visible": np.zeros(n, dtype=np.int8),
            "nozzle_deg": np.array(ep.commanded_deg, dtype=np.float64),
            "time_s": np.array([ep.time_s]),
        }
        for key in ("positions", "velocities", "references"):
            obs[key][:k] = known[key][:k]
        obs["visible"][:k] = known["seen"][:k]
        self._known = known
        return obs

    def _info(self):
        ep = self._episode
        known = self._known
        return {
            "ids": known["ids"][:self.n_objects],
            "types": known["types"][:self.n_objects],
            "dynamics": known["dynamics"][:self.n_objects],
            # eq. (10)'s shaping of the task now (sorting in stages), empty otherwise.
            "weights": np.array(known["weights"][:self.n_objects]),
            "reach_m": np.array(known["reach_m"][:self.n_objects]),
            "time_s": ep.time_s,
            "reference_index": ep.reference_index,
            "cost": ep.last_cost,
            "stagnation_point": np.array(ep.last_stagnation_point),
            "seed": self._episode_seed,
        }


class CemPolicy:
    """The shipped CEM planner (airtwin.CemPlanner with the scenario's controller parameters) as
    a policy of the observation: eq. (10) toward the observation's references, with the task's
    weights and reaches (info) when sorting in stages, the re-aim from the nozzle's command
    predicted when the scenario asks (predict_transition), each decision's samples from the stream
    (seed, controller, decision number). Returns the action in the env's action_type."""

    def __init__(self, env, seed=1):
        self.env = env
        self.seed = seed
        self.planner = _core.CemPlanner(_core.Field.default(), scenario=env.scenario)
        self.decisions = 0

    def __call__(self, obs, info):
        rows = np.isfinite(obs["positions"][:, 0])  # every object the controller knows
        shaping = {key: info[key][rows] for key in ("weights", "reach_m") if len(info[key])}
        plan = self.planner.plan(obs["positions"][rows], obs["references"][rows],
                                 info["dynamics"][rows], velocities=obs["velocities"][rows],
                                 seed=self.seed, decision=self.decisions,
                                 pan_hint_deg=float(obs["nozzle_deg"][0]),
                                 nozzle_now_deg=tuple(obs["nozzle_deg"]), **shaping)
        self.decisions += 1
        if self.env.action_type == "stagnation":
            return np.array(plan.stagnation_point)
        return np.array([plan.pan_deg, plan.tilt_deg])
