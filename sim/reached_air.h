#pragma once
// The CFD air that each of a set of floor points feels while the nozzle moves: the orientation
// whose wall jet has reached the point (sim/air_transport.h, its lag) and, with the wall jet's
// formation, the point's departure from that orientation's air. A change of the reached
// orientation adds the change of its air at the point to the departure, which then decays at the
// formation's rate there, exp(-dt / tau(r)) a step; the departure never grows as a point moves
// through still air. With the carried front, each point's lag is scaled by phi from the air it
// felt last (sim/air_transport.h), taken again when the newest s or that air's s moves by 5 cm
// or the point by 2 cm.
//
// The twin keeps one point per object (sim/twin.cc); the air probe keeps fixed points, the
// twin's anemometers (sim/air_probe.h).

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "models/cfd_field.h"
#include "sim/air_transport.h"

namespace airtwin {

class ReachedAir {
 public:
  /// `cfd` (must outlive this) gives the air, its start-up the lag and its pulses the formation
  /// (when params ask for them); the air has been at rest at `initial` for long. `points`: how
  /// many points are tracked.
  ReachedAir(const CfdField& cfd, const AirTransportParameters& params, double timestep_s,
             const NozzleOrientation& initial, size_t points);

  /// Records this step's effective orientation and its air `present` (copied); once per step,
  /// before begin_step().
  void push(const NozzleOrientation& effective, const CfdOrientedField& present);

  /// Begins this step's lookups. False when every point feels the present air with no departure
  /// (the lag is off, or no orientation but the present one is kept and nothing is still
  /// forming): at() need not be called then.
  bool begin_step();

  /// What point i feels this step: `field` is the reached orientation's air (null: the present
  /// one) and `departure` (m/s, world frame) is added to it (zero when formed). Call for every
  /// point after begin_step() returned true; the field stays valid until the next begin_step().
  struct PointAir {
    const CfdOrientedField* field = nullptr;
    Eigen::Vector2d departure = Eigen::Vector2d::Zero();
  };
  PointAir at(size_t i, const Eigen::Vector2d& p_W, double z_m);

  const AirTransport& transport() const { return transport_; }

 private:
  // The CFD's air of the orientation `steps` back (0: the present one): the ring's, built once
  // when it was the present orientation.
  const CfdOrientedField& lagged(int steps) const;
  struct PointState;
  // The air of the orientation point f felt last step, when it is the one a step further back
  // now (the ring's); null otherwise.
  const CfdOrientedField* last_reached(const PointState& f);
  // phi for point i at p_W (sim/air_transport.h): the front from the newest s through the air
  // the point felt last step.
  double carry_factor(PointState& f, const Eigen::Vector2d& p_W, double z_m);

  const CfdField& cfd_;
  AirTransport transport_;
  // The air of every kept orientation, in step with the transport's ring: each present air is
  // copied in as it is pushed, so no orientation's air is built again while it is kept (a
  // 25-tracer twin looked up tens of lagged orientations a step while the nozzle moved).
  std::vector<CfdOrientedField> ring_;
  int newest_ = 0;
  // Per point: the orientation whose air reached it last step, its s, how many steps back that
  // was, and its departure from that air; the carried front's phi and where it was taken.
  struct PointState {
    NozzleOrientation reached;
    Eigen::Vector2d reached_s = Eigen::Vector2d::Zero();
    int steps = 0;
    Eigen::Vector2d departure = Eigen::Vector2d::Zero();
    double carry = 1.0;
    bool carry_set = false;
    Eigen::Vector2d carry_s = Eigen::Vector2d::Zero(), carry_p = Eigen::Vector2d::Zero(),
                    carry_reached_s = Eigen::Vector2d::Zero();
  };
  std::vector<PointState> points_;
  bool forming_ = false;  // some point's departure is not yet zero
};

}  // namespace airtwin
