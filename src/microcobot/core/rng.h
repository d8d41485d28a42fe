#pragma once
/// @file
/// A seeded, deterministic random number generator (xoshiro256** seeded by splitmix64)
/// whose streams are identical on every platform and standard library, unlike
/// std::normal_distribution. Cheap to copy; never allocates.

#include <cstdint>

namespace mc {

class Rng {
 public:
  explicit Rng(std::uint64_t seed = 0x6d6963726f636fULL);

  /// Next raw 64-bit value.
  std::uint64_t next_u64();
  /// Uniform in [0, 1) with 53 random bits.
  double uniform();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi);
  /// Standard normal (Marsaglia polar method, with the spare value cached).
  double normal();
  /// Normal with mean and standard deviation.
  double normal(double mean, double stddev) { return mean + stddev * normal(); }

 private:
  std::uint64_t s_[4];
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace mc
