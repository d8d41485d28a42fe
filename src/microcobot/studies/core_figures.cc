#include "microcobot/studies/core_figures.h"

#include <cmath>
#include <vector>

#include "microcobot/core/rng.h"

namespace mc::studies {

void rng_figures(report::Report& r) {
  r.section("Random number generator",
            "Sensor noise, PRBS seeds and Brownian motion all come from mc::Rng "
            "(xoshiro256**, identical streams on every platform). Histogram of 200000 normal "
            "draws (seed 1) against the standard normal density.");
  Rng rng(1);
  constexpr int kBins = 81;
  constexpr double kLo = -4.05, kWidth = 0.1;
  constexpr int kDraws = 200000;
  std::vector<double> count(kBins, 0.0), centre(kBins), density(kBins);
  double sum = 0, sum2 = 0;
  for (int i = 0; i < kDraws; ++i) {
    const double v = rng.normal();
    sum += v;
    sum2 += v * v;
    const int b = static_cast<int>(std::floor((v - kLo) / kWidth));
    if (b >= 0 && b < kBins) count[static_cast<std::size_t>(b)] += 1.0;
  }
  for (int b = 0; b < kBins; ++b) {
    const auto i = static_cast<std::size_t>(b);
    centre[i] = kLo + (b + 0.5) * kWidth;
    count[i] /= kDraws * kWidth;
    density[i] = std::exp(-0.5 * centre[i] * centre[i]) / std::sqrt(2 * M_PI);
  }
  const double mean = sum / kDraws;
  r.add_result("mean of draws", mean);
  r.add_result("variance of draws", sum2 / kDraws - mean * mean);
  r.add_figure({"Normal draws",
                "Histogram (points) against the N(0,1) density (line).",
                {"Value", "", false},
                {"Probability density", "", false},
                {{"histogram", centre, count, true}, {"N(0,1) density", centre, density, false}}});
}

}  // namespace mc::studies
