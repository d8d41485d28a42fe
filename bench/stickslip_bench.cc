// One stick-slip axis at the default step: real-time factor (simulated seconds per wall second,
// counter "rtf") and the cost of the odeint reference at equal accuracy (docs/benchmarks.md).
//   build/<dir>/bench/stickslip_bench --benchmark_counters_tabular=true
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <vector>

#include <benchmark/benchmark.h>

#include "microcobot/stickslip/actuator.h"
#include "microcobot/stickslip/prandtl_ishlinskii.h"
#include "microcobot/stickslip/reference_solver.h"

namespace {

namespace ss = mc::stickslip;

struct Scenario {
  double amplitude_V, frequency_Hz;
  ss::Direction direction;
  double duration_s;
};
const Scenario kScenarios[] = {
    {20, 50, ss::Direction::kForward, 0.1},    // scanning
    {40, 50, ss::Direction::kBackward, 0.1},   // stepping near the threshold
    {60, 500, ss::Direction::kForward, 0.02},  // fast stepping: the most sub-stepping
    // Corners off the 10 us grid: 300 Hz is 333.3 steps per period, 150 Hz 666.7.
    {70, 300, ss::Direction::kForward, 0.03},   // fast stepping, off the grid
    {45, 150, ss::Direction::kBackward, 0.04},  // backward stepping, off the grid
};

/// The loosest odeint tolerance whose error against a tight reference (rtol 1e-11) is no larger
/// than the fixed-step integrator's error: "equal accuracy".
double equal_accuracy_tolerance(int i) {
  static std::map<int, double> cache;
  if (cache.count(i)) return cache[i];
  const auto& s = kScenarios[i];
  const ss::StickSlipParams p;
  const ss::ActuatorModel m(p);
  const auto w =
      ss::make_waveform(ss::WaveKind::kSawtooth, s.amplitude_V, s.frequency_Hz, s.direction, p.drive);
  ss::ReferenceOptions tight;
  tight.rel_tol = 1e-11;
  tight.abs_tol_m = 1e-17;
  tight.sample_dt_s = m.dt_s();
  const auto truth = ss::simulate_reference(p, w, s.duration_s, tight);
  const double fixed_error = ss::relative_rms_error(ss::simulate(m, w, s.duration_s), truth);
  double chosen = 1e-10;
  for (double tol : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10}) {
    ss::ReferenceOptions o;
    o.rel_tol = tol;
    o.abs_tol_m = tol * 1e-6;
    o.sample_dt_s = m.dt_s();
    if (ss::relative_rms_error(ss::simulate_reference(p, w, s.duration_s, o), truth) <= fixed_error) {
      chosen = tol;
      break;
    }
  }
  std::fprintf(stderr,
               "scenario %d: fixed-step error %.3g%% of range; reference rtol %.0e at equal accuracy\n", i,
               100 * fixed_error, chosen);
  cache[i] = chosen;
  return chosen;
}

void BM_FixedStep(benchmark::State& state) {
  const auto& s = kScenarios[state.range(0)];
  const ss::StickSlipParams p;
  const ss::ActuatorModel m(p);
  const auto w =
      ss::make_waveform(ss::WaveKind::kSawtooth, s.amplitude_V, s.frequency_Hz, s.direction, p.drive);
  const auto steps = static_cast<long>(std::llround(s.duration_s / m.dt_s()));
  for (auto _ : state) {
    ss::ActuatorState st = m.initial_state();
    m.set_operating_point(st, s.amplitude_V, s.frequency_Hz, s.direction);
    for (long k = 1; k <= steps; ++k) m.step(st, w.segment(static_cast<double>(k - 1) * m.dt_s(), m.dt_s()));
    benchmark::DoNotOptimize(st.x2_m);
  }
  state.counters["rtf"] =
      benchmark::Counter(s.duration_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FixedStep)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);

/// The loop of the Python module's rollout (python/stickslip_py.cc) for one axis: fast stepping
/// (60 V, 500 Hz, 0.1 s) as a stream of one voltage sample per model step (step(state, u), linear
/// between samples), writing x1 and x2 each step. bench/python_rollout_bench.py compares the
/// module's rollout with this (docs/benchmarks.md).
void BM_SampleStream(benchmark::State& state) {
  const ss::StickSlipParams p;
  const ss::ActuatorModel m(p);
  const auto w = ss::make_waveform(ss::WaveKind::kSawtooth, 60.0, 500.0, ss::Direction::kForward, p.drive);
  const double duration_s = 0.1;
  const auto steps = static_cast<std::size_t>(std::llround(duration_s / m.dt_s()));
  std::vector<double> u(steps), x1(steps), x2(steps);
  for (std::size_t k = 0; k < steps; ++k) u[k] = w.value(static_cast<double>(k + 1) * m.dt_s());
  for (auto _ : state) {
    ss::ActuatorState st = m.initial_state();
    m.set_operating_point(st, 60.0, 500.0, ss::Direction::kForward);
    for (std::size_t k = 0; k < steps; ++k) {
      m.step(st, u[k]);
      x2[k] = m.slider_position(st);
      x1[k] = st.x1_m();
    }
    benchmark::DoNotOptimize(x2.data());
    benchmark::DoNotOptimize(x1.data());
  }
  state.counters["rtf"] =
      benchmark::Counter(duration_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SampleStream)->Unit(benchmark::kMillisecond);

void BM_ReferenceEqualAccuracy(benchmark::State& state) {
  const int i = static_cast<int>(state.range(0));
  const auto& s = kScenarios[i];
  const ss::StickSlipParams p;
  const auto w =
      ss::make_waveform(ss::WaveKind::kSawtooth, s.amplitude_V, s.frequency_Hz, s.direction, p.drive);
  ss::ReferenceOptions o;
  o.rel_tol = equal_accuracy_tolerance(i);
  o.abs_tol_m = o.rel_tol * 1e-6;
  o.sample_dt_s = p.integrator.dt_s;
  for (auto _ : state) benchmark::DoNotOptimize(ss::simulate_reference(p, w, s.duration_s, o));
  state.counters["rtf"] =
      benchmark::Counter(s.duration_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["rtol"] = o.rel_tol;
}
BENCHMARK(BM_ReferenceEqualAccuracy)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);

// The PI hysteresis's inverse from a state (the scanning feedforward of the tracking and position
// controllers): the library's regula falsi against the bisection it replaced (40 halvings), on the
// same 64 random histories and targets.
struct PiInverseCase {
  ss::PiState state;
  double h;
};
std::vector<PiInverseCase> pi_inverse_cases(const ss::PiParams& p) {
  std::vector<PiInverseCase> cases;
  ss::PiState s = ss::make_pi_state(p);
  std::uint64_t x = 88172645463325252ull;  // xorshift: the same cases in both benchmarks
  const auto uniform = [&] {
    x ^= x << 13, x ^= x >> 7, x ^= x << 17;
    return static_cast<double>(x >> 11) * 0x1.0p-53;
  };
  for (int k = 0; k < 64; ++k) {
    ss::pi_update(p, s, 100.0 * uniform());
    const double lo = ss::pi_peek(p, s, 0.0), hi = ss::pi_peek(p, s, 100.0);
    cases.push_back({s, lo + (hi - lo) * uniform()});
  }
  return cases;
}
double pi_inverse_by_bisection(const ss::PiParams& p, const ss::PiState& s, double h, double lo, double hi) {
  if (h <= ss::pi_peek(p, s, lo)) return lo;
  if (h >= ss::pi_peek(p, s, hi)) return hi;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ss::pi_peek(p, s, mid) < h ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
void BM_PiPeekInverse(benchmark::State& state) {
  const ss::PiParams p = ss::default_pi_params();
  const auto cases = pi_inverse_cases(p);
  std::size_t k = 0;
  for (auto _ : state) {
    const auto& c = cases[k++ % cases.size()];
    benchmark::DoNotOptimize(state.range(0) ? ss::pi_peek_inverse(p, c.state, c.h, 0.0, 100.0)
                                            : pi_inverse_by_bisection(p, c.state, c.h, 0.0, 100.0));
  }
  state.SetLabel(state.range(0) ? "regula falsi (library)" : "bisection (before)");
}
BENCHMARK(BM_PiPeekInverse)->Arg(0)->Arg(1);

}  // namespace
