#pragma once
// The jet's air on the floor from the CFD campaign (data/cfd/, docs/cfd.md): steady RANS
// k-epsilon solutions of the rig's jet, one per tilt, sampled on a 1 cm grid at a few heights above
// the floor. The twin's air comes from here; the controller's model (models/air_field.h, eqs. 1-3)
// is fitted to it, as the paper fitted eq. (3) to its CFD.
//
// Frames. Each case is computed at pan 0: the nozzle exit 1.43 m above the origin, the jet tilted
// toward +x, the stagnation point s on the +x axis. The data cover x in [-1.5, 1.5] m and
// y in [0, 1.5] m; the field at (x, -y) is the mirror image (ux, -uy, k, epsilon). A nozzle
// orientation (pan theta, tilt phi) rotates the case by theta about the vertical.
//
// Between tilts. For a tilt between two cases, s is interpolated linearly in |c| = h tan(phi)
// between the cases' stagnation points (within 0.9 cm of the held-out 37.5 deg case), each case's
// field is shifted along x to put its s there, and the two are mixed linearly in tilt (docs/cfd.md:
// 1.8 % MAPE of the held-out floor speed when anchored at its true s). Outside the grid the air is
// still (velocity 0) with the ambient turbulence of the case.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "models/cfd_startup.h"
#include "models/nozzle_geometry.h"
#include "models/wall_jet_formation.h"

namespace airtwin {

/// The mean air and its turbulence at one point.
struct CfdSample {
  Eigen::Vector2d u_W = Eigen::Vector2d::Zero();  ///< horizontal mean velocity (m/s)
  double k = 0.0;                                 ///< turbulence kinetic energy (m^2/s^2)
  double epsilon = 0.0;                           ///< its dissipation rate (m^2/s^3)
};

/// One CFD case: one tilt at pan 0, in the case frame (see above). Immutable.
class CfdCase {
 public:
  /// Reads a case from its JSON header (format "airtwin-cfd-floor 1") and the float32 data file it
  /// names, beside it. InputError naming the file and the field or value when the header lacks a
  /// field, the data file has the wrong size, or a value is not finite.
  static CfdCase read(const std::string& header_path);

  double tilt_rad() const { return tilt_rad_; }
  /// The stagnation point's x in the case frame (m; s is on the +x axis).
  double stagnation_x_m() const { return s_x_m_; }
  const std::string& name() const { return name_; }
  bool held_out() const { return held_out_; }
  int mesh_level() const { return mesh_level_; }
  double inlet_diameter_m() const { return inlet_d_m_; }
  const std::vector<double>& heights_m() const { return heights_m_; }

  /// The field at (x, y) of the case frame and height z: bilinear on the grid, linear between
  /// heights (clamped to the lowest and highest), mirrored for y < 0; still air outside the grid.
  CfdSample at(double x_m, double y_m, double z_m) const;
  /// The vertical mean velocity there (m/s, up positive; the same interpolation; 0 outside the
  /// grid). What an omnidirectional anemometer sees besides the horizontal air, large near s.
  double vertical_at(double x_m, double y_m, double z_m) const;
  /// The horizontal gradient of the kinematic pressure p / rho there (m/s^2, case frame): central
  /// differences one grid pitch wide of the bilinear field (mirrored for y < 0), linear between
  /// heights; 0 outside the grid. -rho V grad(p / rho) is the pressure push on a body of volume V.
  Eigen::Vector2d pressure_gradient_at(double x_m, double y_m, double z_m) const;
  /// How far from s the kinematic pressure stays above 1 % of its largest value at the lowest
  /// height (m): beyond it the pressure push is negligible and is not evaluated.
  double pressure_radius_m() const { return pressure_radius_m_; }

 private:
  friend class CfdOrientedField;
  // The height bracket of z: lower index and weight of the upper one (0 at or past the ends).
  std::pair<size_t, double> height_bracket(double z_m) const;
  // Adds weight x (ux, uy, k, epsilon) at (x, |y|), between heights lo and lo + 1 with weight t
  // of the upper one, to acc: one grid lookup for both heights.
  void accumulate(double x_m, double y_abs_m, size_t lo, double t, double weight,
                  double acc[4]) const;

  std::string name_;
  double tilt_rad_ = 0.0;
  double s_x_m_ = 0.0;
  bool held_out_ = false;
  int mesh_level_ = 0;
  double inlet_d_m_ = 0.0;
  double x0_m_ = 0.0, y0_m_ = 0.0, dx_m_ = 0.0, dy_m_ = 0.0;
  long nx_ = 0, ny_ = 0;
  int n_fields_ = 0;
  int ux_ = 0, uy_ = 0, k_ = 0, epsilon_ = 0;  // indices of the fields in the data
  std::vector<double> heights_m_;
  double k_ambient_ = 0.0, epsilon_ambient_ = 0.0;
  using Node = std::array<float, 4>;  // ux, uy, k, epsilon
  std::vector<Node> nodes_;           // [height][iy][ix]
  std::vector<float> uz_;             // [height][iy][ix]
  std::vector<float> p_;              // kinematic pressure, [height][iy][ix]
  double pressure_radius_m_ = 0.0;
  // pressure_gradient_at between heights lo and lo + 1 with weight t of the upper one.
  Eigen::Vector2d pressure_gradient_at(double x_m, double y_m, size_t lo, double t) const;
  // Bilinear value of `plane` ([height][iy][ix]) at (x, |y|), between heights lo and lo + 1 with
  // weight t of the upper one (height_bracket); 0 outside the grid.
  double plane_at(const std::vector<float>& plane, double x_m, double y_m, size_t lo,
                  double t) const;
};

class CfdField;

/// The CFD air of one nozzle orientation: the tilt bracket and the pan rotation resolved once, as
/// OrientedField is for the model. Cheap to build and copy; the CfdField must outlive it.
class CfdOrientedField {
 public:
  const NozzleOrientation& orientation() const { return orientation_; }
  /// The stagnation point s (m, world frame).
  const Eigen::Vector2d& stagnation_point() const { return s_W_; }
  /// The air at floor point p_W (m) and height z_m (see the top of this file).
  CfdSample at(const Eigen::Vector2d& p_W, double z_m) const;
  /// The vertical mean velocity at p_W and z_m (m/s, up positive; CfdCase::vertical_at).
  double vertical_at(const Eigen::Vector2d& p_W, double z_m) const;
  /// The horizontal gradient of the kinematic pressure at p_W and z_m (m/s^2, world frame;
  /// CfdCase::pressure_gradient_at), mixed between the bracket's cases as the velocity is.
  Eigen::Vector2d pressure_gradient_at(const Eigen::Vector2d& p_W, double z_m) const;
  /// Beyond this distance from s (m) the pressure gradient is negligible (the larger of the
  /// bracket's CfdCase::pressure_radius_m).
  double pressure_radius_m() const { return pressure_radius_m_; }

 private:
  friend class CfdField;
  double pressure_radius_m_ = 0.0;
  const CfdField* field_ = nullptr;
  NozzleOrientation orientation_{0.0, 0.0};
  size_t lo_ = 0, hi_ = 0;
  double w_ = 0.0;                          // weight of case hi_, linear in tilt
  double shift_lo_ = 0.0, shift_hi_ = 0.0;  // case x = frame x + shift (puts each case's s at s)
  double cos_pan_ = 1.0, sin_pan_ = 0.0;
  Eigen::Vector2d s_W_ = Eigen::Vector2d::Zero();
};

/// The CFD air for any nozzle orientation within the cases' tilt range. Immutable; any number of
/// threads may query one.
class CfdField {
 public:
  /// Reads every case in `dir` of the given mesh level and inlet diameter, the held-out tilt left
  /// out (it is for testing the interpolation), the jet's start-up (startup_tilt00_d40.json)
  /// when the folder has it, and the wall jet's formation fitted to its pulses
  /// (pulse<MS>ms_tilt00_d40.json) when it has any. InputError when no case is found, two share a
  /// tilt, or a case or the start-up cannot be read.
  static CfdField read_dir(const std::string& dir, int mesh_level = 1,
                           double inlet_diameter_m = 0.02);
  /// From cases already read (any order; at least one) and, if the cases came with them, the
  /// jet's start-up and the wall jet's formation.
  explicit CfdField(std::vector<CfdCase> cases, NozzleGeometry geometry = {},
                    std::optional<CfdStartup> startup = std::nullopt,
                    std::optional<WallJetFormation> formation = std::nullopt);

  double min_tilt_rad() const { return cases_.front().tilt_rad(); }
  double max_tilt_rad() const { return cases_.back().tilt_rad(); }
  const std::vector<CfdCase>& cases() const { return cases_; }
  /// The jet's start-up (models/cfd_startup.h) if the cases came with it, else null.
  const CfdStartup* startup() const { return startup_ ? &*startup_ : nullptr; }
  /// The wall jet's formation (models/wall_jet_formation.h) if the cases came with pulses.
  const WallJetFormation* formation() const { return formation_ ? &*formation_ : nullptr; }
  /// True when the cases can form the twin's air over time: they came with the start-up (the
  /// lag) and pulses (the formation's time).
  bool forms_air() const { return startup_ && formation_; }
  /// What forms_air() needs, for errors: "the jet's start-up (...) and pulse cases (...)".
  static const char* kFormationData;

  /// The field of orientation `o`. InputError when the tilt is outside [min_tilt_rad,
  /// max_tilt_rad].
  CfdOrientedField at(const NozzleOrientation& o) const;
  /// The stagnation point of orientation `o` (m, world frame); the same errors.
  Eigen::Vector2d stagnation_point(const NozzleOrientation& o) const;
  /// The air at floor point p_W (m) and height z_m under orientation `o`; the same errors. Prefer
  /// at(o) for many points.
  CfdSample at(const NozzleOrientation& o, const Eigen::Vector2d& p_W, double z_m) const;

 private:
  friend class CfdOrientedField;
  struct Bracket {
    size_t lo = 0, hi = 0;
    double w = 0.0;    // weight of `hi`, linear in tilt
    double s_x = 0.0;  // the interpolated stagnation point on the case frame's +x axis
  };
  Bracket bracket(double tilt_rad) const;

  std::vector<CfdCase> cases_;  // by tilt
  NozzleGeometry geometry_;
  std::optional<CfdStartup> startup_;
  std::optional<WallJetFormation> formation_;
};

}  // namespace airtwin
