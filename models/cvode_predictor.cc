#include "models/cvode_predictor.h"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>

#include "common/errors.h"
#include "common/text.h"

namespace airtwin {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// What the C callbacks see: the field and object being integrated, and the last message that
// SUNDIALS reported (so an error flag can be turned into an exception with SUNDIALS' words).
struct CallbackData {
  const OrientedField* field = nullptr;
  ObjectDynamics xi;
  std::string last_message;
};

// eqs. (8)-(9) while moving, state (x, y, v). Never throws (C frames above).
int rhs(sunrealtype /*t*/, N_Vector y, N_Vector ydot, void* user_data) {
  const auto* d = static_cast<const CallbackData*>(user_data);
  const sunrealtype* yv = N_VGetArrayPointer(y);
  sunrealtype* out = N_VGetArrayPointer(ydot);
  const PlanarRate rate = moving_rate(*d->field, d->xi, Eigen::Vector2d(yv[0], yv[1]), yv[2]);
  out[0] = rate.p_dot_W.x();
  out[1] = rate.p_dot_W.y();
  out[2] = rate.v_dot;
  // A non-finite rate is a recoverable failure: CVODE retries with a smaller step, then reports.
  return std::isfinite(out[0]) && std::isfinite(out[1]) && std::isfinite(out[2]) ? 0 : 1;
}

// The stop event: the speed v reaching 0 (falling crossings only, see CVodeSetRootDirection).
int stop_root(sunrealtype /*t*/, N_Vector y, sunrealtype* gout, void* /*user_data*/) {
  gout[0] = N_VGetArrayPointer(y)[2];
  return 0;
}

void record_message(int /*error_code*/, const char* module, const char* function, char* msg,
                    void* user_data) {
  auto* d = static_cast<CallbackData*>(user_data);
  d->last_message = std::string(module ? module : "") + "::" + (function ? function : "") + ": " +
                    (msg ? msg : "");
}

// One CVODE integrator with its context, vector and nonlinear solver, freed in reverse order.
class CvodeSession {
 public:
  CvodeSession(const CvodePredictor::Options& o, CallbackData* data) : data_(data) {
    check_flag(SUNContext_Create(nullptr, &ctx_), "SUNContext_Create");
    y_ = N_VNew_Serial(3, ctx_);
    if (y_ == nullptr) fail("N_VNew_Serial returned null");
    N_VConst(0.0, y_);
    mem_ = CVodeCreate(CV_ADAMS, ctx_);
    if (mem_ == nullptr) fail("CVodeCreate returned null");
    // Route messages to `data` before anything can fail, so nothing is printed.
    check(CVodeSetErrHandlerFn(mem_, record_message, data_), "CVodeSetErrHandlerFn");
    check(CVodeInit(mem_, rhs, 0.0, y_), "CVodeInit");
    check(CVodeSetUserData(mem_, data_), "CVodeSetUserData");
    check(CVodeSStolerances(mem_, o.rtol, o.atol), "CVodeSStolerances");
    check(CVodeSetMaxNumSteps(mem_, o.max_num_steps), "CVodeSetMaxNumSteps");
    // Adams + fixed-point iteration (no Jacobian), as ode113.
    nls_ = SUNNonlinSol_FixedPoint(y_, 0, ctx_);
    if (nls_ == nullptr) fail("SUNNonlinSol_FixedPoint returned null");
    check(CVodeSetNonlinearSolver(mem_, nls_), "CVodeSetNonlinearSolver");
    // The stop event: root of v, falling only; no warning for a root that starts at v = 0.
    check(CVodeRootInit(mem_, 1, stop_root), "CVodeRootInit");
    int direction = -1;
    check(CVodeSetRootDirection(mem_, &direction), "CVodeSetRootDirection");
    check(CVodeSetNoInactiveRootWarn(mem_), "CVodeSetNoInactiveRootWarn");
  }
  ~CvodeSession() {
    if (mem_ != nullptr) CVodeFree(&mem_);
    if (nls_ != nullptr) SUNNonlinSolFree(nls_);
    if (y_ != nullptr) N_VDestroy(y_);
    if (ctx_ != nullptr) SUNContext_Free(&ctx_);
  }
  CvodeSession(const CvodeSession&) = delete;
  CvodeSession& operator=(const CvodeSession&) = delete;

  sunrealtype* y() { return N_VGetArrayPointer(y_); }

  // Restarts at (t0, y()) with the integration bounded by t_stop.
  void restart(double t0, double t_stop) {
    check(CVodeReInit(mem_, t0, y_), "CVodeReInit");
    check(CVodeSetStopTime(mem_, t_stop), "CVodeSetStopTime");
  }

  // Integrates toward t_out; returns CV_SUCCESS, CV_TSTOP_RETURN or CV_ROOT_RETURN, with the
  // reached time in *t and the state in y().
  int step_to(double t_out, double* t) {
    sunrealtype t_reached = 0.0;
    const int flag = CVode(mem_, t_out, y_, &t_reached, CV_NORMAL);
    *t = t_reached;
    if (flag < 0) check(flag, "CVode");
    return flag;
  }

  void check(int flag, const char* call) {
    if (flag < 0) {
      char* name = CVodeGetReturnFlagName(flag);
      std::string flag_name = name ? name : std::to_string(flag);
      std::free(name);  // CVodeGetReturnFlagName allocates with malloc
      fail(std::string(call) + " failed with " + flag_name +
           (data_->last_message.empty() ? "" : " (" + data_->last_message + ")"));
    }
  }

 private:
  void check_flag(int flag, const char* call) {
    if (flag != 0) fail(std::string(call) + " failed with code " + std::to_string(flag));
  }
  [[noreturn]] void fail(const std::string& what) { throw IntegrationError("CVODE: " + what); }

  CallbackData* data_;
  SUNContext ctx_ = nullptr;
  N_Vector y_ = nullptr;
  void* mem_ = nullptr;
  SUNNonlinearSolver nls_ = nullptr;
};

}  // namespace

CvodePredictor::CvodePredictor(const Options& options) : options_(options) {
  if (!(std::isfinite(options.rtol) && options.rtol > 0 && std::isfinite(options.atol) &&
        options.atol > 0)) {
    throw InputError("CVODE predictor: tolerances must be finite and > 0, got rtol " +
                     format_number(options.rtol) + ", atol " + format_number(options.atol));
  }
  if (options.max_num_steps < 1) {
    throw InputError("CVODE predictor: max_num_steps must be >= 1, got " +
                     std::to_string(options.max_num_steps));
  }
}

void CvodePredictor::advance(const Segment& seg, std::span<const ObjectDynamics> dynamics,
                             std::span<ObjectState> state, std::span<double> rest_since_s) const {
  // CVODE evaluates the field anywhere on the floor: the full field, built here when the segment
  // came as rays.
  std::optional<OrientedField> built;
  if (seg.field == nullptr) built = seg.rays->field();
  const OrientedField& field = seg.field ? *seg.field : *built;
  CallbackData data;
  data.field = &field;
  CvodeSession cvode(options_, &data);
  const size_t m = state.size();
  const size_t n_samples = seg.sample_times_s.size();

  for (size_t j = 0; j < m; ++j) {
    ObjectState& s = state[j];
    const ObjectDynamics& xi = dynamics[j];
    auto write_sample = [&](size_t i) {
      if (i < n_samples) seg.samples[i * m + j] = s;
    };

    // At rest where friction wins: nothing moves during this segment.
    if (s.v == 0.0 && xi.drive(field.speed(s.p_W)) <= 0.0) {
      if (!(rest_since_s[j] < kInf)) rest_since_s[j] = seg.t0_s;
      for (size_t i = 0; i < n_samples; ++i) write_sample(i);
      continue;
    }
    rest_since_s[j] = kInf;

    // Moving (or set in motion): integrate to each output time, handling stop events.
    data.xi = xi;
    data.last_message.clear();
    sunrealtype* y = cvode.y();
    y[0] = s.p_W.x();
    y[1] = s.p_W.y();
    y[2] = s.v;
    double t = seg.t0_s;
    cvode.restart(t, seg.t1_s);
    bool stopped = false;
    for (size_t i = 0; i <= n_samples; ++i) {
      const double t_out = i < n_samples ? seg.sample_times_s[i] : seg.t1_s;
      // Output times closer than this are reached already (CVODE refuses such tiny intervals).
      const double too_close = 1e-13 * std::max(1.0, std::abs(t_out));
      while (!stopped && t_out - t > too_close) {
        int flag;
        try {
          flag = cvode.step_to(t_out, &t);
        } catch (const IntegrationError& e) {
          throw IntegrationError(std::string(e.what()) + " at t = " + format_number(t) +
                                 " s, object " + std::to_string(j));
        }
        if (flag != CV_ROOT_RETURN) {
          t = t_out;
          continue;
        }
        // Stop event: v is exactly 0; rest when friction wins, else (a tangency) go on from 0.
        y[2] = 0.0;
        if (xi.drive(field.speed(Eigen::Vector2d(y[0], y[1]))) <= 0.0) {
          stopped = true;
          rest_since_s[j] = t;
        } else {
          cvode.restart(t, seg.t1_s);
        }
      }
      s.p_W = Eigen::Vector2d(y[0], y[1]);
      s.v = stopped ? 0.0 : y[2];
      write_sample(i);
    }
  }
}

}  // namespace airtwin
