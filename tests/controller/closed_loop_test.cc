#include "controller/closed_loop.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.h"
#include "models/cvode_predictor.h"

namespace airtwin {
namespace {

// A rig whose objects obey the controller's own model exactly (eqs. 8-9 integrated by CVODE
// under the commanded orientation, applied at once): what the loop does with perfect physics.
class ModelRig final : public Rig {
 public:
  ModelRig(const AirFieldModel& model, std::vector<ObservedObject> objects)
      : model_(model), objects_(std::move(objects)), v_(objects_.size(), 0.0) {}

  Observation observe() override {
    ++observations_;
    Observation o;
    o.t_s = t_;
    for (size_t j = 0; j < objects_.size(); ++j) {
      if (hide_every_ > 0 && j == 0 && observations_ % hide_every_ == 0) continue;
      if (hide_from_ > 0 && j == 0 && observations_ >= hide_from_) {
        o.out_of_view = report_hidden_out_of_view_ ? 1 : 0;
        continue;
      }
      o.objects.push_back(objects_[j]);
    }
    return o;
  }
  void aim(const NozzleOrientation& target) override {
    orientation_ = target;
    ++aims_;
    aim_times_.push_back(t_);
    aim_positions_.push_back(objects_[0].p_W);
  }
  void wait(double duration_s) override {
    const OrientedField field = model_.at(orientation_);
    std::vector<ObjectDynamics> xi;
    std::vector<ObjectState> start;
    for (size_t j = 0; j < objects_.size(); ++j) {
      xi.push_back(objects_[j].type == "tracer" ? kTracerDynamics : kCottonDynamics);
      const Eigen::Vector2d e = (objects_[j].p_W - field.stagnation_point()).normalized();
      start.push_back(ObjectState{objects_[j].p_W, std::max(0.0, objects_[j].v_W.dot(e))});
    }
    const Prediction p = cvode_.predict(field, xi, start, PredictionOptions{duration_s, 0.0});
    for (size_t j = 0; j < objects_.size(); ++j) {
      const Eigen::Vector2d e = (p.end[j].p_W - field.stagnation_point()).normalized();
      objects_[j].p_W = p.end[j].p_W;
      objects_[j].v_W = p.end[j].v * e;
    }
    t_ += duration_s;
  }
  double time() const override { return t_; }

  int aims_ = 0;
  std::vector<double> aim_times_;               // rig time of each aim
  std::vector<Eigen::Vector2d> aim_positions_;  // object 0 at each aim
  int hide_every_ = 0;
  int hide_from_ = 0;                       // object 0 unseen from this observation (1-based) on
  bool report_hidden_out_of_view_ = false;  // ... and reported out of view

 private:
  const AirFieldModel& model_;
  CvodePredictor cvode_;
  std::vector<ObservedObject> objects_;
  std::vector<double> v_;
  NozzleOrientation orientation_;
  double t_ = 0.0;
  int observations_ = 0;
};

TaskSpec line_task() {
  TaskSpec t;
  t.kind = TaskKind::kPath;
  t.path_W = {{-0.26, 0.25}, {0.26, 0.25}};
  t.time_limit_s = 120.0;
  return t;
}

TEST(ClosedLoop, FollowsALineUnderItsOwnModel) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  ModelRig rig(model, {ObservedObject{"t1", "tracer", {-0.26, 0.25}, {0, 0}}});
  CemParameters cem = CemParameters::line_defaults();
  cem.mean0_m = 0.3;
  cem.variance0_m2 = 40e-4;
  Controller controller(model, cem, line_task(), {{"tracer", kTracerDynamics}}, 1);
  const LoopResult result = run_closed_loop(rig, controller, LoopOptions{1.5, 120.0});
  ASSERT_TRUE(result.success);
  ASSERT_TRUE(result.completion_time_s.has_value());
  // Six references 10 cm apart: at least a few decisions, and the loop stops when done.
  EXPECT_GE(result.decisions.size(), 3u);
  EXPECT_EQ(rig.aims_, static_cast<int>(result.decisions.size()));
  EXPECT_DOUBLE_EQ(result.end_time_s, 1.5 * static_cast<double>(result.decisions.size()));
  // Decisions are 1.5 s apart and look at the rig's clock.
  for (size_t k = 0; k < result.decisions.size(); ++k) {
    EXPECT_DOUBLE_EQ(result.decisions[k].t_s, 1.5 * static_cast<double>(k));
  }
  EXPECT_LT((controller.known().at("t1").p_W - Eigen::Vector2d(0.26, 0.25)).norm(), 0.04);
}

TEST(ClosedLoop, StopsAtTheTimeLimitAndRemembersUnseenObjects) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  // Two objects, the first hidden from every other observation: the controller keeps planning
  // for both.
  ModelRig rig(model, {ObservedObject{"a", "tracer", {0.5, 0.0}, {0, 0}},
                       ObservedObject{"b", "tracer", {-0.5, 0.1}, {0, 0}}});
  rig.hide_every_ = 2;
  TaskSpec agg;
  agg.kind = TaskKind::kAggregation;
  agg.zone = Zone{{0.0, 0.0}, 0.01};  // too small to reach: the limit ends the run
  agg.time_limit_s = 6.0;
  Controller controller(model, CemParameters::line_defaults(), agg, {{"tracer", kTracerDynamics}},
                        2);
  const LoopResult result = run_closed_loop(rig, controller, LoopOptions{1.8, 6.0});
  EXPECT_FALSE(result.success);
  EXPECT_DOUBLE_EQ(result.end_time_s, 6.0);
  ASSERT_FALSE(result.decisions.empty());
  for (const auto& d : result.decisions) EXPECT_EQ(d.n_known, 2);
  EXPECT_EQ(result.decisions[1].n_observed, 1);
}

TEST(ClosedLoop, ObjectsUnseenTooLongAreForgotten) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  ModelRig rig(model, {ObservedObject{"a", "tracer", {0.5, 0.0}, {0, 0}},
                       ObservedObject{"b", "tracer", {-0.5, 0.1}, {0, 0}}});
  rig.hide_from_ = 2;  // "a" is seen at t = 0 only
  TaskSpec agg;
  agg.kind = TaskKind::kAggregation;
  agg.zone = Zone{{0.0, 0.0}, 0.01};
  agg.time_limit_s = 8.0;
  Controller controller(model, CemParameters::line_defaults(), agg, {{"tracer", kTracerDynamics}},
                        2, /*forget_after_s=*/3.0);
  const LoopResult result = run_closed_loop(rig, controller, LoopOptions{1.8, 8.0});
  // Observations at 0, 1.8, 3.6, 5.4, 7.2 s: "a" is remembered until 3 s have passed.
  ASSERT_GE(result.decisions.size(), 4u);
  EXPECT_EQ(result.decisions[0].n_known, 2);
  EXPECT_EQ(result.decisions[1].n_known, 2);
  EXPECT_EQ(result.decisions[2].n_known, 1);
  EXPECT_EQ(controller.known().count("a"), 0u);
}

// An object the perception lost for good (blown out of the camera's view) is forgotten; the rig
// says it is out of view, and the one still seen being in the zone does not finish the task.
TEST(ClosedLoop, AnObjectOutOfViewKeepsTheTaskOpen) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  TaskSpec agg;
  agg.kind = TaskKind::kAggregation;
  agg.zone = Zone{{-0.5, 0.1}, 0.3};  // "b" starts inside, "a" outside
  agg.time_limit_s = 8.0;
  for (const bool reported : {false, true}) {
    ModelRig rig(model, {ObservedObject{"a", "tracer", {0.5, 0.0}, {0, 0}},
                         ObservedObject{"b", "tracer", {-0.5, 0.1}, {0, 0}}});
    rig.hide_from_ = 2;  // "a" is seen at t = 0 only
    rig.report_hidden_out_of_view_ = reported;
    Controller controller(model, CemParameters::line_defaults(), agg, {{"tracer", kTracerDynamics}},
                          2, /*forget_after_s=*/3.0);
    const LoopResult result = run_closed_loop(rig, controller, LoopOptions{1.8, 8.0});
    EXPECT_EQ(result.objects_seen_at_end, 1) << reported;
    if (reported) {
      EXPECT_FALSE(result.success);
      EXPECT_DOUBLE_EQ(result.end_time_s, 8.0);
    } else {
      // Hidden, not out of view (as in a merge): done once "a" is forgotten (at the observation
      // at 3.6 s), as long as "b" stayed in the zone.
      EXPECT_TRUE(result.success);
      EXPECT_LT(result.end_time_s, 8.0);
    }
  }
}

// The only object blown out of the camera's view for good: once it is forgotten there is
// nothing to plan for, and the run ends there, failed (it used to throw, which ended a whole
// batch on one run's outcome).
TEST(ClosedLoop, EndsFailedWhenEveryObjectIsLost) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  ModelRig rig(model, {ObservedObject{"a", "tracer", {0.5, 0.0}, {0, 0}}});
  rig.hide_from_ = 2;  // seen at t = 0 only
  rig.report_hidden_out_of_view_ = true;
  TaskSpec agg;
  agg.kind = TaskKind::kAggregation;
  agg.zone = Zone{{0.0, 0.0}, 0.01};
  agg.time_limit_s = 30.0;
  Controller controller(model, CemParameters::line_defaults(), agg, {{"tracer", kTracerDynamics}},
                        2, /*forget_after_s=*/3.0);
  const LoopResult result = run_closed_loop(rig, controller, LoopOptions{1.8, 30.0});
  EXPECT_FALSE(result.success);
  EXPECT_TRUE(result.lost_every_object);
  EXPECT_EQ(result.objects_seen_at_end, 0);
  // Observations at 0, 1.8, 3.6 s: unseen for 3.6 s > 3 s at the third, and no decision after it.
  EXPECT_DOUBLE_EQ(result.end_time_s, 3.6);
  EXPECT_EQ(result.decisions.size(), 2u);
  EXPECT_TRUE(controller.known().empty());
}

// A latency between each observation and its aim: the objects move on under the previous
// command meanwhile, and every turn of the loop takes the latency longer.
TEST(ClosedLoop, AimsALatencyAfterItsObservation) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const ObservedObject start{"t1", "tracer", {-0.26, 0.25}, {0, 0}};
  ModelRig rig(model, {start});
  CemParameters cem = CemParameters::line_defaults();
  cem.mean0_m = 0.3;
  cem.variance0_m2 = 40e-4;
  Controller controller(model, cem, line_task(), {{"tracer", kTracerDynamics}}, 1);
  const LoopResult result = run_closed_loop(rig, controller, LoopOptions{1.5, 120.0, 0.4});
  ASSERT_GE(result.decisions.size(), 2u);
  ASSERT_EQ(rig.aim_times_.size(), result.decisions.size());
  for (size_t k = 0; k < result.decisions.size(); ++k) {
    EXPECT_NEAR(result.decisions[k].t_s, 1.9 * static_cast<double>(k), 1e-12);
    EXPECT_NEAR(rig.aim_times_[k], result.decisions[k].t_s + 0.4, 1e-12);
  }
  // Before the first aim the tracer moved 0.4 s in the rig's starting air (s at the nozzle's
  // foot, 36 cm away): where a rig that only waits puts it, and not where it was seen.
  ModelRig waited(model, {start});
  waited.wait(0.4);
  const Eigen::Vector2d moved = waited.observe().objects[0].p_W;
  EXPECT_EQ(rig.aim_positions_[0], moved);
  EXPECT_GT((moved - start.p_W).norm(), 0.01);
  EXPECT_NE(result.decisions[0].objects[0].p_W, moved);  // planned from the observation

  // A latency past the time limit aims at the limit and ends the run there.
  ModelRig late(model, {start});
  Controller again(model, cem, line_task(), {{"tracer", kTracerDynamics}}, 1);
  const LoopResult cut = run_closed_loop(late, again, LoopOptions{1.5, 1.0, 5.0});
  EXPECT_FALSE(cut.success);
  EXPECT_DOUBLE_EQ(cut.end_time_s, 1.0);
  ASSERT_EQ(late.aim_times_.size(), 1u);
  EXPECT_DOUBLE_EQ(late.aim_times_[0], 1.0);
}

TEST(ClosedLoop, UnknownTypeAndBadOptionsAreInputErrors) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  ModelRig rig(model, {ObservedObject{"g", "glass", {0.3, 0.0}, {0, 0}}});
  Controller controller(model, CemParameters::line_defaults(), line_task(),
                        {{"tracer", kTracerDynamics}}, 1);
  EXPECT_THROW(run_closed_loop(rig, controller, LoopOptions{1.5, 10.0}), InputError);
  EXPECT_THROW(run_closed_loop(rig, controller, LoopOptions{0.0, 10.0}), InputError);
  EXPECT_THROW(run_closed_loop(rig, controller, LoopOptions{1.5, 10.0, -0.1}), InputError);
  EXPECT_THROW(run_closed_loop(rig, controller, LoopOptions{1.5, 10.0, std::nan("")}), InputError);
}

}  // namespace
}  // namespace airtwin
