#pragma once
// The analytical air-field model of section III: for a nozzle orientation (pan, tilt), the air
// velocity on the floor at any point, in three steps:
//   (i)  projection point c (eq. 1) and stagnation point s (eq. 2);
//   (ii) distance r and direction alpha of the point seen from s, alpha measured from the jet's
//        downstream direction (the pan direction);
//   (iii) speed from eq. (3) with coefficients interpolated linearly in alpha (with wrap-around
//        at 360 deg) and by Makima in tilt (tilt clamped to the fitted range); direction radial
//        from s; zero at s.
//
// AirFieldModel is the fixed model (geometry + table), immutable after construction and safe to
// share between threads. Per orientation, two views of the same field:
//  - OrientedField holds s and the 360 coefficient profiles already interpolated to the
//    orientation's tilt, so evaluating a point is a handful of arithmetic operations and two
//    exponentials: for fields evaluated at many points (the twin's drag, grids, CVODE).
//  - OrientedRays holds s and the tilt's interpolation weights only, and interpolates a profile
//    when asked for one: for predictors that follow each object's ray from s, where one profile
//    per object serves a whole segment (models/fast_predictor.h). Building it skips the 360
//    profiles; its profiles are bit-identical to OrientedField's.

#include <Eigen/Core>
#include <array>
#include <memory>

#include "models/field_table.h"
#include "models/nozzle_geometry.h"

namespace airtwin {

class AirFieldModel;
class OrientedField;

/// The field for one nozzle orientation, seen along rays from s: its profiles are interpolated on
/// demand from the model, which must outlive it. Cheap to build and copy, immutable.
class OrientedRays {
 public:
  const Eigen::Vector2d& stagnation_point() const { return s_W_; }
  const Eigen::Vector2d& projection_point() const { return c_W_; }
  const NozzleOrientation& orientation() const { return orientation_; }
  double coefficient_tilt_rad() const { return coefficient_tilt_rad_; }
  const AirFieldModel& model() const { return *model_; }

  /// The eq. (3) profile in direction alpha_rad (from downstream): the two neighbouring 1-degree
  /// profiles interpolated in tilt, then linearly in alpha. Equals OrientedField::coefficients.
  FieldCoefficients coefficients(double alpha_rad) const;
  /// Air velocity (m/s, world frame) at floor point p_W (m), from the two profiles around its
  /// direction: OrientedField::velocity to rounding (FMA contraction may differ), without
  /// building the 360 profiles. For a few points per orientation, as when the nozzle moves.
  Eigen::Vector2d velocity(const Eigen::Vector2d& p_W) const;
  /// The full field of this orientation (AirFieldModel::at).
  OrientedField field() const;

 private:
  friend class AirFieldModel;
  const AirFieldModel* model_ = nullptr;
  NozzleOrientation orientation_;
  double coefficient_tilt_rad_ = 0.0;
  Eigen::Vector2d c_W_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d s_W_ = Eigen::Vector2d::Zero();
  double cos_pan_ = 1.0, sin_pan_ = 0.0;  // rotation into the jet frame, as OrientedField's
  // Makima in tilt: the table's interval and the Hermite weights h00, h10, h01, h11 in it.
  size_t tilt_interval_ = 0;
  std::array<double, 4> tilt_weights_{};
};

/// The field for one nozzle orientation. Cheap to build (~1 us), cheap to copy, immutable.
class OrientedField {
 public:
  const Eigen::Vector2d& stagnation_point() const { return s_W_; }
  const Eigen::Vector2d& projection_point() const { return c_W_; }
  const NozzleOrientation& orientation() const { return orientation_; }
  /// The tilt (rad) at which the coefficients were interpolated: the tilt clamped to the table.
  double coefficient_tilt_rad() const { return coefficient_tilt_rad_; }

  /// Air speed (m/s) at floor point p_W (m).
  double speed(const Eigen::Vector2d& p_W) const;
  /// Air velocity (m/s, world frame) at floor point p_W (m); zero at s.
  Eigen::Vector2d velocity(const Eigen::Vector2d& p_W) const;
  /// The eq. (3) profile in direction alpha_rad (from downstream), linearly interpolated in alpha.
  FieldCoefficients coefficients(double alpha_rad) const;

  /// Batch evaluation: speeds (m/s) at the columns of p_W (2 x N, m). `speed_out` has N entries.
  void speeds(const Eigen::Ref<const Eigen::Matrix2Xd>& p_W,
              Eigen::Ref<Eigen::VectorXd> speed_out) const;
  /// Batch evaluation: velocities (2 x N, m/s) at the columns of p_W (2 x N, m).
  void velocities(const Eigen::Ref<const Eigen::Matrix2Xd>& p_W,
                  Eigen::Ref<Eigen::Matrix2Xd> v_out) const;

 private:
  friend class AirFieldModel;
  static constexpr int kBlock = 64;
  // The kernel of every evaluation: speeds (and, when ux is given, unit directions from s) of up
  // to kBlock points (x[i], y[i]). Vectorised angle and exponentials.
  void evaluate_block(const double* x, const double* y, int n, double* speed, double* ux,
                      double* uy) const;
  // Both kernels read the points through a stride (2 for the columns of a 2 x N matrix).
  void evaluate(const double* xy, Eigen::Index n, double* speed, double* v_xy) const;

  NozzleOrientation orientation_;
  double cos_pan_ = 1.0, sin_pan_ = 0.0;  // rotation into the jet frame (alpha from downstream)
  double coefficient_tilt_rad_ = 0.0;
  Eigen::Vector2d c_W_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d s_W_ = Eigen::Vector2d::Zero();
  // Profiles at alpha = 0..359 deg plus a copy of alpha 0 at index 360 for the wrap-around.
  std::array<FieldCoefficients, FieldTable::kAlphaBins + 1> ring_;
};

/// The fixed air-field model: rig geometry and coefficient table.
class AirFieldModel {
 public:
  /// Throws InputError when the geometry is invalid.
  AirFieldModel(NozzleGeometry geometry, FieldTable table);
  /// The default model: eqs. (2) and (3) fitted to the jet's CFD the paper's way (Appendices A-C
  /// with the simulated hot-wire; models/data/cfd_fitted_field_model.json, docs/cfd.md).
  static AirFieldModel fitted_to_cfd();
  /// The paper's geometry with the table constructed from the wall-jet literature
  /// (models/data/constructed_field_table.csv), the model for users without a CFD.
  static AirFieldModel with_constructed_table();

  const NozzleGeometry& geometry() const { return geometry_; }
  const FieldTable& table() const { return table_; }

  /// The field for one orientation (pan, tilt in rad). Throws InputError unless pan is finite and
  /// tilt in [0, fold_tilt_rad(geometry)) (64.4 deg: beyond it eq. (2) is not meaningful).
  OrientedField at(const NozzleOrientation& o) const;
  /// The same field seen along rays (OrientedRays): cheaper to build, same errors.
  OrientedRays rays_at(const NozzleOrientation& o) const;

  /// Convenience: velocity (m/s) at p_W (m) for orientation o. Prefer at() for many points.
  Eigen::Vector2d velocity(const NozzleOrientation& o, const Eigen::Vector2d& p_W) const {
    return at(o).velocity(p_W);
  }

 private:
  NozzleGeometry geometry_;
  FieldTable table_;
  double fold_tilt_rad_ = 0.0;  // fold_tilt_rad(geometry_), checked for every orientation
  // Makima node slopes over tilt: slopes_by_tilt_[tilt node][alpha][coefficient b1, b2, b3].
  std::vector<std::array<std::array<double, 3>, FieldTable::kAlphaBins>> slopes_by_tilt_;

  friend class OrientedRays;
  // The profile at 1-degree bin `alpha_bin` interpolated in tilt with `rays`' weights.
  FieldCoefficients profile(const OrientedRays& rays, int alpha_bin) const;
};

}  // namespace airtwin
