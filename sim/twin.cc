#include "sim/twin.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/errors.h"
#include "common/units.h"
#include "sim/reached_air.h"

namespace airtwin {

namespace {

bool same_orientation(const NozzleOrientation& a, const NozzleOrientation& b) {
  return a.pan_rad == b.pan_rad && a.tilt_rad == b.tilt_rad;
}

// The parameters a twin runs with: in the CFD's air with its start-up's timings, the free jet's
// transit is the CFD's (AirTransportParameters::cfd_timing).
TwinParameters with_cfd_timing(TwinParameters p) {
  if (p.cfd_air && p.air_transport.cfd_timing && p.cfd_air->startup()) {
    p.nozzle.field_delay_s = p.cfd_air->startup()->transit_s();
  }
  return p;
}

}  // namespace

struct Twin::Impl {
  Impl(const SceneSpec& spec, const TwinParameters& given, const AirFieldModel& fm, uint64_t seed)
      : params(with_cfd_timing(given)),
        field_model(fm),
        scene(params.scene_file.empty() ? build_scene(spec, params.scene, seed)
                                        : load_scene(params.scene_file, spec, params.scene)),
        data(make_data(scene.model.get())),
        actuator(params.nozzle, params.initial_orientation, params.scene.timestep_s),
        field(field_model.at(actuator.effective())),
        air(params.air, params.scene, scene.objects, seed, params.scene.timestep_s),
        reached(params.cfd_air
                    ? std::optional<ReachedAir>(std::in_place, *params.cfd_air,
                                                params.air_transport, params.scene.timestep_s,
                                                actuator.effective(), scene.objects.size())
                    : std::nullopt) {
    if (params.cfd_air) cfd_field = params.cfd_air->at(actuator.effective());
    if (!params.cfd_air && params.analytical_air_transport) {
      transport.emplace(params.air_transport, params.scene.timestep_s, actuator.effective(),
                        nullptr, nullptr, field.stagnation_point());
      lagged_rays.reserve(scene.objects.size());  // pointers into it stay valid for a step
    }
  }

  void set_rig_joints();
  void refresh_field();
  void set_object_air();
  void check_state();
  std::string object_label(int body) const;

  TwinParameters params;
  AirFieldModel field_model;
  BuiltScene scene;
  DataPtr data;
  NozzleActuator actuator;
  OrientedField field;
  std::optional<CfdOrientedField> cfd_field;  // the air when params.cfd_air is set
  AirForces air;
  // In the CFD's air, what each object feels: the orientation whose wall jet has reached it and
  // the formation's departure (sim/reached_air.h).
  std::optional<ReachedAir> reached;
  // In the analytical air with analytical_air_transport: which orientation reaches each object,
  // and this step's air of the lagged orientations objects feel, by steps back: read along rays
  // (an object's few bodies need two profiles, not the full field of 360).
  std::optional<AirTransport> transport;
  std::vector<std::pair<int, OrientedRays>> lagged_rays;
  int64_t steps = 0;
  std::string last_warning;
};

// The rig's hinges follow the servos kinematically: position and speed set, never integrated.
void Twin::Impl::set_rig_joints() {
  const mjModel* m = scene.model.get();
  mjData* d = data.get();
  d->qpos[m->jnt_qposadr[scene.pan_joint]] = actuator.actual().pan_rad;
  d->qpos[m->jnt_qposadr[scene.tilt_joint]] = actuator.actual().tilt_rad;
  d->qvel[m->jnt_dofadr[scene.pan_joint]] = actuator.pan_rate_radps();
  d->qvel[m->jnt_dofadr[scene.tilt_joint]] = actuator.tilt_rate_radps();
}

// Rebuilds the air's oriented field only when the effective orientation changed. In the CFD's air
// the analytical field is not rebuilt here: no step reads it, and its 360 profiles cost more than
// the CFD's bracket; Twin::field() builds it when asked.
void Twin::Impl::refresh_field() {
  const NozzleOrientation& e = actuator.effective();
  if (cfd_field) {
    if (!same_orientation(e, cfd_field->orientation())) cfd_field = params.cfd_air->at(e);
  } else if (!same_orientation(e, field.orientation())) {
    field = field_model.at(e);
  }
}

// Each object's air comes from the newest orientation whose wall jet has reached it, formed over
// time in the CFD's air (sim/reached_air.h). The transport is enabled in the CFD's air, and in
// the analytical air with analytical_air_transport (TwinParameters::air_transport).
void Twin::Impl::set_object_air() {
  air.clear_object_air();
  if (transport && !transport->steady()) {
    lagged_rays.clear();
    for (size_t o = 0; o < scene.objects.size(); ++o) {
      const double* x = data->xpos + 3 * scene.objects[o].root_body;
      const int k = transport->reached_steps(Eigen::Vector2d(x[0], x[1]));
      if (k == 0) continue;
      auto it = std::find_if(lagged_rays.begin(), lagged_rays.end(),
                             [k](const auto& f) { return f.first == k; });
      if (it == lagged_rays.end()) {
        lagged_rays.emplace_back(k, field_model.rays_at(transport->at_lag(k)));
        it = lagged_rays.end() - 1;
      }
      air.set_object_air(o, it->second);
    }
    return;
  }
  if (!reached || !reached->begin_step()) return;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const double* x = data->xpos + 3 * scene.objects[o].root_body;
    const Eigen::Vector2d p(x[0], x[1]);
    const double z = data->xipos[3 * scene.objects[o].root_body + 2];
    const ReachedAir::PointAir a = reached->at(o, p, z);
    if (a.departure.squaredNorm() > 0.0) air.set_object_air_departure(o, a.departure);
    if (a.field) air.set_object_air(o, *a.field);
  }
}

std::string Twin::Impl::object_label(int body) const {
  if (body >= 0) {
    const int root = scene.model->body_rootid[body];
    for (const SceneObject& o : scene.objects) {
      if (o.root_body == root) return "object '" + o.id + "'";
    }
  }
  return "the nozzle rig";
}

// After a step: air faults, MuJoCo's bad-state warnings (it resets the state on them) and
// non-finite or runaway object states end the run with the object and the time.
void Twin::Impl::check_state() {
  const mjModel* m = scene.model.get();
  const mjData* d = data.get();
  // The message prefix is built only when something went wrong (this runs every step).
  auto when = [&] {
    std::ostringstream s;
    s << "twin: at t = " << static_cast<double>(steps) * params.scene.timestep_s << " s: ";
    return s.str();
  };
  if (!air.fault().empty()) throw SimulationError(when() + air.fault());
  ThreadWarnings w = take_thread_warnings();
  if (w.count > 0) last_warning = w.last_message;
  for (int kind : {mjWARN_BADQACC, mjWARN_BADQVEL, mjWARN_BADQPOS}) {
    if (d->warning[kind].number > 0) {
      const int dof = d->warning[kind].lastinfo;
      const int body = (dof >= 0 && dof < m->nv) ? m->dof_bodyid[dof] : -1;
      throw SimulationError(when() + object_label(body) +
                            " diverged (MuJoCo found a non-finite or huge state and reset it: " +
                            (last_warning.empty() ? std::string("bad state") : last_warning) + ")");
    }
  }
  for (const SceneObject& o : scene.objects) {
    for (int b : o.bodies) {
      const double* p = d->xipos + 3 * b;
      if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) {
        throw SimulationError(when() + "object '" + o.id + "' has a non-finite position");
      }
    }
    const int dof = m->jnt_dofadr[m->body_jntadr[o.root_body]];
    const double* v = d->qvel + dof;
    if (!(std::abs(v[0]) < 100.0 && std::abs(v[1]) < 100.0 && std::abs(v[2]) < 100.0)) {
      throw SimulationError(when() + "object '" + o.id +
                            "' moves faster than 100 m/s: the simulation blew up");
    }
  }
}

Twin::Twin(const SceneSpec& spec, const TwinParameters& params, const AirFieldModel& field_model,
           uint64_t seed) {
  install_mujoco_handlers();
  params.nozzle.validate();
  params.air.validate();
  params.air_transport.validate();
  if (params.nozzle.tilt_max_rad >= fold_tilt_rad(field_model.geometry())) {
    throw InputError("nozzle parameters: tilt_max_rad " +
                     std::to_string(rad_to_deg(params.nozzle.tilt_max_rad)) +
                     " deg reaches the field model's fold at " +
                     std::to_string(rad_to_deg(fold_tilt_rad(field_model.geometry()))) + " deg");
  }
  if (params.cfd_air) {
    const CfdField& cfd = *params.cfd_air;
    if (params.nozzle.tilt_min_rad < cfd.min_tilt_rad() - 1e-9 ||
        params.nozzle.tilt_max_rad > cfd.max_tilt_rad() + 1e-9) {
      throw InputError("nozzle parameters: tilt range [" +
                       std::to_string(rad_to_deg(params.nozzle.tilt_min_rad)) + ", " +
                       std::to_string(rad_to_deg(params.nozzle.tilt_max_rad)) +
                       "] deg is not covered by the CFD cases' [" +
                       std::to_string(rad_to_deg(cfd.min_tilt_rad())) + ", " +
                       std::to_string(rad_to_deg(cfd.max_tilt_rad())) + "] deg");
    }
  }
  impl_ = std::make_unique<Impl>(spec, params, field_model, seed);
  impl_->actuator.set_jet(params.jet_on_at_start);
  // The initial configuration, with the rig in place and kinematics computed.
  mj_resetData(impl_->scene.model.get(), impl_->data.get());
  impl_->set_rig_joints();
  mj_forward(impl_->scene.model.get(), impl_->data.get());
  // Let the objects come to rest (no air scope is registered, so no air force acts).
  if (!(std::isfinite(params.settle_time_s) && params.settle_time_s >= 0)) {
    throw InputError("twin parameters: settle_time_s must be >= 0");
  }
  const int64_t settle_steps = std::llround(params.settle_time_s / params.scene.timestep_s);
  for (int64_t k = 0; k < settle_steps; ++k) {
    mj_step(impl_->scene.model.get(), impl_->data.get());
  }
  impl_->data->time = 0.0;
  mj_forward(impl_->scene.model.get(), impl_->data.get());
  impl_->check_state();
}

Twin::~Twin() = default;
Twin::Twin(Twin&&) noexcept = default;
Twin& Twin::operator=(Twin&&) noexcept = default;

void Twin::step() {
  Impl& s = *impl_;
  s.actuator.step();
  s.set_rig_joints();
  s.refresh_field();
  if (s.reached) s.reached->push(s.actuator.effective(), *s.cfd_field);
  if (s.transport) s.transport->push(s.actuator.effective(), s.field.stagnation_point());
  if (s.cfd_field) {
    s.air.set_air(*s.cfd_field, s.actuator.jet_level());
  } else {
    s.air.set_air(s.field, s.actuator.jet_level());
  }
  s.set_object_air();
  s.air.advance_turbulence();
  s.air.advance_friction();
  {
    AirForcesScope scope(s.scene.model.get(), &s.air);
    mj_step(s.scene.model.get(), s.data.get());
  }
  // mj_step integrated the rig's hinges over the step; put them back on the servo angles.
  s.set_rig_joints();
  ++s.steps;
  s.check_state();
}

void Twin::advance_to(double t_s) {
  if (!std::isfinite(t_s)) throw InputError("twin: advance_to needs a finite time");
  const int64_t target = std::llround(t_s / impl_->params.scene.timestep_s);
  while (impl_->steps < target) step();
}

void Twin::advance(double duration_s) { advance_to(time() + duration_s); }

void Twin::command_nozzle(const NozzleOrientation& target) { impl_->actuator.command(target); }
void Twin::set_jet(bool on) { impl_->actuator.set_jet(on); }
void Twin::settle_jet() { impl_->actuator.settle_jet(); }

double Twin::time() const {
  return static_cast<double>(impl_->steps) * impl_->params.scene.timestep_s;
}
int64_t Twin::step_count() const { return impl_->steps; }
double Twin::timestep() const { return impl_->params.scene.timestep_s; }
NozzleOrientation Twin::commanded_orientation() const { return impl_->actuator.commanded(); }
NozzleOrientation Twin::actual_orientation() const { return impl_->actuator.actual(); }
NozzleOrientation Twin::effective_orientation() const { return impl_->actuator.effective(); }
double Twin::jet_level() const { return impl_->actuator.jet_level(); }
const OrientedField& Twin::field() const {
  Impl& s = *impl_;
  if (!same_orientation(s.actuator.effective(), s.field.orientation())) {
    s.field = s.field_model.at(s.actuator.effective());  // in the CFD's air, built when asked
  }
  return s.field;
}
Eigen::Vector2d Twin::stagnation_point() const {
  return impl_->cfd_field ? impl_->cfd_field->stagnation_point() : impl_->field.stagnation_point();
}

size_t Twin::object_count() const { return impl_->scene.objects.size(); }
const SceneObject& Twin::object(size_t i) const {
  AIRTWIN_DEMAND(i < impl_->scene.objects.size());
  return impl_->scene.objects[i];
}

void Twin::push_object(size_t i, const Eigen::Vector2d& force_W) {
  const SceneObject& o = object(i);
  if (!force_W.allFinite()) {
    throw InputError("twin: push on object '" + o.id + "': the force must be finite");
  }
  const mjModel* m = impl_->scene.model.get();
  mjData* d = impl_->data.get();
  // Each body takes its share of the mass, so the object accelerates as one without turning.
  for (int b : o.bodies) {
    const double share = m->body_mass[b] / o.mass_kg;
    d->xfrc_applied[6 * b] = share * force_W.x();
    d->xfrc_applied[6 * b + 1] = share * force_W.y();
  }
}

ObjectMotion Twin::object_state(size_t i) const {
  const SceneObject& o = object(i);
  const mjModel* m = impl_->scene.model.get();
  const mjData* d = impl_->data.get();
  ObjectMotion state;
  for (size_t k = 0; k < o.bodies.size(); ++k) {
    const int b = o.bodies[k];
    const double w = o.area_share[k];
    if (w == 0.0) continue;
    state.p_W += w * Eigen::Vector2d(d->xipos[3 * b], d->xipos[3 * b + 1]);
    state.v_W += w * body_com_velocity(m, d, b).head<2>();
  }
  return state;
}

std::vector<ObjectMotion> Twin::object_states() const {
  std::vector<ObjectMotion> states;
  states.reserve(object_count());
  for (size_t i = 0; i < object_count(); ++i) states.push_back(object_state(i));
  return states;
}

int Twin::warning_count() const {
  int total = 0;
  for (int k = 0; k < mjNWARNING; ++k) total += impl_->data->warning[k].number;
  return total;
}
const std::string& Twin::last_warning() const { return impl_->last_warning; }
const mjModel* Twin::model() const { return impl_->scene.model.get(); }
const mjData* Twin::data() const { return impl_->data.get(); }
const std::string& Twin::scene_xml() const { return impl_->scene.xml; }
const AirForces& Twin::air_forces() const { return impl_->air; }
const NozzleActuator& Twin::actuator() const { return impl_->actuator; }

}  // namespace airtwin
