#pragma once
// The twin as a rig (controller/rig.h): aim() commands the twin's servos, wait() steps the physics
// camera frame by camera frame (40 Hz of simulation time), observe() reports what a perception
// sees. Two perceptions:
//  - TruthPerception (the fast mode): the twin's own object states, ids and types.
//  - the detection pipeline on rendered frames (rigs/vision_perception.h, `--vision`).
// Frame observers (logging, metrics, video) see every camera frame, whichever the perception.

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "controller/rig.h"
#include "sim/twin.h"

namespace airtwin {

/// What the controller is told about the objects.
class Perception {
 public:
  virtual ~Perception() = default;
  /// Called on every camera frame while the rig waits (and once at the start).
  virtual void on_frame(const Twin& twin, int64_t frame_index) = 0;
  /// The objects as perceived now (at the last frame).
  virtual Observation observe(const Twin& twin) = 0;
};

/// The twin's ground truth: every object, exact position and velocity.
class TruthPerception final : public Perception {
 public:
  void on_frame(const Twin&, int64_t) override {}
  Observation observe(const Twin& twin) override;
};

class TwinRig final : public Rig {
 public:
  using FrameObserver = std::function<void(const Twin& twin, int64_t frame_index)>;

  /// `twin` and `perception` must outlive the rig. The frame at the twin's current time (frame
  /// 0 at t = 0) is shown to the perception and the observers at the first observe().
  TwinRig(Twin& twin, Perception& perception, double frame_rate_hz = 40.0);

  void add_frame_observer(FrameObserver observer);

  Observation observe() override;
  void aim(const NozzleOrientation& target) override;
  /// Steps frame by frame to time() + duration_s (rounded to whole frames).
  void wait(double duration_s) override;
  double time() const override;

  int64_t frame_index() const { return frame_; }

 private:
  void show_frame();

  Twin& twin_;
  Perception& perception_;
  double rate_hz_;
  int64_t frame_ = 0;
  bool started_ = false;
  std::vector<FrameObserver> observers_;
};

}  // namespace airtwin
