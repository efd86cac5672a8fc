#pragma once
// How long turbulent air keeps its memory as seen from a fixed probe or from a body the air
// sweeps past. An eddy stops being felt when it dies, after the Lagrangian integral time T_L, or
// when the mean flow relative to the observer has carried it past, after its integral length
// L11 over that speed: T = 1 / (1 / T_L + U / L11), with L11 = 0.43 k^1.5 / epsilon at high
// Reynolds number (Pope, Turbulent Flows, 2000, Fig. 6.22 and sections 6.5, 12.4). For a fixed
// probe U is the mean speed (the Eulerian integral time); for a body moving at v through mean air
// u it is |u - v|, the crossing-trajectories effect of particles that drift through the eddies
// (Csanady 1963, J. Atmos. Sci. 20, 201-208; Wells & Stock 1983, J. Fluid Mech. 136, 31-62).
// One home for both the simulated anemometer (models/hotwire.h) and the twin's objects
// (sim/air_forces.h).

namespace airtwin {

/// L11 (m): the longitudinal integral length of turbulence of kinetic energy k (m^2/s^2) and
/// dissipation epsilon (m^2/s^3), 0.43 k^1.5 / epsilon.
double integral_length_m(double k, double epsilon);

/// T (s) = 1 / (1 / T_L + U / L11) for the Lagrangian time `lagrangian_time_s` (> 0), the sweep
/// speed U = `sweep_speed_mps` (>= 0) and L11 from k, epsilon (> 0). Callers check the inputs.
double swept_integral_time_s(double lagrangian_time_s, double sweep_speed_mps, double k,
                             double epsilon);

}  // namespace airtwin
