#include "microcobot/studies/delay_case_sets.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"

namespace mc::studies {

std::vector<SetCase> tuning_set() {
  std::vector<SetCase> set;
  std::uint64_t seed = 1;
  for (double delay : {0.1, 0.2})
    for (double loss : {0.0, 0.2})
      for (double k_e : {300.0, 1000.0, 3000.0})
        for (auto [error, noise] : {std::pair{-1e-3, 0.0}, {1e-3, 4e-3}})
          set.push_back(
              {{delay, 0.1 * 0.5 * delay, loss, teleop::Scheme::kNone, seed++, error}, k_e, 1.0, noise});
  return set;
}

std::vector<SetCase> validation_set(int n, std::uint64_t seed) {
  require(n >= 1 && n <= 1000, "cases", "must be within [1, 1000]", n);
  Rng rng(seed);
  std::vector<SetCase> set;
  for (int i = 0; i < n; ++i) {
    const double delay = rng.uniform(0.0, 0.2);
    const double jitter = rng.uniform(0.0, 0.5) * 0.5 * delay;
    const double loss = rng.uniform(0.0, 0.2);
    const double k_e = 300.0 * std::pow(10.0, rng.uniform());  // log-uniform over a decade
    const double error = rng.uniform(-1.5e-3, 1.5e-3), noise = rng.uniform(0.0, 5e-3);
    const std::uint64_t link_seed = rng.next_u64();
    const double exponent = rng.uniform() < 0.5 ? 1.0 : 1.5;
    set.push_back({{delay, jitter, loss, teleop::Scheme::kNone, link_seed, error}, k_e, exponent, noise});
  }
  return set;
}

SetSummary run_case_set(const teleop::DelayedTeleopParams& base, const std::vector<SetCase>& set,
                        teleop::Scheme scheme) {
  SetSummary s;
  s.set = set;
  for (const SetCase& sc : set) {
    teleop::DelayedTeleopParams p = base;
    p.wall_stiffness_N_m = sc.wall_stiffness_N_m;
    p.wall_exponent = sc.wall_exponent;
    p.mmt.force_noise_N = sc.force_noise_N;
    teleop::DelayCase c = sc.c;
    c.scheme = scheme;
    teleop::DelayCaseResult r = teleop::run_delay_case(p, c);
    ++s.cases;
    s.settled += r.settled ? 1 : 0;
    s.worst_handle_excursion_m = std::max(s.worst_handle_excursion_m, r.max_handle_excursion_m);
    s.worst_force_error = std::max(s.worst_force_error, r.contact_force_max_error);
    s.worst_settling_time_s = std::max(s.worst_settling_time_s, r.settling_time_s);
    s.min_observed_energy_J = std::min(s.min_observed_energy_J, r.min_observed_energy_J);
    s.results.push_back(std::move(r));
  }
  return s;
}

}  // namespace mc::studies
