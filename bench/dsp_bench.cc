// SOS filtering and Welch PSD throughput. Results and commands: docs/benchmarks.md.
// MC_WELCH_DATA=FILE (raw float64, written by bench/scipy_welch_bench.py) makes the Welch
// benchmark use the same samples scipy is timed on.
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <benchmark/benchmark.h>

#include "microcobot/dsp/butterworth.h"
#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/welch.h"

namespace {

void BM_SosFilterBlock(benchmark::State& state) {
  const int sections = static_cast<int>(state.range(0));
  mc::dsp::SosFilter f(mc::dsp::butter(2 * sections, 500.0, 10000.0, mc::dsp::FilterType::kLowPass));
  const auto x = mc::dsp::white_noise(65536, 1.0, 1);
  std::vector<double> y(x.size());
  for (auto _ : state) {
    f.process(x, y);
    benchmark::DoNotOptimize(y.data());
  }
  const double per = static_cast<double>(x.size()) * sections;
  state.counters["ns_per_sample_section"] =
      benchmark::Counter(per * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SosFilterBlock)->Arg(1)->Arg(2)->Arg(4)->Arg(8);

/// The previous block path (one section at a time over the whole block), kept here as the
/// baseline that BM_SosFilterBlock is compared with in the same run (docs/benchmarks.md).
void BM_SosFilterBlockSectionBySection(benchmark::State& state) {
  const int sections = static_cast<int>(state.range(0));
  const auto sos = mc::dsp::butter(2 * sections, 500.0, 10000.0, mc::dsp::FilterType::kLowPass);
  const auto x = mc::dsp::white_noise(65536, 1.0, 1);
  std::vector<double> y(x.size()), z(2 * sos.size(), 0.0);
  for (auto _ : state) {
    const double* src = x.data();
    for (std::size_t i = 0; i < sos.size(); ++i) {
      const mc::dsp::Biquad s = sos[i];
      double z0 = z[2 * i], z1 = z[2 * i + 1];
      for (std::size_t k = 0; k < x.size(); ++k) {
        const double in = src[k];
        const double out = s.b0 * in + z0;
        z0 = s.b1 * in - s.a1 * out + z1;
        z1 = s.b2 * in - s.a2 * out;
        y[k] = out;
      }
      z[2 * i] = z0;
      z[2 * i + 1] = z1;
      src = y.data();
    }
    benchmark::DoNotOptimize(y.data());
  }
  const double per = static_cast<double>(x.size()) * sections;
  state.counters["ns_per_sample_section"] =
      benchmark::Counter(per * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SosFilterBlockSectionBySection)->Arg(1)->Arg(2)->Arg(4)->Arg(8);

std::vector<double> welch_data() {
  if (const char* path = std::getenv("MC_WELCH_DATA")) {
    std::ifstream in(path, std::ios::binary);
    std::vector<double> x(1000000);
    in.read(reinterpret_cast<char*>(x.data()), static_cast<std::streamsize>(x.size() * sizeof(double)));
    if (in) return x;
  }
  return mc::dsp::white_noise(1000000, 1.0, 1);
}

void BM_Welch1e6(benchmark::State& state) {
  const auto x = welch_data();
  mc::dsp::WelchOptions o;
  o.fs_Hz = 10000.0;
  o.nperseg = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    auto p = mc::dsp::welch(x, o);
    benchmark::DoNotOptimize(p.value.data());
  }
}
BENCHMARK(BM_Welch1e6)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

}  // namespace
