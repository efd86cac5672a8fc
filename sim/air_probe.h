#pragma once
// The twin's air at fixed floor points while the nozzle follows a program: what a probe on the
// twin's floor reads, the mean air an object standing there would feel (before turbulence, the
// jet fully on, no effects). It is the CFD's air of the orientation whose wall jet has reached
// the point, formed over time when the formation is on (sim/reached_air.h), the very code the
// twin's objects get their air from. For checking the twin's moving air against a transient CFD
// of the same program (docs/cfd.md, "A re-aim in 3-D") or against anemometers on the rig.
//
// The program gives the nozzle's orientation (its exit's direction, the servos' actual angles)
// at knots, linear between them and held before the first and after the last. The floor's air
// follows it after the free jet's transit (sim/nozzle_actuator.h): the CFD start-up's when
// params.cfd_timing is set and the cases have one, else `field_delay_s`; in whole steps, as the
// twin's delay line has it.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/cfd_field.h"
#include "models/nozzle_geometry.h"
#include "sim/air_transport.h"

namespace airtwin {

struct ProgramKnot {
  double t_s = 0.0;
  NozzleOrientation orientation;  ///< rad
};

struct ProbePoint {
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();  ///< floor point (m, world frame)
  double z_m = 0.015;                             ///< height above the floor (m)
};

struct AirProbeSettings {
  double timestep_s = 0.0025;  ///< the twin's physics step (SceneParameters::timestep_s)
  double interval_s = 0.01;    ///< one record this often (a whole number of steps)
  double end_s = 1.0;          ///< last record's time (s from the program's t = 0)
  double field_delay_s = 0.2;  ///< the transit without the CFD's start-up
  /// Throws InputError naming the field unless the step is positive, the interval a whole
  /// number (>= 1) of steps and the end after 0.
  void validate() const;
};

struct AirProbeRecord {
  std::vector<double> t_s;                        ///< record times, from 0
  std::vector<std::vector<Eigen::Vector2d>> u_W;  ///< per record, per point (m/s, world frame)
};

/// Reads a program CSV: columns t_s, pan_deg, tilt_deg; times strictly increasing. InputError
/// naming the file, line and column otherwise.
std::vector<ProgramKnot> read_nozzle_program(const std::string& path);
/// Reads probe points: columns x_m, y_m and optionally z_m (default 0.015 m, the hot-wire's
/// height). InputError naming the file, line and column for a height outside (0, 0.1] m.
std::vector<ProbePoint> read_probe_points(const std::string& path);

/// The program's orientation at time t (s): linear between knots, held outside them.
NozzleOrientation program_at(const std::vector<ProgramKnot>& program, double t_s);

/// Records the air at `points` every settings.interval_s from 0 to settings.end_s. The air has
/// been at rest at the program's first orientation for long before t = 0. It forms over time when
/// params.formation is set and the cases have what that needs (CfdField::forms_air), as in the
/// twin. InputError naming the knot for an empty program or decreasing times; CfdField's for an
/// orientation outside its tilts.
AirProbeRecord probe_air(const CfdField& cfd, const AirTransportParameters& params,
                         const std::vector<ProgramKnot>& program,
                         const std::vector<ProbePoint>& points, const AirProbeSettings& settings);

}  // namespace airtwin
