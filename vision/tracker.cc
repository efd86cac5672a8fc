#include "vision/tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "common/errors.h"

namespace airtwin {

void TrackerOptions::validate() const {
  if (!(std::isfinite(max_jump_m) && max_jump_m > 0)) {
    throw InputError("tracker: max_jump_m must be finite and > 0");
  }
  if (max_missed_frames < 0) throw InputError("tracker: max_missed_frames must be >= 0");
  if (velocity_window < 2) throw InputError("tracker: velocity_window must be >= 2");
  if (!(std::isfinite(kind_mismatch_m) && kind_mismatch_m >= 0)) {
    throw InputError("tracker: kind_mismatch_m must be finite and >= 0");
  }
  if (!(std::isfinite(border_margin_px) && border_margin_px >= 0)) {
    throw InputError("tracker: border_margin_px must be finite and >= 0");
  }
  if (image_width_px < 0 || image_height_px < 0) {
    throw InputError("tracker: the image size must be >= 0");
  }
  if (!(std::isfinite(merge_radius_m) && merge_radius_m >= 0)) {
    throw InputError("tracker: merge_radius_m must be finite and >= 0");
  }
}

std::vector<int> solve_assignment(const Eigen::MatrixXd& cost) {
  AIRTWIN_DEMAND(cost.allFinite());
  // The algorithm below wants no more rows than columns: solve the transpose otherwise.
  if (cost.rows() > cost.cols()) {
    const std::vector<int> by_column = solve_assignment(cost.transpose());
    std::vector<int> by_row(cost.rows(), -1);
    for (size_t c = 0; c < by_column.size(); ++c) by_row[by_column[c]] = static_cast<int>(c);
    return by_row;
  }
  // Hungarian algorithm with row and column potentials (shortest augmenting paths), 1-based:
  // column 0 is the virtual start of each augmentation. row_of[j] = row assigned to column j.
  const int n = static_cast<int>(cost.rows()), m = static_cast<int>(cost.cols());
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> row_of(m + 1, 0), way(m + 1, 0);
  for (int i = 1; i <= n; ++i) {
    row_of[0] = i;
    int j0 = 0;
    std::vector<double> min_reduced(m + 1, kInf);
    std::vector<char> used(m + 1, 0);
    // Grow a tree of tight edges from row i until it reaches a free column.
    do {
      used[j0] = 1;
      const int i0 = row_of[j0];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double reduced = cost(i0 - 1, j - 1) - u[i0] - v[j];
        if (reduced < min_reduced[j]) {
          min_reduced[j] = reduced;
          way[j] = j0;
        }
        if (min_reduced[j] < delta) {
          delta = min_reduced[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[row_of[j]] += delta;
          v[j] -= delta;
        } else {
          min_reduced[j] -= delta;
        }
      }
      j0 = j1;
    } while (row_of[j0] != 0);
    // Flip the augmenting path.
    do {
      const int j1 = way[j0];
      row_of[j0] = row_of[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> column_of(n, -1);
  for (int j = 1; j <= m; ++j) {
    if (row_of[j] > 0) column_of[row_of[j] - 1] = j - 1;
  }
  return column_of;
}

Tracker::Tracker(const TrackerOptions& options) : options_(options) { options_.validate(); }

bool Tracker::near_edge(const Eigen::Vector2d& uv) const {
  if (options_.image_width_px <= 0 || options_.image_height_px <= 0) return false;
  const double m = options_.border_margin_px;
  return uv.x() < m || uv.y() < m || uv.x() > options_.image_width_px - 1 - m ||
         uv.y() > options_.image_height_px - 1 - m;
}

void Tracker::record(Track& track, History& history, const Detection& d, double t_s, int index) {
  history.t.push_back(t_s);
  history.p.push_back(d.p_W);
  history.uv.push_back(d.centre_px);
  while (static_cast<int>(history.t.size()) > options_.velocity_window) {
    history.t.pop_front();
    history.p.pop_front();
    history.uv.pop_front();
  }
  // Velocities: least-squares slopes of position (and pixel) against time over the window.
  const size_t n = history.t.size();
  if (n >= 2) {
    double t_mean = 0;
    for (double t : history.t) t_mean += t;
    t_mean /= static_cast<double>(n);
    double stt = 0;
    Eigen::Vector2d stp = Eigen::Vector2d::Zero(), stuv = Eigen::Vector2d::Zero();
    for (size_t k = 0; k < n; ++k) {
      const double dt = history.t[k] - t_mean;
      stt += dt * dt;
      stp += dt * history.p[k];  // sum of dt is 0: no need to centre the positions
      stuv += dt * history.uv[k];
    }
    track.v_W = stp / stt;
    track.v_px = stuv / stt;
  }
  track.p_W = d.p_W;
  track.centre_px = d.centre_px;
  track.t_last_s = t_s;
  if (track.hits == 0) track.t_first_s = t_s;
  ++track.hits;
  track.missed_frames = 0;
  track.detection = index;
  // Kind by majority; a tie keeps the kind it had.
  const int k = static_cast<int>(d.kind);
  ++track.kind_votes[k];
  if (track.kind_votes[k] > track.kind_votes[1 - k]) track.kind = d.kind;
}

const std::vector<Track>& Tracker::update(double t_s, const std::vector<Detection>& detections) {
  if (!std::isfinite(t_s) || (started_ && !(t_s > last_t_s_))) {
    throw InputError("tracker: frame time " + std::to_string(t_s) +
                     " s must be finite and after the previous frame's " +
                     std::to_string(last_t_s_) + " s");
  }
  started_ = true;
  last_t_s_ = t_s;
  ++counters_.frames;
  counters_.detections += static_cast<int64_t>(detections.size());
  ended_.clear();

  // The augmented cost matrix: tracks x detections within the gate, plus a dummy column per
  // track (left unassigned: its gate minus half a jump) and a dummy row per detection (a new
  // track: half a jump), so a pair is assigned only when its cost is below the track's gate.
  const int n_tracks = static_cast<int>(tracks_.size());
  const int n_detections = static_cast<int>(detections.size());
  const int size = n_tracks + n_detections;
  constexpr double kForbidden = 1e9;
  Eigen::MatrixXd cost = Eigen::MatrixXd::Constant(size, size, kForbidden);
  const double half_jump = 0.5 * options_.max_jump_m;
  for (int i = 0; i < n_tracks; ++i) {
    const Track& track = tracks_[i];
    const double gate = options_.max_jump_m * (track.missed_frames + 1);
    const Eigen::Vector2d predicted = track.predict(t_s);
    for (int j = 0; j < n_detections; ++j) {
      const double distance = (detections[j].p_W - predicted).norm();
      const double c =
          distance + (detections[j].kind == track.kind ? 0.0 : options_.kind_mismatch_m);
      if (c < gate) cost(i, j) = c;
    }
    cost(i, n_detections + i) = gate - half_jump;
  }
  for (int j = 0; j < n_detections; ++j) {
    cost(n_tracks + j, j) = half_jump;
    for (int i = 0; i < n_tracks; ++i) cost(n_tracks + j, n_detections + i) = 0.0;
  }
  const std::vector<int> column_of = size > 0 ? solve_assignment(cost) : std::vector<int>{};

  // Assigned pairs update their tracks.
  detection_ids_.assign(detections.size(), 0);
  std::vector<char> matched(tracks_.size(), 0);
  for (int i = 0; i < n_tracks; ++i) {
    const int j = column_of[i];
    if (j < 0 || j >= n_detections || cost(i, j) >= kForbidden) continue;
    record(tracks_[i], histories_[i], detections[j], t_s, j);
    detection_ids_[j] = tracks_[i].id;
    matched[i] = 1;
  }

  // The other tracks coast: merged when beside another track's detection, ended at the image's
  // edge or after too many misses.
  std::vector<char> keep(tracks_.size(), 1);
  for (int i = 0; i < n_tracks; ++i) {
    if (matched[i]) continue;
    Track& track = tracks_[i];
    track.detection = -1;
    ++track.missed_frames;
    ++counters_.missed;
    const Eigen::Vector2d predicted = track.predict(t_s);
    bool merged = false;
    for (int j = 0; j < n_detections && !merged; ++j) {
      merged = detection_ids_[j] != 0 &&
               (detections[j].p_W - predicted).norm() <= options_.merge_radius_m;
    }
    if (merged) ++counters_.merged;
    const Eigen::Vector2d predicted_px = track.centre_px + track.v_px * (t_s - track.t_last_s);
    if (!merged && near_edge(predicted_px)) {
      ++counters_.left_view;
      keep[i] = 0;
    } else if (track.missed_frames > options_.max_missed_frames) {
      ++counters_.lost;
      keep[i] = 0;
    }
  }

  // Ended tracks out (ids stay in order), then a new track for each detection left.
  std::vector<Track> tracks;
  std::vector<History> histories;
  for (int i = 0; i < n_tracks; ++i) {
    if (keep[i]) {
      tracks.push_back(std::move(tracks_[i]));
      histories.push_back(std::move(histories_[i]));
    } else {
      ended_.push_back(std::move(tracks_[i]));
    }
  }
  tracks_ = std::move(tracks);
  histories_ = std::move(histories);
  for (int j = 0; j < n_detections; ++j) {
    if (detection_ids_[j] != 0) continue;
    Track track;
    track.id = next_id_++;
    track.kind = detections[j].kind;
    History history;
    record(track, history, detections[j], t_s, j);
    detection_ids_[j] = track.id;
    tracks_.push_back(std::move(track));
    histories_.push_back(std::move(history));
    ++counters_.new_tracks;
  }
  return tracks_;
}

}  // namespace airtwin
