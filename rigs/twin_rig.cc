#include "rigs/twin_rig.h"

#include <cmath>

#include "common/errors.h"

namespace airtwin {

Observation TruthPerception::observe(const Twin& twin) {
  Observation o;
  o.t_s = twin.time();
  const std::vector<ObjectMotion> motion = twin.object_states();
  for (size_t i = 0; i < motion.size(); ++i) {
    ObservedObject obj;
    obj.id = twin.object(i).id;
    obj.type = object_type_name(twin.object(i).type);
    obj.p_W = motion[i].p_W;
    obj.v_W = motion[i].v_W;
    o.objects.push_back(std::move(obj));
  }
  return o;
}

TwinRig::TwinRig(Twin& twin, Perception& perception, double frame_rate_hz)
    : twin_(twin), perception_(perception), rate_hz_(frame_rate_hz) {
  if (!(std::isfinite(frame_rate_hz) && frame_rate_hz > 0.0 && frame_rate_hz <= 1000.0)) {
    throw InputError("rig: the camera frame rate must be in (0, 1000] Hz");
  }
  frame_ = std::llround(twin_.time() * rate_hz_);
}

void TwinRig::add_frame_observer(FrameObserver observer) {
  observers_.push_back(std::move(observer));
}

void TwinRig::show_frame() {
  perception_.on_frame(twin_, frame_);
  for (const auto& obs : observers_) obs(twin_, frame_);
}

Observation TwinRig::observe() {
  if (!started_) {
    started_ = true;
    show_frame();
  }
  return perception_.observe(twin_);
}

void TwinRig::aim(const NozzleOrientation& target) { twin_.command_nozzle(target); }

void TwinRig::wait(double duration_s) {
  if (!(std::isfinite(duration_s) && duration_s >= 0.0)) {
    throw InputError("rig: wait needs a finite duration >= 0 s");
  }
  if (!started_) {
    started_ = true;
    show_frame();
  }
  const int64_t frames = std::llround(duration_s * rate_hz_);
  for (int64_t k = 0; k < frames; ++k) {
    ++frame_;
    twin_.advance_to(static_cast<double>(frame_) / rate_hz_);
    show_frame();
  }
}

double TwinRig::time() const { return twin_.time(); }

}  // namespace airtwin
