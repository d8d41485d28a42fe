#include "microcobot/dsp/sos.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/dsp/butterworth.h"
#include "microcobot/dsp/signals.h"
#include "support/counting_allocator.h"

namespace mc::dsp {
namespace {

TEST(SosFilter, ImpulseResponseOfOneSectionIsTheDifferenceEquation) {
  // y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2], from its definition.
  const Biquad s{0.2, 0.3, -0.1, -0.5, 0.25};
  SosFilter f({s});
  std::vector<double> x(50, 0.0), ref(50, 0.0);
  x[0] = 1.0;
  for (std::size_t n = 0; n < x.size(); ++n) {
    ref[n] = s.b0 * x[n] + (n >= 1 ? s.b1 * x[n - 1] - s.a1 * ref[n - 1] : 0.0) +
             (n >= 2 ? s.b2 * x[n - 2] - s.a2 * ref[n - 2] : 0.0);
    EXPECT_NEAR(f.process(x[n]), ref[n], 1e-15);
  }
}

TEST(SosFilter, BlockEqualsPerSampleAndResetRestarts) {
  const auto sos = butter(6, 300.0, 10000.0, FilterType::kLowPass);
  const auto x = white_noise(4000, 1.0, 3);
  SosFilter a(sos), b(sos);
  std::vector<double> y(x.size());
  a.process(x, y);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_DOUBLE_EQ(b.process(x[i]), y[i]);
  a.reset();
  std::vector<double> y2(x.size());
  a.process(x, y2);
  EXPECT_EQ(y, y2);
  // In place.
  std::vector<double> z = x;
  a.reset();
  a.process(z, z);
  EXPECT_EQ(z, y);
}

TEST(SosFilter, BlockIsBitIdenticalToPerSampleForAnyCascadeAndBlockSplit) {
  // The block path runs groups of sections as wavefronts (sos.cc); every section must still see
  // the same inputs with the same operations as scipy's per-sample loop: equal bit for bit, for
  // cascades that fill the groups partly (9 and 17 sections split 5+4 and 6+6+5), and for blocks
  // shorter than a group.
  const auto x = white_noise(700, 1.0, 11);
  std::vector<Sos> cascades;
  for (int order : {4, 6, 8, 10, 14, 18})
    cascades.push_back(butter(order, 800.0, 10000.0, FilterType::kHighPass));
  Sos seventeen = butter(20, 800.0, 10000.0, FilterType::kHighPass);
  for (const auto& s : butter(14, 2000.0, 10000.0, FilterType::kLowPass)) seventeen.push_back(s);
  cascades.push_back(seventeen);
  for (const auto& sos : cascades) {
    const std::size_t order = 2 * sos.size();
    for (std::size_t chunk :
         {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{5}, std::size_t{64}, x.size()}) {
      SosFilter block(sos), sample(sos);
      std::vector<double> y(x.size());
      for (std::size_t start = 0; start < x.size(); start += chunk) {
        const std::size_t n = std::min(chunk, x.size() - start);
        block.process(std::span<const double>(x).subspan(start, n), std::span<double>(y).subspan(start, n));
      }
      for (std::size_t i = 0; i < x.size(); ++i) {
        ASSERT_EQ(y[i], sample.process(x[i])) << "order " << order << " chunk " << chunk << " sample " << i;
      }
    }
  }
}

TEST(SosFilter, LoneSectionLookAheadEqualsPerSampleUpToRounding) {
  // A single section's block path is a four-sample look-ahead (sos.cc): not bit-identical, but
  // equal to the difference equation up to rounding, for any block split (tails of 1-3 samples
  // go through the per-sample update), in place, from a non-zero state, and at fc/fs = 1e-4
  // where the poles sit 6e-4 from z = 1.
  const auto x = white_noise(5003, 1.0, 17);
  for (const auto& sos :
       {butter(2, 800.0, 10000.0, FilterType::kHighPass), butter(2, 1.0, 10000.0, FilterType::kLowPass),
        Sos{Biquad{0.2, 0.3, -0.1, -0.5, 0.25}}}) {
    ASSERT_EQ(sos.size(), 1u);
    for (std::size_t chunk : {std::size_t{1}, std::size_t{3}, std::size_t{4}, std::size_t{7}, x.size()}) {
      SosFilter block(sos), sample(sos);
      block.reset_to_steady_state(0.3);
      sample.reset_to_steady_state(0.3);
      std::vector<double> y = x;  // in place
      double max_ref = 0.0, max_err = 0.0;
      for (std::size_t start = 0; start < x.size(); start += chunk) {
        const std::size_t n = std::min(chunk, x.size() - start);
        auto part = std::span<double>(y).subspan(start, n);
        block.process(part, part);
      }
      for (std::size_t i = 0; i < x.size(); ++i) {
        const double ref = sample.process(x[i]);
        max_ref = std::max(max_ref, std::abs(ref));
        max_err = std::max(max_err, std::abs(y[i] - ref));
      }
      // The look-ahead's rounding differs from the per-sample one; both are within the
      // eps / (1 + a1 + a2) the recursion amplifies rounding by (~3e-10 at fc/fs = 1e-4).
      EXPECT_LE(max_err, 1e-9 * max_ref) << "chunk " << chunk << " b0 " << sos[0].b0;
      // The states agree too: the next per-sample output matches.
      EXPECT_NEAR(block.process(1.0), sample.process(1.0), 1e-9 * max_ref);
    }
  }
}

/// Peak of the steady response of `f` (block path) to 40 s of a unit sine at `f_Hz`, fs 10 kHz.
double steady_sine_peak(SosFilter& f, double f_Hz) {
  const std::size_t n = 400000;
  const auto x = sine(n, f_Hz, 10000.0);
  std::vector<double> out(n);
  f.process(x, out);
  double peak = 0;
  for (std::size_t i = n - 20000; i < n; ++i) peak = std::max(peak, std::abs(out[i]));
  return peak;
}

TEST(SosFilter, LoneSectionLookAheadTracksASineAtVeryLowCutoff) {
  SosFilter f(butter(2, 1.0, 10000.0, FilterType::kLowPass));  // fc/fs = 1e-4
  EXPECT_NEAR(steady_sine_peak(f, 1.0), std::sqrt(0.5), 1e-6);
}

TEST(SosFilter, ProcessingDoesNotAllocate) {
  SosFilter f(butter(8, 1000.0, 10000.0, FilterType::kHighPass));
  std::vector<double> x(1024, 1.0), y(1024);
  mc::test::AllocationGuard guard;
  double acc = 0;
  for (int i = 0; i < 100; ++i) acc += f.process(0.1 * i);
  f.process(x, y);
  f.reset();
  f.reset_to_steady_state(2.0);
  EXPECT_EQ(guard.allocations(), 0u);
  EXPECT_TRUE(std::isfinite(acc));
}

TEST(SosFilter, SoundAtVeryLowCutoff) {
  // fc/fs = 1e-4: the step response of a 4th-order low-pass settles to exactly 1 and its
  // sine response matches the designed magnitude.
  const double fs = 10000.0, fc = 1.0;
  const auto sos = butter(4, fc, fs, FilterType::kLowPass);
  SosFilter f(sos);
  double y = 0;
  for (int i = 0; i < 200000; ++i) y = f.process(1.0);
  // Rounding in a section scales as eps / (1 + a1 + a2) ~ eps / (2 pi fc/fs)^2 ~ 3e-10: the
  // cascade settles on unit gain to ~1e-9.
  EXPECT_NEAR(y, 1.0, 1e-8);
  // Steady sine at fc: amplitude 1/sqrt(2).
  f.reset();
  const double peak = steady_sine_peak(f, fc);
  EXPECT_NEAR(peak, std::abs(sos_response(sos, fc, fs)), 1e-6);
  EXPECT_NEAR(peak, std::sqrt(0.5), 1e-6);
}

TEST(SosFilter, SteadyStateResetGivesNoTransient) {
  SosFilter f(butter(4, 50.0, 10000.0, FilterType::kLowPass));
  f.reset_to_steady_state(3.0);
  for (int i = 0; i < 100; ++i) EXPECT_NEAR(f.process(3.0), 3.0, 1e-10);
}

TEST(SosFilter, RejectsEmptyAndNonFinite) {
  EXPECT_THROW(SosFilter(Sos{}), InvalidParams);
  EXPECT_THROW(SosFilter(Sos{Biquad{std::numeric_limits<double>::quiet_NaN(), 0, 0, 0, 0}}), InvalidParams);
  EXPECT_THROW(Biquad::from_row({1, 0, 0, 0, 0, 0}), InvalidParams);
  SosFilter f(Sos{Biquad{}});
  std::vector<double> a(3), b(2);
  EXPECT_THROW(f.process(a, b), InvalidParams);
}

}  // namespace
}  // namespace mc::dsp
