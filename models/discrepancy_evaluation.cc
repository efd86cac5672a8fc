#include "models/discrepancy_evaluation.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "common/parallel_for.h"

namespace airtwin::discrepancy_detail {

double robust_cost(double e) {
  const double c2 = kRobustScale * kRobustScale;
  return 2.0 * c2 * (std::sqrt(1.0 + e * e / c2) - 1.0);
}

std::map<std::string, ModelExtensions> extensions_by_type(const ModelExtensions& ext,
                                                          const WindowSet& ws,
                                                          const std::vector<size_t>& which) {
  std::map<std::string, ModelExtensions> typed;
  if (ext.object_by_type.empty()) return typed;
  for (size_t i : which) {
    const std::string& type = *ws.windows[i].type;
    if (typed.find(type) == typed.end()) typed.emplace(type, ext.for_type(type));
  }
  return typed;
}

size_t Evaluator::Kept::bytes() const {
  return sizeof(Kept) + which.size() * sizeof(size_t) + scores.size() * sizeof(WindowScore) +
         static_cast<size_t>(residuals.size()) * sizeof(double);
}

size_t Evaluator::repeats_answered() const {
  std::lock_guard<std::mutex> lock(kept_mutex_);
  return answered_;
}

size_t Evaluator::evaluations_predicted() const {
  std::lock_guard<std::mutex> lock(kept_mutex_);
  return predicted_;
}

void Evaluator::evaluate(const ModelExtensions& ext, const std::vector<size_t>& which,
                         std::vector<WindowScore>* scores, Eigen::VectorXd* residuals,
                         Fidelity fidelity) const {
  {
    std::lock_guard<std::mutex> lock(kept_mutex_);
    for (auto it = kept_.begin(); it != kept_.end(); ++it) {
      if (it->fidelity != fidelity || !(it->ext == ext) || it->which != which) continue;
      if (residuals != nullptr && !it->has_residuals) break;  // predicted again, kept with them
      *scores = it->scores;
      if (residuals != nullptr) *residuals = it->residuals;
      kept_.splice(kept_.begin(), kept_, it);
      ++answered_;
      return;
    }
  }
  predict(ext, which, scores, residuals, fidelity);
  Kept k{fidelity,
         which,
         ext,
         *scores,
         residuals != nullptr,
         residuals != nullptr ? *residuals : Eigen::VectorXd()};
  const size_t bytes = k.bytes();
  std::lock_guard<std::mutex> lock(kept_mutex_);
  ++predicted_;
  if (bytes > kMemoBytes) return;
  // A result kept without residuals that these now have is superseded.
  for (auto it = kept_.begin(); it != kept_.end(); ++it) {
    if (it->fidelity == fidelity && it->ext == ext && it->which == which) {
      kept_bytes_ -= it->bytes();
      kept_.erase(it);
      break;
    }
  }
  kept_.push_front(std::move(k));
  kept_bytes_ += bytes;
  while (kept_bytes_ > kMemoBytes || kept_.size() > kMemoEntries) {
    kept_bytes_ -= kept_.back().bytes();
    kept_.pop_back();
  }
}

void Evaluator::predict(const ModelExtensions& ext, const std::vector<size_t>& which,
                        std::vector<WindowScore>* scores, Eigen::VectorXd* residuals,
                        Fidelity fidelity) const {
  const ExtendedPredictor& predictor = fidelity == Fidelity::kFull ? predictor_ : screen_;
  scores->assign(which.size(), {});
  std::vector<size_t> offsets(which.size() + 1, 0);
  for (size_t i = 0; i < which.size(); ++i) {
    offsets[i + 1] = offsets[i] + 2 * ws_.windows[which[i]].times.size();
  }
  if (residuals != nullptr) residuals->setZero(static_cast<Eigen::Index>(offsets.back()));
  const std::map<std::string, ModelExtensions> typed = extensions_by_type(ext, ws_, which);
  auto felt_in = [&](const Window& w) -> const ModelExtensions& {
    return typed.empty() ? ext : typed.at(*w.type);
  };
  // Each window's track made ready first, once per window (a bootstrap's resample names some
  // windows several times), and only read while the windows are predicted.
  const int f = static_cast<int>(fidelity);
  std::vector<size_t> distinct = which;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  parallel_for(distinct.size(), static_cast<int>(std::min<size_t>(threads_, distinct.size())),
               [&](size_t j) {
                 const Window& w = ws_.windows[distinct[j]];
                 const ModelExtensions& felt = felt_in(w);
                 TrackSlot& s = tracks_[distinct[j]][f];
                 std::optional<OrientationTrack>& slot = s.track;
                 if (felt.transport_pace_s_per_m > 0.0 || w.times.empty() ||
                     (slot && slot->serves(felt, *w.timeline, w.start.t_s, predictor.step_s()))) {
                   return;
                 }
                 const bool again = s.asked && s.extra_delay_s == felt.extra_delay_s &&
                                    s.pan_offset_rad == felt.pan_offset_rad &&
                                    s.tilt_offset_rad == felt.tilt_offset_rad;
                 s.asked = !again;
                 s.extra_delay_s = felt.extra_delay_s;
                 s.pan_offset_rad = felt.pan_offset_rad;
                 s.tilt_offset_rad = felt.tilt_offset_rad;
                 if (!again) return;
                 if (slot) track_bytes_ -= slot->bytes();
                 slot = predictor.track(felt, *w.timeline, w.start.t_s, w.times.back());
                 track_bytes_ += slot->bytes();
                 if (track_bytes_ > kTrackBytes) {  // over the bound: this window goes without
                   track_bytes_ -= slot->bytes();
                   slot.reset();
                 }
               });
  auto work = [&](size_t begin, size_t end) {
    std::vector<Eigen::Vector2d> predicted;
    for (size_t i = begin; i < end; ++i) {
      const Window& w = ws_.windows[which[i]];
      const ModelExtensions& felt = felt_in(w);
      const std::optional<OrientationTrack>& slot = tracks_[which[i]][f].track;
      const OrientationTrack* track = slot ? &*slot : nullptr;  // predict() reads it if it serves
      predictor.predict(*w.xi, felt, *w.timeline, w.start, w.times, &predicted, track);
      const double norm = 1.0 / (w.scale_m * std::sqrt(static_cast<double>(w.times.size())));
      double sum = 0.0;
      for (size_t k = 0; k < w.times.size(); ++k) {
        const Eigen::Vector2d e = (predicted[k] - w.measured[k]) * norm;
        sum += e.squaredNorm();
        if (residuals != nullptr) {
          (*residuals)[static_cast<Eigen::Index>(offsets[i] + 2 * k)] = e.x();
          (*residuals)[static_cast<Eigen::Index>(offsets[i] + 2 * k + 1)] = e.y();
        }
      }
      WindowScore& sc = (*scores)[i];
      sc.path_error = std::sqrt(sum);
      if (residuals != nullptr && sum > 0.0) {
        // Soft-L1: the window's squares sum to robust_cost(path_error) instead of its square.
        const double f = std::sqrt(robust_cost(sc.path_error) / sum);
        residuals->segment(static_cast<Eigen::Index>(offsets[i]),
                           static_cast<Eigen::Index>(offsets[i + 1] - offsets[i])) *= f;
      }
      // Percent of the distance travelled, at least the window's scale (5 cm), so that every
      // window counts with one fixed denominator whatever the model predicts.
      sc.end_pct = 100.0 * (predicted.back() - w.measured.back()).norm() / w.scale_m;
      sc.predicted_travel_m = (predicted.back() - w.start.p_W).norm();
    }
  };
  // Windows in small chunks handed out to the threads as they come free (a window where the
  // object moves costs many times one where it rests): each window's figures are its own, so the
  // result does not depend on the thread count.
  const size_t n = which.size();
  const size_t chunk = 2;
  const size_t items = (n + chunk - 1) / chunk;
  parallel_for(items, static_cast<int>(std::min<size_t>(threads_, items)),
               [&](size_t j) { work(j * chunk, std::min(n, (j + 1) * chunk)); });
}

double sum_squares(const std::vector<WindowScore>& s) {
  double sum = 0.0;
  for (const WindowScore& w : s) sum += robust_cost(w.path_error);
  return sum;
}
double mean_path_error(const std::vector<WindowScore>& s, const std::vector<char>& informative) {
  std::vector<double> e;
  for (size_t i = 0; i < s.size(); ++i) {
    if (informative[i]) e.push_back(s[i].path_error);
  }
  if (e.empty()) return NAN;
  const size_t mid = e.size() / 2;
  std::nth_element(e.begin(), e.begin() + static_cast<long>(mid), e.end());
  if (e.size() % 2 == 1) return e[mid];
  const double upper = e[mid];
  std::nth_element(e.begin(), e.begin() + static_cast<long>(mid) - 1, e.end());
  return 0.5 * (upper + e[mid - 1]);
}
double end_mape(const std::vector<WindowScore>& s, size_t* n) {
  double sum = 0.0;
  size_t count = 0;
  for (const WindowScore& w : s) {
    if (std::isfinite(w.end_pct)) {
      sum += w.end_pct;
      ++count;
    }
  }
  if (n != nullptr) *n = count;
  return count == 0 ? NAN : sum / static_cast<double>(count);
}

}  // namespace airtwin::discrepancy_detail
