#include "microcobot/microworld/optical_trap.h"

#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "support/counting_allocator.h"

namespace mc::microworld {
namespace {

// The trap's stiffness is checked against the step like the contact's (a trap
// stiffer than ~1e-2 N/m at 1e-5 s gave wrong corner frequencies with exit 0).
TEST(OpticalTrap, ATrapThatRelaxesWithinAStepIsRefused) {
  OpticalTrapParams p;
  const double gamma = 6.0 * std::numbers::pi * p.viscosity_Pa_s * p.bead_radius_m;
  p.trap_stiffness_N_per_m = 0.49 * gamma / p.dt_s;
  EXPECT_NO_THROW(p.validate());
  for (double k : {0.51 * gamma / p.dt_s, 1e-2, 1e308}) {
    p.trap_stiffness_N_per_m = k;
    try {
      p.validate();
      ADD_FAILURE() << "accepted " << k;
    } catch (const InvalidParams& e) {
      EXPECT_EQ(e.field(), "trap_stiffness_N_per_m");
    }
  }
  p.dt_s = 1e-7;  // a finer step resolves it
  p.trap_stiffness_N_per_m = 1e-2;
  EXPECT_NO_THROW(p.validate());
}

TEST(OpticalTrap, DragAndCornerFromStokes) {
  const OpticalTrap trap{OpticalTrapParams{}};
  const double gamma = 6 * std::numbers::pi * 0.85e-3 * 1.5e-6;
  EXPECT_NEAR(trap.drag(), gamma, 1e-20);
  EXPECT_NEAR(trap.corner_frequency_Hz(), 1e-5 / (2 * std::numbers::pi * gamma), 1e-9);
}

TEST(OpticalTrap, BrownianMotionObeysEquipartitionAndRelaxationTime) {
  const OpticalTrap trap{OpticalTrapParams{}};
  OpticalTrapState s;
  Rng rng(7);
  const int n = 400000;
  double sum2 = 0.0, lag = 0.0, prev = 0.0;
  const int lag_steps = 100;  // 1 ms
  std::vector<double> xs(n);
  {
    test::AllocationGuard guard;
    for (int i = 0; i < n; ++i) {
      trap.step(s, rng);
      xs[static_cast<std::size_t>(i)] = s.bead_m(0);
    }
    EXPECT_EQ(guard.allocations(), 0u);
  }
  for (int i = 0; i < n; ++i) sum2 += xs[static_cast<std::size_t>(i)] * xs[static_cast<std::size_t>(i)];
  for (int i = lag_steps; i < n; ++i)
    lag += xs[static_cast<std::size_t>(i)] * xs[static_cast<std::size_t>(i - lag_steps)];
  (void)prev;
  const double var = sum2 / n;
  EXPECT_NEAR(var / trap.position_variance_m2(), 1.0, 0.05);  // k_B T / k
  // Autocorrelation decays as exp(-2 pi f_c tau).
  const double rho = lag / (n - lag_steps) / var;
  const double expected =
      std::exp(-2 * std::numbers::pi * trap.corner_frequency_Hz() * lag_steps * trap.params().dt_s);
  EXPECT_NEAR(rho, expected, 0.05);
}

TEST(OpticalTrap, StuckBeadPushesTheProbeAway) {
  OpticalTrap trap{OpticalTrapParams{}};
  const double touch = 1.5e-6 + 5e-6;
  trap.set_obstacle(Eigen::Vector2d(0.0, touch));
  EXPECT_EQ(trap.contact_force(Eigen::Vector2d(0.0, -1e-7)).norm(), 0.0);
  const Eigen::Vector2d f = trap.contact_force(Eigen::Vector2d(0.0, 2e-7));
  EXPECT_LT(f(1), 0.0);  // repulsive, along the line of centres
  EXPECT_NEAR(f(0), 0.0, 1e-20);
  // Trap driven into the obstacle: the bead stays out of it and the trap force rises.
  OpticalTrapState s;
  s.trap_m = Eigen::Vector2d(0.0, 0.5e-6);
  Rng rng(3);
  double mean_force = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    trap.step(s, rng);
    mean_force += trap.trap_force(s)(1);
  }
  mean_force /= n;
  // Free bead: mean trap force 0. In contact: the trap pulls the bead towards the obstacle.
  EXPECT_GT(mean_force, 2e-12);  // k (x_trap - x) with x pinned near 0: ~4.9 pN
  EXPECT_LT(s.bead_m(1), 0.5e-6);
}

// A bead pushed into a stuck one is held up to the trap's escape force, k r within
// 20 %, and escapes when pushed harder (it stays behind while the trap moves on).
TEST(OpticalTrap, APushedBeadEscapesAtTheEscapeForce) {
  const OpticalTrapParams p;
  OpticalTrap trap{p};
  const double kr = p.trap_stiffness_N_per_m * p.bead_radius_m;
  EXPECT_NEAR(trap.escape_force_N() / kr, 1.0, 1e-12);  // the default waist puts it at k r
  // Slightly off the line of centres (as a hand never is exactly on it): the trap moves at
  // 2 um/s along x through where the stuck bead is.
  const Eigen::Vector2d obstacle(10e-6, 0.3e-6);
  trap.set_obstacle(obstacle);
  for (int seed = 1; seed <= 5; ++seed) {
    OpticalTrapState s;
    Rng rng(static_cast<std::uint64_t>(seed));
    const double speed = 2e-6, dt = p.dt_s;
    double peak = 0.0;
    for (int i = 0; s.trap_m.x() < 20e-6; ++i) {
      s.trap_m.x() = speed * dt * i;
      trap.step(s, rng);
      peak = std::max(peak, trap.trap_force(s).norm());
    }
    SCOPED_TRACE(seed);
    EXPECT_NEAR(peak / kr, 1.0, 0.2);
    // Escaped: the bead was left behind against the stuck bead, far from the trap, and the trap
    // no longer pulls it.
    const double lag = (s.bead_m - s.trap_m).norm();
    EXPECT_GT(lag, 3.0 * trap.escape_distance_m());
    EXPECT_LT(s.bead_m.x(), obstacle.x());
    EXPECT_LT(trap.trap_force(s).norm(), 0.05 * kr);
  }
}

TEST(OpticalTrap, RejectsNonPhysicalParameters) {
  OpticalTrapParams p;
  p.temperature_K = -1;
  EXPECT_THROW(OpticalTrap{p}, InvalidParams);
  p = {};
  p.contact_stiffness_N_per_m = 1.0;
  EXPECT_THROW(OpticalTrap{p}, InvalidParams);
}

}  // namespace
}  // namespace mc::microworld
