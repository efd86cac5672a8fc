#include "vision/tracker.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

#include "common/errors.h"

namespace airtwin {

void TrackerOptions::validate() const {
  if (!(std::isfinite(max_jump_m) && max_jump_m > 0)) {
    throw InputError("tracker: max_jump_m must be finite and > 0");
  }
  if (max_missed_frames < 0) throw InputError("tracker: max_missed_frames must be >= 0");
  if (velocity_window < 2) throw InputError("tracker: velocity_window must be >= 2");
  if (velocity_degree < 1 || velocity_degree > 2) {
    throw InputError("tracker: velocity_degree must be 1 or 2");
  }
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
  // Velocities: the derivative at the last frame of a least-squares polynomial in time (a line,
  // or a parabola when asked and the window has 3 points) through the window's positions and
  // pixels, time taken from the last frame so the derivative is the linear coefficient.
  const int n = static_cast<int>(history.t.size());
  const int degree = std::min(options_.velocity_degree, n - 1);
  if (degree >= 1) {
    Eigen::MatrixXd A(n, degree + 1), b(n, 4);
    for (int k = 0; k < n; ++k) {
      const double tau = history.t[k] - t_s;
      for (int c = 0; c <= degree; ++c) A(k, c) = std::pow(tau, c);
      b.row(k) << history.p[k].x(), history.p[k].y(), history.uv[k].x(), history.uv[k].y();
    }
    const Eigen::MatrixXd x = A.colPivHouseholderQr().solve(b);
    track.v_W = x.block<1, 2>(1, 0).transpose();
    track.v_px = x.block<1, 2>(1, 2).transpose();
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

  // The augmented cost matrix: tracks x detections within each track's gate (the distance to
  // its prediction, plus the kind mismatch), plus a dummy column per track and a dummy row per
  // detection (left unassigned), each costing more than any allowed pair: every detection that
  // can join a track does, and among such assignments the total distance is least. A track that
  // coasts is no hungrier than one seen in the last frame (its gate is wider, its costs are not
  // lower), so a detection goes to the track that predicted it best.
  const int n_tracks = static_cast<int>(tracks_.size());
  const int n_detections = static_cast<int>(detections.size());
  const int size = n_tracks + n_detections;
  const double widest_gate = options_.max_jump_m * (options_.max_missed_frames + 1);
  const double unassigned = widest_gate + options_.kind_mismatch_m;
  const double forbidden = 1e6 * (unassigned + 1.0);
  Eigen::MatrixXd cost = Eigen::MatrixXd::Constant(size, size, forbidden);
  std::vector<Eigen::Vector2d> predicted(n_tracks);
  for (int i = 0; i < n_tracks; ++i) {
    const Track& track = tracks_[i];
    const double gate = options_.max_jump_m * (track.missed_frames + 1);
    predicted[i] = track.predict(t_s);
    for (int j = 0; j < n_detections; ++j) {
      const double distance = (detections[j].p_W - predicted[i]).norm();
      if (distance > gate) continue;
      cost(i, j) = distance + (detections[j].kind == track.kind ? 0.0 : options_.kind_mismatch_m);
    }
    cost(i, n_detections + i) = unassigned;
  }
  for (int j = 0; j < n_detections; ++j) {
    cost(n_tracks + j, j) = unassigned;
    for (int i = 0; i < n_tracks; ++i) cost(n_tracks + j, n_detections + i) = 0.0;
  }
  const std::vector<int> column_of = size > 0 ? solve_assignment(cost) : std::vector<int>{};
  detection_ids_.assign(detections.size(), 0);
  std::vector<int> detection_of(n_tracks, -1);
  for (int i = 0; i < n_tracks; ++i) {
    const int j = column_of[i];
    if (j >= 0 && j < n_detections && cost(i, j) < forbidden) {
      detection_of[i] = j;
      detection_ids_[j] = tracks_[i].id;
    }
  }

  // Merges: a track without a detection whose prediction lies by another track's detection is
  // hidden in that detection's blob. The blob's centre is neither object's: both tracks go on
  // with their predictions and velocities (the other keeps the detection and its id).
  std::vector<char> merged(n_tracks, 0);
  for (int i = 0; i < n_tracks; ++i) {
    if (detection_of[i] >= 0) continue;
    for (int k = 0; k < n_tracks; ++k) {
      const int j = detection_of[k];
      if (j >= 0 && (detections[j].p_W - predicted[i]).norm() <= options_.merge_radius_m) {
        merged[i] = merged[k] = 1;
      }
    }
  }

  // Tracks with a detection take it in (a merge's keeper only its time and pixel); the others
  // coast, and end at the image's edge or after too many misses.
  std::vector<char> keep(tracks_.size(), 1);
  for (int i = 0; i < n_tracks; ++i) {
    Track& track = tracks_[i];
    const int j = detection_of[i];
    if (j >= 0 && !merged[i]) {
      record(track, histories_[i], detections[j], t_s, j);
      continue;
    }
    if (j >= 0) {
      track.p_W = predicted[i];
      track.centre_px = detections[j].centre_px;
      track.t_last_s = t_s;
      ++track.hits;
      track.missed_frames = 0;
      track.detection = j;
      continue;
    }
    track.detection = -1;
    ++track.missed_frames;
    ++counters_.missed;
    if (merged[i]) ++counters_.merged;
    const Eigen::Vector2d predicted_px = track.centre_px + track.v_px * (t_s - track.t_last_s);
    if (!merged[i] && near_edge(predicted_px)) {
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
    if (counters_.frames > 1 && near_edge(detections[j].centre_px)) ++counters_.entered_view;
  }
  return tracks_;
}

std::string detection_rows_csv(const Tracker& tracker, const std::vector<Detection>& detections,
                               int64_t frame, double t_s) {
  AIRTWIN_DEMAND(tracker.detection_ids().size() == detections.size());
  // The track of each detection (all of them are alive after the update) and its kind by vote.
  std::map<int, ObjectKind> kind_of;
  for (const Track& t : tracker.tracks()) kind_of[t.id] = t.kind;
  std::map<int, size_t> detection_of_id;
  for (size_t j = 0; j < detections.size(); ++j) detection_of_id[tracker.detection_ids()[j]] = j;
  // One row per detection, in id order.
  std::string rows;
  char row[192];
  for (const auto& [id, j] : detection_of_id) {
    const Detection& d = detections[j];
    std::snprintf(row, sizeof row, "%lld,%.6f,%d,%s,%.6f,%.6f,%.6f,%.6f\n",
                  static_cast<long long>(frame), t_s, id, object_kind_name(kind_of.at(id)),
                  d.p_W.x(), d.p_W.y(), d.centre_px.x(), d.centre_px.y());
    rows += row;
  }
  return rows;
}

}  // namespace airtwin
