#include "sim/air_probe.h"

#include <cmath>
#include <string>

#include "common/csv.h"
#include "common/errors.h"
#include "common/text.h"
#include "common/units.h"
#include "sim/reached_air.h"

namespace airtwin {

void AirProbeSettings::validate() const {
  if (!std::isfinite(timestep_s) || timestep_s <= 0.0 || timestep_s > 0.1) {
    throw FieldError("air_probe.timestep_s",
                     "expected a step in (0, 0.1] s, got " + format_number(timestep_s));
  }
  const double steps = interval_s / timestep_s;
  if (!std::isfinite(interval_s) || steps < 1.0 - 1e-9 ||
      std::abs(steps - std::round(steps)) > 1e-6) {
    throw FieldError("air_probe.interval_s", "expected a whole number of " +
                                                 format_number(timestep_s) + " s steps, got " +
                                                 format_number(interval_s));
  }
  if (!std::isfinite(end_s) || end_s <= 0.0 || end_s > 3600.0) {
    throw FieldError("air_probe.end_s",
                     "expected a time in (0, 3600] s, got " + format_number(end_s));
  }
  if (!std::isfinite(field_delay_s) || field_delay_s < 0.0 || field_delay_s > 2.0) {
    throw FieldError("air_probe.field_delay_s",
                     "expected a delay in [0, 2] s, got " + format_number(field_delay_s));
  }
}

std::vector<ProgramKnot> read_nozzle_program(const std::string& path) {
  const CsvTable t = CsvTable::read_file(path, {"t_s", "pan_deg", "tilt_deg"});
  if (t.rows() == 0) throw InputError(path + ": expected at least one program row, got none");
  std::vector<ProgramKnot> out;
  for (size_t r = 0; r < t.rows(); ++r) {
    ProgramKnot k;
    k.t_s = t.number(r, "t_s");
    const double pan = t.number(r, "pan_deg");
    const double tilt = t.number(r, "tilt_deg");
    if (!out.empty() && k.t_s <= out.back().t_s) {
      throw InputError(t.where(r) + ": column 't_s': expected a time after the previous row's " +
                       format_number(out.back().t_s) + " s, got " + format_number(k.t_s));
    }
    if (pan < -180.0 || pan > 180.0) {
      throw InputError(t.where(r) + ": column 'pan_deg': expected [-180, 180], got " +
                       format_number(pan));
    }
    if (tilt < 0.0 || tilt > 90.0) {
      throw InputError(t.where(r) + ": column 'tilt_deg': expected [0, 90], got " +
                       format_number(tilt));
    }
    k.orientation = {deg_to_rad(pan), deg_to_rad(tilt)};
    out.push_back(k);
  }
  return out;
}

std::vector<ProbePoint> read_probe_points(const std::string& path) {
  const CsvTable t = CsvTable::read_file(path, {"x_m", "y_m"}, {"z_m"});
  if (t.rows() == 0) throw InputError(path + ": expected at least one point, got none");
  std::vector<ProbePoint> out;
  for (size_t r = 0; r < t.rows(); ++r) {
    ProbePoint p;
    p.p_W = {t.number(r, "x_m"), t.number(r, "y_m")};
    if (t.has_column("z_m")) p.z_m = t.number(r, "z_m");
    if (p.z_m <= 0.0 || p.z_m > 0.1) {
      throw InputError(t.where(r) + ": column 'z_m': expected a height in (0, 0.1] m, got " +
                       format_number(p.z_m));
    }
    out.push_back(p);
  }
  return out;
}

NozzleOrientation program_at(const std::vector<ProgramKnot>& program, double t_s) {
  if (t_s <= program.front().t_s) return program.front().orientation;
  if (t_s >= program.back().t_s) return program.back().orientation;
  size_t i = 1;
  while (program[i].t_s < t_s) ++i;
  const ProgramKnot& a = program[i - 1];
  const ProgramKnot& b = program[i];
  const double f = (t_s - a.t_s) / (b.t_s - a.t_s);
  return {a.orientation.pan_rad + f * (b.orientation.pan_rad - a.orientation.pan_rad),
          a.orientation.tilt_rad + f * (b.orientation.tilt_rad - a.orientation.tilt_rad)};
}

AirProbeRecord probe_air(const CfdField& cfd, const AirTransportParameters& params,
                         const std::vector<ProgramKnot>& program,
                         const std::vector<ProbePoint>& points, const AirProbeSettings& settings) {
  settings.validate();
  params.validate();
  if (program.empty())
    throw FieldError("air_probe.program", "expected at least one knot, got none");
  for (size_t i = 1; i < program.size(); ++i) {
    if (!(program[i].t_s > program[i - 1].t_s)) {
      throw InputError("air_probe.program[" + std::to_string(i) +
                       "].t_s: expected a time after the previous knot's");
    }
  }
  const double transit =
      params.cfd_timing && cfd.startup() ? cfd.startup()->transit_s() : settings.field_delay_s;
  const double dt = settings.timestep_s;
  // Whole steps, as the actuator's delay line has it (sim/nozzle_actuator.h).
  const long delay_steps = std::lround(transit / dt);
  const auto effective_at = [&](long step) {
    return program_at(program, static_cast<double>(step - delay_steps) * dt);
  };
  NozzleOrientation effective = effective_at(0);
  ReachedAir reached(cfd, params, dt, effective, points.size());
  CfdOrientedField present = cfd.at(effective);
  const long every = std::lround(settings.interval_s / dt);
  const long last = std::lround(std::floor(settings.end_s / dt + 1e-9));

  AirProbeRecord out;
  for (long step = 0; step <= last; ++step) {
    const NozzleOrientation e = effective_at(step);
    if (e.pan_rad != effective.pan_rad || e.tilt_rad != effective.tilt_rad) {
      effective = e;
      present = cfd.at(effective);
    }
    reached.push(effective, present);
    const bool own = reached.begin_step();
    const bool record = step % every == 0;
    std::vector<Eigen::Vector2d> row;
    if (record) row.reserve(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      // Every point's state advances each step, recorded or not (the formation decays per step).
      if (!own) {
        if (record) row.push_back(present.at(points[i].p_W, points[i].z_m).u_W);
        continue;
      }
      const ReachedAir::PointAir a = reached.at(i, points[i].p_W, points[i].z_m);
      if (record) {
        const CfdOrientedField& f = a.field ? *a.field : present;
        row.push_back(f.at(points[i].p_W, points[i].z_m).u_W + a.departure);
      }
    }
    if (record) {
      out.t_s.push_back(step * dt);
      out.u_W.push_back(std::move(row));
    }
  }
  return out;
}

}  // namespace airtwin
