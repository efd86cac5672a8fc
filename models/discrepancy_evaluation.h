#pragma once
// The discrepancy analysis's evaluator (models/discrepancy.h, steps 1-2): every window predicted
// under one set of model extensions, its normalised path error, end error and the residuals the
// fits minimise, with the robust loss they use. Internal to the analysis.

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <cstddef>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "models/air_field.h"
#include "models/discrepancy_windows.h"
#include "models/extended_predictor.h"
#include "models/model_extensions.h"

namespace airtwin::discrepancy_detail {

// The fits weigh each window's normalised path error e by the soft-L1 loss
// rho(e) = 2 c^2 (sqrt(1 + (e / c)^2) - 1): quadratic below c, linear above, so that the few
// windows where a start or a stop goes the other way (an object near its threshold) do not
// dominate the fit. c = 0.25 of a window's scale.
constexpr double kRobustScale = 0.25;
double robust_cost(double e);

// Per-window figures of one model.
struct WindowScore {
  double path_error = 0.0;          // RMS normalised position error
  double end_pct = NAN;             // percent of the window's scale
  double predicted_travel_m = 0.0;  // predicted displacement over the window
};

// How finely a window is integrated: at the analysis's step, or at the coarser screening step
// for the fits' grids, which only rank starting points (their best few are scored again at the
// full step).
enum class Fidelity { kFull, kScreen };

// Evaluations are pure: the same extensions on the same windows at the same fidelity give the
// same figures. The fits ask for many twice (a grid's point scored again at the full step, the
// compass's and Levenberg-Marquardt's revisits, a candidate's fit seen again by the selection), a
// third of the prediction work of an Appendix D analysis; the evaluator keeps its latest results
// (at most kMemoEntries, kMemoBytes) and answers a repeat from them.
class Evaluator {
 public:
  static constexpr size_t kMemoEntries = 256;
  static constexpr size_t kMemoBytes = size_t{32} << 20;

  Evaluator(const AirFieldModel& field, const WindowSet& ws, double step_s, double screen_step_s)
      : predictor_(field, step_s),
        screen_(field, screen_step_s),
        ws_(ws),
        tracks_(ws.windows.size()) {
    const unsigned hw = std::thread::hardware_concurrency();
    threads_ = std::clamp<unsigned>(hw == 0 ? 1 : hw, 1, 8);
  }

  const ExtendedPredictor& predictor() const { return predictor_; }

  // Predicts windows `which` under `ext`: scores, and (optionally) the normalised residuals,
  // 2 per sample, each divided by sqrt(samples) so that a window's squares sum to its
  // path_error^2.
  void evaluate(const ModelExtensions& ext, const std::vector<size_t>& which,
                std::vector<WindowScore>* scores, Eigen::VectorXd* residuals,
                Fidelity fidelity = Fidelity::kFull) const;

  size_t residual_count(const std::vector<size_t>& which) const {
    size_t n = 0;
    for (size_t i : which) n += 2 * ws_.windows[i].times.size();
    return n;
  }

  // Evaluations answered from the kept results, and predicted.
  size_t repeats_answered() const;
  size_t evaluations_predicted() const;

 private:
  struct Kept {
    Fidelity fidelity;
    std::vector<size_t> which;
    ModelExtensions ext;
    std::vector<WindowScore> scores;
    bool has_residuals = false;
    Eigen::VectorXd residuals;
    size_t bytes() const;
  };
  void predict(const ModelExtensions& ext, const std::vector<size_t>& which,
               std::vector<WindowScore>* scores, Eigen::VectorXd* residuals,
               Fidelity fidelity) const;

  ExtendedPredictor predictor_;
  ExtendedPredictor screen_;
  const WindowSet& ws_;
  unsigned threads_ = 1;
  // Each window's orientations at each fidelity (ExtendedPredictor::track), for the latest
  // response delay and nozzle offset it was predicted under; at most kTrackBytes in all. Made
  // ready before the windows are predicted (evaluate() is not called concurrently).
  // A track is made when a window is predicted a second time in a row under the same delay and
  // offset (a fit of the nozzle offset changes them at every evaluation: no track would serve).
  static constexpr size_t kTrackBytes = size_t{96} << 20;
  struct TrackSlot {
    std::optional<OrientationTrack> track;
    bool asked = false;  // the last evaluation's delay and offset, when no track serves them
    double extra_delay_s = 0.0, pan_offset_rad = 0.0, tilt_offset_rad = 0.0;
  };
  mutable std::vector<std::array<TrackSlot, 2>> tracks_;
  mutable std::atomic<size_t> track_bytes_{0};
  mutable std::mutex kept_mutex_;
  mutable std::list<Kept> kept_;  // the latest first
  mutable size_t kept_bytes_ = 0, answered_ = 0, predicted_ = 0;
};

// `ext` as each type among windows `which` of `ws` feels it (ModelExtensions::for_type); empty
// when `ext` has no effects of one type alone (every window then feels `ext`).
std::map<std::string, ModelExtensions> extensions_by_type(const ModelExtensions& ext,
                                                          const WindowSet& ws,
                                                          const std::vector<size_t>& which);

// The fits' cost: the robust sum over windows.
double sum_squares(const std::vector<WindowScore>& s);
// The typical path error: the median over the windows marked informative (robust to the same
// few windows; windows where nothing moved and nothing was predicted to move, e.g. objects
// parked in a zone for most of a closed-loop log, would make it 0 whatever the model).
double mean_path_error(const std::vector<WindowScore>& s, const std::vector<char>& informative);
// The mean end-position error in percent of the windows' scales over the finite ones (their
// count in *n).
double end_mape(const std::vector<WindowScore>& s, size_t* n = nullptr);

}  // namespace airtwin::discrepancy_detail
