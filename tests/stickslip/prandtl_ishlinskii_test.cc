// Prandtl-Ishlinskii hysteresis (thesis Fig. 2.6): rate independence, the exact inverse,
// monotone loading, a genuine loop.
#include "microcobot/stickslip/prandtl_ishlinskii.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"

namespace mc::stickslip {
namespace {

TEST(PrandtlIshlinskii, DefaultHas35NonUniformOperatorsAndValidates) {
  const PiParams p = default_pi_params();
  ASSERT_EQ(p.size(), 35u);
  EXPECT_NO_THROW(p.validate());
  // Non-uniform partition: the widths of successive partitions differ.
  const double first = p.thresholds_V[1] - p.thresholds_V[0];
  const double last = p.thresholds_V[34] - p.thresholds_V[33];
  EXPECT_GT(last, 5.0 * first);
  EXPECT_NEAR(pi_loading_curve(p, 100.0), 100.0, 1e-9);
}

TEST(PrandtlIshlinskii, RateIndependent) {
  // A piecewise-linear path through the turning points below, traversed with 4 and with 1000
  // samples per segment (250x faster vs slower): equal outputs at the common samples.
  const PiParams p = default_pi_params();
  const std::vector<double> turns = {0, 80, 20, 60, 35, 95, 5, 50};
  PiState slow = make_pi_state(p), fast = make_pi_state(p);
  const int n_fast = 4, n_slow = 1000;
  for (std::size_t seg = 1; seg < turns.size(); ++seg) {
    for (int j = 1; j <= n_fast; ++j) {
      for (int k = 1; k <= n_slow / n_fast; ++k) {
        const double frac =
            (static_cast<double>(j - 1) + static_cast<double>(k) / (n_slow / n_fast)) / n_fast;
        pi_update(p, slow, turns[seg - 1] + (turns[seg] - turns[seg - 1]) * frac);
      }
      const double u = turns[seg - 1] + (turns[seg] - turns[seg - 1]) * j / n_fast;
      const double yf = pi_update(p, fast, u);
      EXPECT_NEAR(pi_peek(p, slow, u), yf, 1e-9) << "segment " << seg << " sample " << j;
    }
  }
}

TEST(PrandtlIshlinskii, InverseIsExact) {
  const PiParams p = default_pi_params();
  const PiParams q = pi_inverse(p);
  EXPECT_NO_THROW(q.validate());
  PiState sp = make_pi_state(p), sq = make_pi_state(q);
  Rng rng(7);
  double y = 0.0;
  for (int k = 0; k < 5000; ++k) {
    y = std::clamp(y + 8.0 * (rng.uniform() - 0.5), 0.0, 95.0);
    const double u = pi_update(q, sq, y);     // H^-1(y)
    const double back = pi_update(p, sp, u);  // H(H^-1(y))
    ASSERT_NEAR(back, y, 1e-9) << "step " << k;
  }
}

TEST(PrandtlIshlinskii, PeekInverseFindsTheInputOfAGivenOutputFromAnyStateAndClampsOutside) {
  const PiParams p = default_pi_params();
  PiState s = make_pi_state(p);
  Rng rng(11);
  for (int k = 0; k < 200; ++k) {
    pi_update(p, s, 100.0 * rng.uniform());  // a random history: the operators' states differ
    const double lo = pi_peek(p, s, 0.0), hi = pi_peek(p, s, 100.0);
    const double h = lo + (hi - lo) * rng.uniform();
    const double u = pi_peek_inverse(p, s, h, 0.0, 100.0);
    ASSERT_NEAR(pi_peek(p, s, u), h, 1e-10) << "step " << k;  // as 40 halvings of 100 V gave
    EXPECT_EQ(pi_peek_inverse(p, s, lo - 1.0, 0.0, 100.0), 0.0);
    EXPECT_EQ(pi_peek_inverse(p, s, hi + 1.0, 0.0, 100.0), 100.0);
  }
}

TEST(PrandtlIshlinskii, LoopHasAreaAndReturnsOnItself) {
  const PiParams p = default_pi_params();
  PiState s = make_pi_state(p);
  double area = 0.0, u_prev = 0.0, y_prev = pi_update(p, s, 0.0);
  std::vector<double> first_cycle;
  for (int cycle = 0; cycle < 3; ++cycle) {
    for (int k = 1; k <= 400; ++k) {
      const double u = 20.0 * (1.0 - std::cos(2.0 * M_PI * k / 400.0));
      const double y = pi_update(p, s, u);
      if (cycle == 1) {
        area += 0.5 * (y + y_prev) * (u - u_prev);
        first_cycle.push_back(y);
      }
      if (cycle == 2) {
        EXPECT_NEAR(y, first_cycle[static_cast<std::size_t>(k - 1)], 1e-12);
      }
      u_prev = u;
      y_prev = y;
    }
  }
  // Counter-clockwise loop in the (U, H) plane: the rising branch lies below the falling one.
  EXPECT_LT(area, -1.0);
}

TEST(PrandtlIshlinskii, ValidateNamesTheField) {
  PiParams p = default_pi_params();
  p.weights.pop_back();
  try {
    p.validate();
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_EQ(e.field(), "hysteresis.weights");
  }
  p = default_pi_params();
  p.thresholds_V[3] = p.thresholds_V[2];
  EXPECT_THROW(p.validate(), InvalidParams);
}

}  // namespace
}  // namespace mc::stickslip
