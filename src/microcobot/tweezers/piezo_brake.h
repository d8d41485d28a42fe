#pragma once
/// @file
/// The piezo-stack friction brake (option 3.2, thesis section 4.4.1.4, eq. 4.2-4.3, Fig. 4.16).

namespace mc::tweezers {

/// Push force left when a fraction `travel_used` of the stack's travel is spent closing the gap,
/// assuming the force falls in proportion to the travel (eq. 4.2): F_push = F_max (1 - used).
double piezo_push_force(double max_force_N, double travel_used);

/// Resistance between the levers (eq. 4.3): F_block = F_push mu g, g converting the friction at
/// the plate into force between the tips. P-830.20 (1 kN), 85 %, mu = 0.1, g = 0.5 give 7.5 N.
double piezo_block_force(double max_force_N, double travel_used, double mu, double geometry);

}  // namespace mc::tweezers
