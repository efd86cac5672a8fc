// Twin step rate (issue 4's benchmark): the MuJoCo twin stepped with its air callback against bare
// MuJoCo stepping the same model without it, in one run, interleaved so that the shared machine's
// load affects both alike.
//
// Each benchmark iteration runs kChunkSteps twin steps (Twin::step: servos, delay line, field,
// turbulence, mj_step with the air registered, state checks). Before each, the twin's state
// (qpos, qvel, warm start, time) is copied into a bare mjData of the same mjModel, which then
// takes one plain mj_step with no air registered (the dispatcher pushes nothing): the same
// configuration, contacts and velocities, minus the air and the twin's bookkeeping. That pair
// gives `ratio`; its order alternates step by step, since the step that runs second finds the
// caches the first left (`ratio_twin_first` and `ratio_bare_first` keep each order's). A third
// mjData takes the same plain mj_step from the same state with the twin's air as given generalized
// forces (qfrc_applied: the twin's qfrc_passive of that step less the bare step's): MuJoCo doing
// the twin's physics, the objects sliding as the air pushes them, without airtwin's code
// (`ratio_forced`: what the twin's own work costs; `ratio` also counts the extra constraint work
// the air's pushes cause MuJoCo). Then the bare data runs a chunk on its own from the twin's state
// (`ratio_free`): without air its objects slow down and stop, so its solver has less to do than the
// twin's. A twin that has run kEpisode_s seconds is rebuilt (untimed), so the objects stay in view.
//
// Scenes (default TwinParameters: 2.5 ms step, turbulence, pressure push, stiction; jet settled):
//   BM_TwinStep/tracers_25:  25 tracers scattered over ~1.2 x 1.2 m, the nozzle re-aimed every
//                            second (tilt 20 deg, pan in 90 deg steps) so s sweeps past them and
//                            the jet drives them into each other (the aggregation scene).
//   BM_TwinStep/tracers_25_1ms: the same at the former 1 ms step (the default is 2.5 ms).
//   BM_TwinStep/tracer_1:    one tracer in the jet.
//   BM_TwinStep/mixed_12:    6 cotton wads + 6 tracers, same nozzle program.
//   BM_TwinStep/tracers_25_cfd: the 25 tracers in the CFD's air (data/cfd/) instead of the
//                            analytical field's; its counter air_share is the share of a twin step
//                            spent in the air callback (the same AirForces::apply on the twin's
//                            state, timed alone; issue target <= 3 %). The nozzle program
//                            re-aims every second, so the wall jet's transport lag
//                            (sim/air_transport.h) is always at work: each tracer's air comes
//                            from its own lagged orientation.
//   BM_TwinStep/tracers_25_cfd_rigid: the same with the rigid floor pattern (no lag), the
//                            reference the lag's cost is read against in the same run.
//   BM_TwinStep/tracers_25_cfd_formed: the same with the wall jet's formation (the default in
//                            CFD air; tracers_25_cfd leaves it out, --no-air-formation).
//   BM_TwinStep/tracers_25_cfd_still_front: formed, with the front of still air instead of the
//                            default carried by the old air (--air-front-co-flow 0): the
//                            reference the carried front's cost is read against.
// Counters: steps_per_s (twin), bare_steps_per_s (mirrored), rtf (simulated s per wall s, twin),
// ratio (twin / mirrored bare step rate, both orders of the pair; the target is >= 0.8
// with rtf >= 10 on the 25-tracer scene), ratio_twin_first and ratio_bare_first (each order's
// alone), ratio_forced (twin / mirrored bare step under the twin's air as applied
// forces), ratio_free (twin / free-running bare step rate), solver_iter, bare_solver_iter and
// forced_solver_iter (MuJoCo's constraint-solver iterations per step).

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/units.h"
#include "models/cfd_field.h"
#include "sim/air_forces.h"
#include "sim/mujoco_runtime.h"
#include "sim/twin.h"

namespace airtwin {
namespace {

constexpr int kChunkSteps = 250;
constexpr double kEpisode_s = 4.0;

const AirFieldModel& field_model() {
  static const AirFieldModel model = AirFieldModel::with_constructed_table();
  return model;
}

std::string numbered(const char* prefix, int i) {
  std::string s = prefix;
  s += std::to_string(i);
  return s;
}

// 25 tracers on a 5 x 5 grid of 0.26 m pitch with a fixed +-5 cm jitter: ~1.2 m across.
SceneSpec tracers_25() {
  SceneSpec spec;
  for (int i = 0; i < 25; ++i) {
    const double jx = 0.05 * std::sin(1.7 * i + 0.3), jy = 0.05 * std::cos(2.3 * i + 1.1);
    spec.objects.push_back(
        {numbered("t", i), "tracer", {0.26 * (i % 5 - 2) + jx, 0.26 * (i / 5 - 2) + jy}, 0.0});
  }
  return spec;
}

SceneSpec tracer_1() {
  SceneSpec spec;
  spec.objects = {{"t0", "tracer", {0.3, 0.2}, 0.0}};
  return spec;
}

// Six wads on a ring of 0.35 m, six tracers on a ring of 0.6 m between them.
SceneSpec mixed_12() {
  SceneSpec spec;
  for (int i = 0; i < 6; ++i) {
    const double a = i * kPi / 3;
    spec.objects.push_back(
        {numbered("c", i), "cotton", {0.35 * std::cos(a), 0.35 * std::sin(a)}, std::nullopt});
    spec.objects.push_back({numbered("t", i),
                            "tracer",
                            {0.6 * std::cos(a + kPi / 6), 0.6 * std::sin(a + kPi / 6)},
                            0.0});
  }
  return spec;
}

// The nozzle program: tilt 20 deg, pan stepping by 90 deg every second.
NozzleOrientation program(double t_s) {
  const int k = static_cast<int>(std::floor(t_s)) % 4;
  return {-kPi / 2 + k * kPi / 2, deg_to_rad(20)};
}

std::shared_ptr<const CfdField> shipped_cfd() {
  static const auto cfd =
      std::make_shared<const CfdField>(CfdField::read_dir(AIRTWIN_SOURCE_DIR "/data/cfd"));
  return cfd;
}

// How the CFD's floor air follows the nozzle (sim/air_transport.h).
enum class Response {
  kLagged,  // the default: each object in the newest orientation's air that has reached it
  kRigid,   // the pattern swings rigidly with the nozzle (no transport lag)
  kFormed,  // lagged, and each object's air forms at the CFD pulses' rate
  kFormedStillFront,  // formed, the front of still air (not carried by the old air)
};

TwinParameters twin_parameters(double timestep_s, bool cfd, Response response = Response::kLagged) {
  TwinParameters p;
  p.scene.timestep_s = timestep_s;
  if (cfd) p.cfd_air = shipped_cfd();
  if (response == Response::kRigid) p.air_transport = AirTransportParameters::rigid();
  p.air_transport.formation =
      response == Response::kFormed || response == Response::kFormedStillFront;
  if (response == Response::kFormedStillFront) p.air_transport.front_co_flow = 0.0;
  p.jet_on_at_start = true;
  p.initial_orientation = program(0.0);
  return p;
}

Twin make_twin(const SceneSpec& spec, double timestep_s, bool cfd = false,
               Response response = Response::kLagged) {
  TwinParameters p = twin_parameters(timestep_s, cfd, response);
  Twin twin(spec, p, field_model(), 7);
  twin.settle_jet();
  return twin;
}

// The state mj_step starts from (everything else in mjData is recomputed from it).
void copy_state(const mjModel* m, const mjData* from, mjData* to) {
  mju_copy(to->qpos, from->qpos, m->nq);
  mju_copy(to->qvel, from->qvel, m->nv);
  mju_copy(to->act, from->act, m->na);
  mju_copy(to->ctrl, from->ctrl, m->nu);
  mju_copy(to->qacc_warmstart, from->qacc_warmstart, m->nv);
  to->time = from->time;
}

void run(benchmark::State& state, const SceneSpec& spec,
         double timestep_s = SceneParameters{}.timestep_s, bool cfd = false,
         Response response = Response::kLagged) {
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  };
  Twin twin = make_twin(spec, timestep_s, cfd, response);
  const mjModel* m = twin.model();
  DataPtr bare = make_data(m);
  DataPtr forced = make_data(m);
  // The air callback alone, on the twin's state: a second AirForces of the same objects.
  const TwinParameters params = twin_parameters(timestep_s, cfd);
  std::vector<SceneObject> objects;
  for (size_t i = 0; i < twin.object_count(); ++i) objects.push_back(twin.object(i));
  AirForces air(params.air, params.scene, objects, 7, timestep_s);
  double forced_s = 0.0, free_s = 0.0, air_s = 0.0;
  double pair_twin_s[2] = {0.0, 0.0}, pair_bare_s[2] = {0.0, 0.0};  // [bare first, twin first]
  int64_t steps = 0, twin_iter = 0, bare_iter = 0, forced_iter = 0;
  for (auto _ : state) {
    // Twin, step by step, each step mirrored by a bare step from the same state.
    for (int k = 0; k < kChunkSteps; ++k) {
      const NozzleOrientation target = program(twin.time());
      if (target.pan_rad != twin.commanded_orientation().pan_rad) twin.command_nozzle(target);
      copy_state(m, twin.data(), bare.get());
      copy_state(m, twin.data(), forced.get());
      // The pair's order alternates step by step: the step that runs second finds the caches
      // the first left, and each order's ratio is kept apart to show how much that weighs.
      const bool twin_first = (steps + k) % 2 == 0;
      if (!twin_first) {
        const auto b0 = Clock::now();
        mj_step(m, bare.get());
        pair_bare_s[0] += seconds(b0, Clock::now());
      }
      const auto t0 = Clock::now();
      twin.step();
      const auto t1 = Clock::now();
      pair_twin_s[twin_first ? 1 : 0] += seconds(t0, t1);
      if (twin_first) {
        mj_step(m, bare.get());
        pair_bare_s[1] += seconds(t1, Clock::now());
      }
      twin_iter += twin.data()->solver_iter;
      bare_iter += bare->solver_iter;
      // Both steps left their passive forces of the same starting state in qfrc_passive: the
      // difference is the twin's air (and holding force), given to the third step as applied.
      for (int i = 0; i < m->nv; ++i) {
        forced->qfrc_applied[i] = twin.data()->qfrc_passive[i] - bare->qfrc_passive[i];
      }
      const auto t5 = Clock::now();
      mj_step(m, forced.get());
      forced_s += seconds(t5, Clock::now());
      forced_iter += forced->solver_iter;
      // The air alone on the state mj_step left (positions and kinematics are current).
      const NozzleOrientation e = twin.effective_orientation();
      std::optional<CfdOrientedField> cfd_air;
      if (cfd) {
        cfd_air = params.cfd_air->at(e);
        air.set_air(*cfd_air, twin.jet_level());
      } else {
        air.set_air(twin.field(), twin.jet_level());
      }
      const auto t4 = Clock::now();
      air.apply(m, bare.get());
      air_s += seconds(t4, Clock::now());
    }
    // Bare, free-running from the twin's state for a chunk (its objects slow down and stop).
    copy_state(m, twin.data(), bare.get());
    const auto t3 = Clock::now();
    for (int k = 0; k < kChunkSteps; ++k) mj_step(m, bare.get());
    free_s += seconds(t3, Clock::now());
    benchmark::DoNotOptimize(bare->qpos[0]);
    steps += kChunkSteps;
    if (twin.time() >= kEpisode_s) {
      state.PauseTiming();
      twin = make_twin(spec, timestep_s, cfd, response);
      m = twin.model();
      bare = make_data(m);
      forced = make_data(m);
      state.ResumeTiming();
    }
  }
  const double n = static_cast<double>(steps);
  const double twin_s = pair_twin_s[0] + pair_twin_s[1];
  const double bare_s = pair_bare_s[0] + pair_bare_s[1];
  state.counters["ratio_bare_first"] = pair_bare_s[0] / pair_twin_s[0];
  state.counters["ratio_twin_first"] = pair_bare_s[1] / pair_twin_s[1];
  state.counters["steps_per_s"] = n / twin_s;
  state.counters["bare_steps_per_s"] = n / bare_s;
  state.counters["rtf"] = n / twin_s * twin.timestep();
  state.counters["ratio"] = bare_s / twin_s;
  state.counters["ratio_forced"] = forced_s / twin_s;
  state.counters["ratio_free"] = free_s / twin_s;
  state.counters["air_share"] = air_s / twin_s;
  // The constraint solver's iterations per step, twin and mirrored bare: the air's forces change
  // the contact problem MuJoCo solves, which costs beside the callback itself.
  state.counters["solver_iter"] = static_cast<double>(twin_iter) / n;
  state.counters["bare_solver_iter"] = static_cast<double>(bare_iter) / n;
  state.counters["forced_solver_iter"] = static_cast<double>(forced_iter) / n;
}

void BM_TwinStep_tracers_25(benchmark::State& state) { run(state, tracers_25()); }
void BM_TwinStep_tracers_25_1ms(benchmark::State& state) { run(state, tracers_25(), 0.001); }
void BM_TwinStep_tracer_1(benchmark::State& state) { run(state, tracer_1()); }
void BM_TwinStep_mixed_12(benchmark::State& state) { run(state, mixed_12()); }
void BM_TwinStep_tracers_25_cfd(benchmark::State& state) {
  run(state, tracers_25(), SceneParameters{}.timestep_s, true);
}
void BM_TwinStep_tracers_25_cfd_rigid(benchmark::State& state) {
  run(state, tracers_25(), SceneParameters{}.timestep_s, true, Response::kRigid);
}
void BM_TwinStep_tracers_25_cfd_formed(benchmark::State& state) {
  run(state, tracers_25(), SceneParameters{}.timestep_s, true, Response::kFormed);
}
void BM_TwinStep_tracers_25_cfd_still_front(benchmark::State& state) {
  run(state, tracers_25(), SceneParameters{}.timestep_s, true, Response::kFormedStillFront);
}

BENCHMARK(BM_TwinStep_tracers_25)
    ->Name("BM_TwinStep/tracers_25")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK(BM_TwinStep_tracers_25_1ms)
    ->Name("BM_TwinStep/tracers_25_1ms")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK(BM_TwinStep_tracer_1)
    ->Name("BM_TwinStep/tracer_1")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK(BM_TwinStep_tracers_25_cfd)
    ->Name("BM_TwinStep/tracers_25_cfd")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK(BM_TwinStep_tracers_25_cfd_rigid)
    ->Name("BM_TwinStep/tracers_25_cfd_rigid")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK(BM_TwinStep_tracers_25_cfd_formed)
    ->Name("BM_TwinStep/tracers_25_cfd_formed")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK(BM_TwinStep_tracers_25_cfd_still_front)
    ->Name("BM_TwinStep/tracers_25_cfd_still_front")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK(BM_TwinStep_mixed_12)
    ->Name("BM_TwinStep/mixed_12")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);

}  // namespace
}  // namespace airtwin
