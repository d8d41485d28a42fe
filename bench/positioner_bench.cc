// The 6-DOF parallel positioner's kinematics on one core (docs/benchmarks.md): poses per second
// (counter items_per_second) of the closed-form inverse kinematics from a SmarPod pose, and of
// the forward kinematics by Newton's method seeded with the previous pose of a random walk
// (a servo loop's case) and from home (a cold start), over seeded random reachable poses; once, the
// round trip's accuracy and the Newton steps over 10^5 poses.
//   build/<dir>/bench/positioner_bench --benchmark_min_time=0.5
#include <algorithm>
#include <cstddef>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Geometry>

#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/parallel_workspace.h"

namespace {

namespace mm = mc::motion;
constexpr double kDeg = M_PI / 180.0;
constexpr std::size_t kPoses = 4096;

/// Independent reachable poses, uniform in the box of the kinematics' test.
const std::vector<mm::SmarPodPose>& random_poses(const mm::ParallelKinematics& k) {
  static const std::vector<mm::SmarPodPose> poses = [&] {
    std::mt19937_64 rng(2026);
    std::uniform_real_distribution<double> t(-4e-3, 4e-3), z(-3e-3, 3e-3), a(-10 * kDeg, 10 * kDeg);
    std::vector<mm::SmarPodPose> v;
    while (v.size() < kPoses) {
      const mm::SmarPodPose p{t(rng), t(rng), z(rng), a(rng), a(rng), a(rng)};
      if (mm::check_pose(k, p).ok()) v.push_back(p);
    }
    return v;
  }();
  return poses;
}

/// A random walk of reachable poses, up to 0.2 mm and 1 deg per coordinate a step.
const std::vector<mm::SmarPodPose>& walk(const mm::ParallelKinematics& k) {
  static const std::vector<mm::SmarPodPose> poses = [&] {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> dt(-0.2e-3, 0.2e-3), da(-1 * kDeg, 1 * kDeg);
    std::vector<mm::SmarPodPose> v{mm::SmarPodPose{}};
    while (v.size() < kPoses) {
      const mm::SmarPodPose& p = v.back();
      const mm::SmarPodPose n{p.x + dt(rng),  p.y + dt(rng),  p.z + dt(rng),
                              p.rx + da(rng), p.ry + da(rng), p.rz + da(rng)};
      if (mm::check_pose(k, n).ok()) v.push_back(n);
    }
    return v;
  }();
  return poses;
}

std::vector<mm::LegCoordinates> legs_of(const mm::ParallelKinematics& k,
                                        const std::vector<mm::SmarPodPose>& poses) {
  std::vector<mm::LegCoordinates> q(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) k.inverse(mm::to_transform(poses[i]), q[i]);
  return q;
}

void InverseKinematics(benchmark::State& state) {
  const mm::ParallelKinematics k;
  const auto& poses = random_poses(k);
  mm::LegCoordinates q;
  std::size_t i = 0;
  for (auto _ : state) {
    const bool ok = k.inverse(mm::to_transform(poses[i]), q);
    benchmark::DoNotOptimize(ok);
    benchmark::DoNotOptimize(q.data());
    i = (i + 1) % kPoses;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(InverseKinematics);

void ForwardFromThePreviousPose(benchmark::State& state) {
  const mm::ParallelKinematics k;
  const auto q = legs_of(k, walk(k));
  mm::PlatformTransform previous;
  std::size_t i = 0, steps = 0;
  for (auto _ : state) {
    const mm::ForwardResult f = k.forward(q[i], previous);
    previous = f.T;
    steps += static_cast<std::size_t>(f.iterations);
    if (++i == kPoses) {
      i = 0;
      previous = {};  // the walk starts at home
    }
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["newton_steps"] = static_cast<double>(steps) / static_cast<double>(state.iterations());
}
BENCHMARK(ForwardFromThePreviousPose);

void ForwardFromHome(benchmark::State& state) {
  const mm::ParallelKinematics k;
  const auto q = legs_of(k, random_poses(k));
  std::size_t i = 0, steps = 0;
  for (auto _ : state) {
    const mm::ForwardResult f = k.forward(q[i]);
    benchmark::DoNotOptimize(f.T.d.data());
    steps += static_cast<std::size_t>(f.iterations);
    i = (i + 1) % kPoses;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["newton_steps"] = static_cast<double>(steps) / static_cast<double>(state.iterations());
}
BENCHMARK(ForwardFromHome);

/// The accuracy goals on 10^5 poses, once: the IK -> FK round trip of independent random reachable
/// poses from home (counters max_error_m, max_error_rad, max_steps_from_home) and, along a random walk, the
/// fraction of forward kinematics from the previous pose done in at most 5 Newton steps (within_5_steps).
void RoundTripOf100kPoses(benchmark::State& state) {
  const mm::ParallelKinematics k;
  constexpr int kN = 100000;
  double worst_m = 0.0, worst_rad = 0.0, within_five = 0.0;
  int most_from_home = 0;
  for (auto _ : state) {
    std::mt19937_64 rng(100000);
    std::uniform_real_distribution<double> t(-4e-3, 4e-3), z(-3e-3, 3e-3), a(-10 * kDeg, 10 * kDeg);
    for (int n = 0; n < kN;) {
      const mm::SmarPodPose p{t(rng), t(rng), z(rng), a(rng), a(rng), a(rng)};
      if (!mm::check_pose(k, p).ok()) continue;
      ++n;
      const mm::PlatformTransform T = mm::to_transform(p);
      mm::LegCoordinates q;
      k.inverse(T, q);
      const mm::ForwardResult f = k.forward(q);
      most_from_home = std::max(most_from_home, f.iterations);
      worst_m = std::max(worst_m, (f.T.d - T.d).lpNorm<Eigen::Infinity>());
      worst_rad = std::max(worst_rad, Eigen::AngleAxisd(f.T.R * T.R.transpose()).angle());
    }
    std::uniform_real_distribution<double> dt(-0.2e-3, 0.2e-3), da(-1 * kDeg, 1 * kDeg);
    mm::SmarPodPose p;
    mm::PlatformTransform previous;
    int five = 0;
    for (int n = 0; n < kN;) {
      const mm::SmarPodPose next{p.x + dt(rng),  p.y + dt(rng),  p.z + dt(rng),
                                 p.rx + da(rng), p.ry + da(rng), p.rz + da(rng)};
      if (!mm::check_pose(k, next).ok()) continue;
      ++n;
      p = next;
      mm::LegCoordinates q;
      k.inverse(mm::to_transform(p), q);
      const mm::ForwardResult f = k.forward(q, previous);
      previous = f.T;
      five += f.iterations <= 5 ? 1 : 0;
    }
    within_five = static_cast<double>(five) / kN;
  }
  state.counters["max_error_m"] = worst_m;
  state.counters["max_error_rad"] = worst_rad;
  state.counters["within_5_steps"] = within_five;
  state.counters["max_steps_from_home"] = most_from_home;
}
BENCHMARK(RoundTripOf100kPoses)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
