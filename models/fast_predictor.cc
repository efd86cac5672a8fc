#include "models/fast_predictor.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include "common/errors.h"
#include "models/fast_math.h"

namespace airtwin {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kLanes = 32;

// One block of objects, structure of arrays. Each lane carries its own time and step, so a lane's
// result never depends on the other lanes in its block. A lane's `move_v` is 1 while it moves and
// 0 at rest; `move_r` is move_v times the ray's `radial` (0 for an object sitting on s); `h` is
// its next step (0 once it has reached the end of the current piece, or rests). Padding lanes
// are all zero and stay at rest.
struct Block {
  int n = 0;         // lanes in use
  int n_padded = 0;  // rounded up to a multiple of 4 for the vector loops
  alignas(64) double r[kLanes];
  alignas(64) double v[kLanes];
  alignas(64) double b1[kLanes];
  alignas(64) double b2[kLanes];
  alignas(64) double b3[kLanes];
  alignas(64) double xi1[kLanes];
  alignas(64) double xi2[kLanes];
  alignas(64) double xi3[kLanes];
  alignas(64) double move_r[kLanes];
  alignas(64) double move_v[kLanes];
  alignas(64) double t[kLanes];     // lane time, s
  alignas(64) double h[kLanes];     // lane's next step, s
  alignas(64) double rate[kLanes];  // local rate of the (r, v) system, 1/s (see lane_rate)
  // The last step's start (r, v) and acceleration, for locating a stop inside it.
  alignas(64) double r_start[kLanes];
  alignas(64) double v_start[kLanes];
  alignas(64) double a_start[kLanes];
};

// eq. (3) along the lane's ray, then eq. (8).
inline double lane_acceleration(double r, double v, double b1, double b2, double b3, double xi1,
                                double xi2, double xi3) {
  return xi1 * v + xi2 * (b1 * (fast_exp_estrin(b2 * r) - fast_exp_estrin(b3 * r))) + xi3;
}

double lane_acceleration(const Block& b, int j, double r, double v) {
  return lane_acceleration(r, v, b.b1[j], b.b2[j], b.b3[j], b.xi1[j], b.xi2[j], b.xi3[j]);
}

double lane_drive(const Block& b, int j, double r) { return lane_acceleration(b, j, r, 0.0); }

// How fast the lane's dynamics change where eq. (3) is steep, 1/s. eq. (3) is b1 (e^{b2 r} -
// e^{b3 r}) with b3 the steep impingement term (|b3| ~ 15-30 1/m against |b2| ~ 1 1/m). Its
// share of the Jacobian of (dr/dt, dv/dt) = (m_r v, eq. 8) is [[0, m_r], [-xi2 b1 b3 e3, .]], whose
// eigenvalues have magnitude up to sqrt(|xi2 b1 b3| e3): ~40 1/s at s, ~10 at 10 cm, ~2.5 at
// 20 cm. The rate is twice that bound; steps of at most rate_factor / rate keep RK4 accurate near
// s and leave the rest of the field alone, where the linear damping xi1 and the slow e^{b2 r}
// term set the scale and max_step suffices.
inline double rate_from(double e3, double mr, double b1, double b3, double xi2) {
  return 2.0 * std::sqrt(std::abs(mr * xi2 * b1 * b3 * e3));
}

double lane_rate(const Block& b, int j) {
  const double e3 = fast_exp_estrin(b.b3[j] * b.r[j]);
  return rate_from(e3, b.move_r[j], b.b1[j], b.b3[j], b.xi2[j]);
}

// One classical RK4 step for every lane, each with its own step b.h[j] (0: unchanged). Also
// records the lane's rate at the step's start. Returns how many moving lanes ended the step with
// v < 0 (stop events to locate).
// Compiled for AVX2+FMA CPUs and for baseline x86-64 like the field kernel; models/ builds with
// -ffp-contract=off, so both compute the same IEEE operations.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(AIRTWIN_NO_TARGET_CLONES)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
int rk4_step(Block& b) {
  const int n = b.n_padded;
  alignas(64) double a1[kLanes], a2[kLanes], a3[kLanes], a4[kLanes];
  alignas(64) double v2[kLanes], v3[kLanes], v4[kLanes], rs[kLanes];
  // Stage-major: each loop's lanes are independent, so their exponentials overlap.
  for (int j = 0; j < n; ++j) {
    const double e2 = fast_exp_estrin(b.b2[j] * b.r[j]), e3 = fast_exp_estrin(b.b3[j] * b.r[j]);
    a1[j] = b.xi1[j] * b.v[j] + b.xi2[j] * (b.b1[j] * (e2 - e3)) + b.xi3[j];
    b.rate[j] = rate_from(e3, b.move_r[j], b.b1[j], b.b3[j], b.xi2[j]);
  }
  for (int j = 0; j < n; ++j) {
    const double half = 0.5 * b.h[j];
    rs[j] = b.r[j] + half * b.move_r[j] * b.v[j];
    v2[j] = b.v[j] + half * b.move_v[j] * a1[j];
    a2[j] =
        lane_acceleration(rs[j], v2[j], b.b1[j], b.b2[j], b.b3[j], b.xi1[j], b.xi2[j], b.xi3[j]);
  }
  for (int j = 0; j < n; ++j) {
    const double half = 0.5 * b.h[j];
    rs[j] = b.r[j] + half * b.move_r[j] * v2[j];
    v3[j] = b.v[j] + half * b.move_v[j] * a2[j];
    a3[j] =
        lane_acceleration(rs[j], v3[j], b.b1[j], b.b2[j], b.b3[j], b.xi1[j], b.xi2[j], b.xi3[j]);
  }
  for (int j = 0; j < n; ++j) {
    rs[j] = b.r[j] + b.h[j] * b.move_r[j] * v3[j];
    v4[j] = b.v[j] + b.h[j] * b.move_v[j] * a3[j];
    a4[j] =
        lane_acceleration(rs[j], v4[j], b.b1[j], b.b2[j], b.b3[j], b.xi1[j], b.xi2[j], b.xi3[j]);
  }
  // Update, counting the moving lanes whose v fell below 0.
  int crossings = 0;
  for (int j = 0; j < n; ++j) {
    const double r = b.r[j], v = b.v[j], sixth = b.h[j] / 6.0;
    b.r_start[j] = r;
    b.v_start[j] = v;
    b.a_start[j] = a1[j];
    b.r[j] = r + sixth * b.move_r[j] * (v + 2.0 * v2[j] + 2.0 * v3[j] + v4[j]);
    b.v[j] = v + sixth * b.move_v[j] * (a1[j] + 2.0 * a2[j] + 2.0 * a3[j] + a4[j]);
    crossings += (b.move_v[j] != 0.0) & (b.v[j] < 0.0);
  }
  return crossings;
}

// Lane clocks and steps: moves each lane's time past its last step (the step that ends a piece
// lands exactly on t_end), then sets its next step toward t_end: equal steps over what remains,
// each at most min(max_step, rate_factor / rate); 0 once the lane has arrived or rests.
// Branch-free so that it vectorises; cloned like rk4_step. Returns the lanes still stepping.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(AIRTWIN_NO_TARGET_CLONES)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
int plan_steps(Block& b, double t_end, double max_step, double rate_factor) {
  int active = 0;
  for (int j = 0; j < b.n_padded; ++j) {
    const double t_next = b.t[j] + b.h[j];
    b.t[j] = t_end - t_next > 1e-12 ? t_next : t_end;
    const double remaining = t_end - b.t[j];
    const double allowed = std::min(max_step, rate_factor / std::max(b.rate[j], 1e-12));
    const double steps = std::max(std::ceil(remaining / allowed - 1e-9), 1.0);
    const bool go = (b.move_v[j] != 0.0) & (remaining > 0.0);
    b.h[j] = go ? remaining / steps : 0.0;
    active += go;
  }
  return active;
}

// The cubic Hermite interpolant on [0, 1] with values y0, y1 and end slopes d0, d1 (already
// multiplied by the step), as c0 + c1 x + c2 x^2 + c3 x^3.
struct Cubic {
  double c0, c1, c2, c3;
  Cubic(double y0, double d0, double y1, double d1)
      : c0(y0), c1(d0), c2(-3 * y0 - 2 * d0 + 3 * y1 - d1), c3(2 * y0 + d0 - 2 * y1 + d1) {}
  double operator()(double x) const { return c0 + x * (c1 + x * (c2 + x * c3)); }
  double slope(double x) const { return c1 + x * (2 * c2 + x * 3 * c3); }
};

// The first x in (0, 1] where the cubic falls from > 0 to <= 0, given q(1) < 0. Splits [0, 1] at
// the critical points into monotone pieces and solves in the first piece that changes sign, by
// Newton safeguarded with bisection. Returns 0 when q is not positive anywhere before.
double first_falling_zero(const Cubic& q) {
  double cuts[4] = {0.0, 1.0, 1.0, 1.0};
  int n_cuts = 1;
  // Critical points: roots of 3 c3 x^2 + 2 c2 x + c1 inside (0, 1).
  const double A = 3 * q.c3, B = 2 * q.c2, C = q.c1;
  if (A != 0.0) {
    const double disc = B * B - 4 * A * C;
    if (disc > 0) {
      const double sq = std::sqrt(disc);
      const double x1 = (-B - sq) / (2 * A), x2 = (-B + sq) / (2 * A);
      for (double x : {std::min(x1, x2), std::max(x1, x2)}) {
        if (x > 0 && x < 1) cuts[n_cuts++] = x;
      }
    }
  } else if (B != 0.0) {
    const double x = -C / B;
    if (x > 0 && x < 1) cuts[n_cuts++] = x;
  }
  cuts[n_cuts++] = 1.0;
  for (int k = 0; k + 1 < n_cuts; ++k) {
    double lo = cuts[k], hi = cuts[k + 1];
    if (!(q(lo) > 0 && q(hi) <= 0)) continue;
    // Monotone decreasing on [lo, hi] with a sign change: q(lo) > 0 >= q(hi).
    double x = 0.5 * (lo + hi);
    for (int it = 0; it < 60; ++it) {
      const double fx = q(x);
      if (fx == 0.0) break;
      if (fx > 0) {
        lo = x;
      } else {
        hi = x;
      }
      const double d = q.slope(x);
      double next = d != 0.0 ? x - fx / d : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      // Newton converges quadratically: a step this small leaves an error far below it.
      const bool done = std::abs(next - x) <= 1e-13 || hi - lo <= 1e-15;
      x = next;
      if (done) break;
    }
    return x;
  }
  return 0.0;
}

}  // namespace

FastPredictor::FastPredictor(const Options& options) : options_(options) {
  char buf[128];
  if (!(std::isfinite(options.max_step_s) && options.max_step_s > 0 && options.max_step_s <= 10)) {
    std::snprintf(buf, sizeof buf, "%.9g", options.max_step_s);
    throw InputError(std::string("fast predictor: max_step_s must be in (0, 10] s, got ") + buf);
  }
  if (!(std::isfinite(options.rate_factor) && options.rate_factor > 0)) {
    std::snprintf(buf, sizeof buf, "%.9g", options.rate_factor);
    throw InputError(std::string("fast predictor: rate_factor must be finite and > 0, got ") + buf);
  }
}

void FastPredictor::advance(const Segment& seg, std::span<const ObjectDynamics> dynamics,
                            std::span<ObjectState> state, std::span<double> rest_since_s) const {
  const size_t m = state.size();
  const size_t n_samples = seg.sample_times_s.size();
  const double max_step = options_.max_step_s, rate_factor = options_.rate_factor;
  Block b;
  Eigen::Vector2d s_W[kLanes], u_W[kLanes];
  bool moved[kLanes];  // moving at the start of this segment (a resting lane never starts later)

  for (size_t first = 0; first < m; first += kLanes) {
    // Set up the block: each object's ray, profile, coefficients and whether it moves.
    b.n = static_cast<int>(std::min<size_t>(kLanes, m - first));
    b.n_padded = std::min(kLanes, (b.n + 3) / 4 * 4);
    int n_moving = 0;
    // Lanes past n_padded are never read (every loop stops at n or n_padded).
    for (int j = 0; j < b.n_padded; ++j) {
      b.r[j] = b.v[j] = b.b1[j] = b.b2[j] = b.b3[j] = 0.0;
      b.xi1[j] = b.xi2[j] = b.xi3[j] = b.move_r[j] = b.move_v[j] = 0.0;
      b.t[j] = seg.t0_s;
      b.h[j] = 0.0;
      b.rate[j] = 1.0;
      b.r_start[j] = b.v_start[j] = b.a_start[j] = 0.0;
      moved[j] = false;
      if (j >= b.n) continue;
      const ObjectState& s = state[first + j];
      const ObjectDynamics& xi = dynamics[first + j];
      const Ray ray = seg.field ? ray_through(*seg.field, s.p_W) : ray_through(*seg.rays, s.p_W);
      s_W[j] = ray.s_W;
      u_W[j] = ray.u_W;
      b.r[j] = ray.r0;
      b.v[j] = s.v;
      b.b1[j] = ray.profile.b1;
      b.b2[j] = ray.profile.b2;
      b.b3[j] = ray.profile.b3;
      b.xi1[j] = xi.xi1;
      b.xi2[j] = xi.xi2;
      b.xi3[j] = xi.xi3;
      double& rest = rest_since_s[first + j];
      if (s.v > 0.0 || lane_drive(b, j, ray.r0) > 0.0) {
        b.move_v[j] = 1.0;
        b.move_r[j] = ray.radial;
        b.rate[j] = lane_rate(b, j);
        rest = kInf;
        moved[j] = true;
        ++n_moving;
      } else if (!(rest < kInf)) {
        rest = seg.t0_s;  // at rest where friction wins: stays put this segment
      }
    }

    // Integrate piece by piece: [t0, first sample], ..., [last sample, t1].
    for (size_t piece = 0; piece <= n_samples; ++piece) {
      const double t_end = piece < n_samples ? seg.sample_times_s[piece] : seg.t1_s;
      while (n_moving > 0 && plan_steps(b, t_end, max_step, rate_factor) > 0) {
        const int crossings = rk4_step(b);
        // Stop events: a moving lane whose v fell below 0 during its step.
        for (int j = 0; j < b.n && crossings > 0; ++j) {
          if (!(b.move_v[j] != 0.0 && b.v[j] < 0.0)) continue;
          const double h = b.h[j];
          const double a_end = lane_acceleration(b, j, b.r[j], b.v[j]);
          const Cubic v_of_x(b.v_start[j], h * b.a_start[j], b.v[j], h * a_end);
          const double x = first_falling_zero(v_of_x);
          const double mr = b.move_r[j];
          const Cubic r_of_x(b.r_start[j], h * mr * b.v_start[j], b.r[j], h * mr * b.v[j]);
          b.r[j] = std::max(r_of_x(x), 0.0);
          b.v[j] = 0.0;
          // Friction wins there (always, but for a tangency): rest for the segment.
          if (lane_drive(b, j, b.r[j]) <= 0.0) {
            b.move_v[j] = b.move_r[j] = 0.0;
            rest_since_s[first + j] = b.t[j] + x * h;
            --n_moving;
          }
        }
      }
      for (int j = 0; j < b.n_padded; ++j) {
        b.t[j] = t_end;
        b.h[j] = 0.0;
      }
      // Sample: back from the ray to the floor.
      if (piece < n_samples) {
        for (int j = 0; j < b.n; ++j) {
          ObjectState& out = seg.samples[piece * m + first + j];
          if (moved[j]) {
            out.p_W = s_W[j] + b.r[j] * u_W[j];
            out.v = b.v[j];
          } else {
            out = state[first + j];
          }
        }
      }
    }
    for (int j = 0; j < b.n; ++j) {
      // An object that did not move keeps its exact position (no round trip through the ray).
      if (!moved[j]) continue;
      ObjectState& s = state[first + j];
      s.p_W = s_W[j] + b.r[j] * u_W[j];
      s.v = b.v[j];
    }
  }
}

}  // namespace airtwin
