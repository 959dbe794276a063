#pragma once

#include "projection_collision_avoidance/sim/SampledSimulator.hpp"
#include "projection_collision_avoidance/sim/Scenario.hpp"

namespace projection_collision_avoidance {

/// The fixed-step explicit Runge-Kutta method of simulateContinuous().
enum class ContinuousMethod {
  kRungeKutta4,  ///< classical RK4: 4 evaluations per step, global error O(h^4)
  kRungeKutta6,  ///< Butcher's 6th-order method: 7 evaluations per step, global error O(h^6)
};

/// Runs the scenario's pair in continuous time (ContinuousDynamics: the laws act at every
/// instant, the model the paper simulated in Sec. IV) with a fixed-step Runge-Kutta method at the
/// step @p step on the grid t_k = k step, k = 0 .. duration / step. A step with a pulse edge of
/// u_1 or u_d strictly inside is split there, the pulses taken at each part's middle (sinusoids
/// of u_1 and u_d at the stage times), so the right-hand side is Lipschitz within every step.
/// After each step xi_hat is moved back onto Omega_1 if the discretisation left it (the exact
/// solution does not; the largest such correction is max_boundary_correction). The summary and
/// the observer's samples are taken at the grid points; the sample's command is u_2(t_k). The
/// global error falls as step^4 (RK4) or step^6 (RK6) while the projection does not switch
/// within a step; where it switches (Run 1) the order drops.
/// @param step h (s): finite, > 0, and duration / h a whole number (within 1e-9)
/// @param method the Runge-Kutta method
/// @throws ParameterError naming "step" for a bad step, "formation.followers" for more than
///         one follower, the key of a link that delays or loses (controller.leader_information
///         .link.*), of a time headway or shaped feed-forward, or of an invalid scenario entry
SimulationSummary simulateContinuous(const Scenario& scenario, double step,
                                     const SampleObserver& observer = {},
                                     ContinuousMethod method = ContinuousMethod::kRungeKutta4);

}  // namespace projection_collision_avoidance
