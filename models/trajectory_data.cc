#include "models/trajectory_data.h"

#include <cmath>
#include <cstdio>
#include <map>

#include "common/csv.h"
#include "common/errors.h"
#include "common/units.h"
#include "models/nozzle_log.h"

namespace airtwin {

double tilt_group_deg(double tilt_rad) { return std::round(rad_to_deg(tilt_rad) * 1e3) / 1e3; }

const std::set<std::string>& default_object_types() {
  static const std::set<std::string> types = {"tracer", "cotton"};
  return types;
}

TrajectorySet read_trajectory_csv(const std::string& path,
                                  const std::set<std::string>& known_objects) {
  return parse_trajectory_csv(read_text_file(path), path, known_objects);
}

TrajectorySet parse_trajectory_csv(const std::string& text, const std::string& source,
                                   const std::set<std::string>& known_objects) {
  const CsvTable csv = CsvTable::parse(
      text, source, {"traj", "object", "t", "x", "y", "pan_deg", "tilt_deg"}, {"group"});
  if (csv.rows() == 0) throw InputError(source + ": no data rows after the header");

  TrajectorySet set;
  set.has_group = csv.has_column("group");
  std::map<std::string, size_t> index_of;
  for (size_t row = 0; row < csv.rows(); ++row) {
    const std::string& id = csv.text(row, "traj");
    const std::string& object = csv.text(row, "object");
    if (id.empty()) throw InputError(csv.where(row) + ": column 'traj': empty trajectory id");
    if (!known_objects.count(object)) {
      std::string known;
      for (const std::string& k : known_objects) known += (known.empty() ? "" : ", ") + k;
      throw InputError(csv.where(row) + ": column 'object': unknown object type '" + object +
                       "', expected one of: " + known);
    }
    TrajectorySample s;
    s.t_s = csv.number(row, "t");
    s.p_W = {csv.number(row, "x"), csv.number(row, "y")};
    s.nozzle = nozzle_orientation_of_row(csv, row);

    auto [it, fresh] = index_of.try_emplace(id, set.trajectories.size());
    if (fresh) {
      Trajectory t;
      t.id = id;
      t.object = object;
      if (set.has_group) t.group = csv.text(row, "group");
      set.trajectories.push_back(std::move(t));
    }
    Trajectory& traj = set.trajectories[it->second];
    if (traj.object != object) {
      throw InputError(csv.where(row) + ": column 'object': trajectory '" + id + "' was '" +
                       traj.object + "' before, now '" + object + "'");
    }
    if (!traj.samples.empty() && !(s.t_s > traj.samples.back().t_s)) {
      throw InputError(csv.where(row) + ": column 't': time must increase within trajectory '" +
                       id + "', got " + csv.text(row, "t") + " after " +
                       std::to_string(traj.samples.back().t_s));
    }
    traj.samples.push_back(s);
  }
  return set;
}

std::string trajectory_csv(const TrajectorySet& set) {
  std::string out = set.has_group ? "traj,object,t,x,y,pan_deg,tilt_deg,group\n"
                                  : "traj,object,t,x,y,pan_deg,tilt_deg\n";
  char line[256];
  for (const Trajectory& tr : set.trajectories) {
    for (const TrajectorySample& s : tr.samples) {
      std::snprintf(line, sizeof line, "%s,%s,%.6f,%.6f,%.6f,%.6f,%.6f", tr.id.c_str(),
                    tr.object.c_str(), s.t_s, s.p_W.x(), s.p_W.y(), rad_to_deg(s.nozzle.pan_rad),
                    rad_to_deg(s.nozzle.tilt_rad));
      out += line;
      if (set.has_group) out += "," + tr.group;
      out += "\n";
    }
  }
  return out;
}

TrajectorySet merge_trajectory_sets(std::vector<TrajectorySet> sets) {
  if (sets.size() == 1) return std::move(sets.front());
  TrajectorySet merged;
  for (size_t k = 0; k < sets.size(); ++k) {
    merged.has_group = merged.has_group || sets[k].has_group;
    for (Trajectory& t : sets[k].trajectories) {
      t.id = std::to_string(k + 1) + ":" + t.id;
      merged.trajectories.push_back(std::move(t));
    }
  }
  return merged;
}

}  // namespace airtwin
