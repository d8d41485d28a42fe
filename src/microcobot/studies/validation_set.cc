#include "microcobot/studies/validation_set.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/motion/path_generator.h"
#include "microcobot/motion/reference.h"

namespace mc::studies {

namespace {
constexpr double kPi = std::numbers::pi;
// From rest: a lead-in move of 5-40 um at these limits, then this rest, before the case.
constexpr motion::MotionLimits kLeadIn{200e-6, 2e-2};
constexpr double kLeadInDwell_s = 0.02;
// After a move the run goes on at rest this long (the settling is part of the record).
constexpr double kTail_s = 0.05;
// Jerk limit of the 3-D paths: a_max / 10 ms, the path generator's default ramp time.
constexpr double kJerkRamp_s = 0.01;

double log_uniform(Rng& rng, double lo, double hi) {
  return std::exp(rng.uniform(std::log(lo), std::log(hi)));
}

Eigen::Vector3d random_unit(Rng& rng) {
  Eigen::Vector3d v;
  do {
    // One draw per statement: a call's arguments are evaluated in an unspecified order (GCC right
    // to left, clang left to right), and a seeded set must be the same whatever the compiler. The
    // order is the one GCC gave, so that the sets measured before keep their cases.
    const double z = rng.normal(), y = rng.normal(), x = rng.normal();
    v = Eigen::Vector3d(x, y, z);
  } while (v.norm() < 1e-3);
  return v.normalized();
}

motion::PathLimits path_limits(const ValidationCase& c) {
  motion::PathLimits lim;
  lim.max_velocity_m_s = c.velocity_m_s;
  lim.max_acceleration_m_s2 = c.acceleration_m_s2;
  lim.max_jerk_m_s3 = c.acceleration_m_s2 / kJerkRamp_s;
  return lim;
}

motion::PathGenerator make_path(const ValidationCase& c) {
  if (c.profile == CaseProfile::kLine) {
    return motion::PathGenerator::line(-0.5 * c.distance_m * c.direction, 0.5 * c.distance_m * c.direction,
                                       path_limits(c));
  }
  return motion::PathGenerator::arc(c.radius_m * c.radial, Eigen::Vector3d::Zero(), c.direction, c.angle_rad,
                                    path_limits(c));
}

double sine_duration_s(const ValidationCase& c) { return std::min(1.0 / c.frequency_Hz, kMaxCaseDuration_s); }

/// The move's duration without lead-in and tail [s].
double move_duration_s(const ValidationCase& c) {
  switch (c.profile) {
    case CaseProfile::kTrapezoid:
      return motion::trapezoid_duration_s(c.distance_m,
                                          motion::MotionLimits{c.velocity_m_s, c.acceleration_m_s2});
    case CaseProfile::kSine:
      return sine_duration_s(c);
    default:
      return make_path(c).duration_s();
  }
}

/// One random case of kind `profile` within the operating envelope (validation_set.h; redrawn until its move
/// lasts <= kMaxCaseDuration_s).
ValidationCase draw_case(Rng& rng, CaseProfile profile, int index) {
  ValidationCase c;
  c.profile = profile;
  for (int attempt = 0; attempt < 1000; ++attempt) {
    c.power_up = rng.uniform() < 0.5;
    c.sign = rng.uniform() < 0.5 ? -1.0 : 1.0;
    c.velocity_m_s = log_uniform(rng, 20e-6, 800e-6);
    c.acceleration_m_s2 = log_uniform(rng, 2e-3, 0.1);
    c.distance_m = log_uniform(rng, 10e-6, 2e-3);
    c.amplitude_m = log_uniform(rng, 2e-6, 50e-6);
    c.frequency_Hz = log_uniform(rng, 0.1, 5.0);
    c.radius_m = log_uniform(rng, 10e-6, 1e-3);
    c.angle_rad = c.sign * rng.uniform(0.5, 2.0 * kPi);
    c.direction = random_unit(rng);
    const Eigen::Vector3d any = random_unit(rng);
    c.radial = (any - any.dot(c.direction) * c.direction).normalized();
    const double lead_in_sign = rng.uniform() < 0.5 ? -1.0 : 1.0;  // sequenced: see random_unit()
    c.lead_in_m = lead_in_sign * rng.uniform(5e-6, 40e-6);
    const Eigen::Vector3d lead_in_direction = random_unit(rng);  // GCC drew the direction first
    c.lead_in_vec_m = rng.uniform(5e-6, 40e-6) * lead_in_direction;
    c.sensor_seed = 1 + static_cast<int>(rng.next_u64() % 100000);
    // A sine within the trapezoids' envelope: peak velocity <= 800 um/s, acceleration <= 0.1 m/s^2.
    const double w = 2.0 * kPi * c.frequency_Hz;
    if (profile == CaseProfile::kSine && (c.amplitude_m * w > 800e-6 || c.amplitude_m * w * w > 0.1))
      continue;
    if (profile == CaseProfile::kArc && c.radius_m * std::abs(c.angle_rad) < 5e-6) continue;
    if (move_duration_s(c) <= kMaxCaseDuration_s) break;
  }
  c.name = fmt::format("{}{:02d}", to_string(profile), index);
  return c;
}

}  // namespace

bool is_one_d(const ValidationCase& c) {
  return c.profile == CaseProfile::kTrapezoid || c.profile == CaseProfile::kSine;
}

ReferenceFn one_d_reference(const ValidationCase& c, double& start_m, double& duration_s, double& from_s) {
  require(is_one_d(c), "case", "must be a 1-D case (trapezoid or sine)");
  const bool trap = c.profile == CaseProfile::kTrapezoid;
  const double case_start = trap ? -0.5 * c.sign * c.distance_m : 0.0;
  const double lead = c.power_up ? 0.0 : c.lead_in_m;
  start_m = case_start - lead;
  from_s = c.power_up ? 0.0 : motion::trapezoid_duration_s(std::abs(lead), kLeadIn) + kLeadInDwell_s;
  duration_s = from_s + move_duration_s(c) + (trap ? kTail_s : 0.0);
  auto lead_in = std::make_shared<motion::ReferenceLimiter>(kLeadIn, start_m);
  const double t0 = from_s;
  if (trap) {
    const motion::MotionLimits lim{c.velocity_m_s, c.acceleration_m_s2};
    auto l = std::make_shared<motion::ReferenceLimiter>(lim, case_start);
    const double end = case_start + c.sign * c.distance_m;
    return [lead_in, l, t0, case_start, end](double t, double dt) {
      if (t < t0) return lead_in->step(case_start, dt);
      return l->step(end, dt);
    };
  }
  const double w = 2.0 * kPi * c.frequency_Hz;
  const motion::MotionLimits lim{std::max(1.01 * c.amplitude_m * w, 1e-9),
                                 std::max(1.01 * c.amplitude_m * w * w, 1e-9)};
  auto sine =
      std::make_shared<motion::SineReference>(case_start, c.sign * c.amplitude_m, c.frequency_Hz, lim);
  return [lead_in, sine, t0, case_start](double t, double dt) {
    if (t < t0) return lead_in->step(case_start, dt);
    return sine->at(t - t0);
  };
}

std::string to_string(CaseProfile p) {
  switch (p) {
    case CaseProfile::kTrapezoid:
      return "trapezoid";
    case CaseProfile::kSine:
      return "sine";
    case CaseProfile::kLine:
      return "line";
    case CaseProfile::kArc:
      return "arc";
  }
  return "trapezoid";
}

std::string to_string(CaseSet s) { return s == CaseSet::kTuning ? "tuning" : "validation"; }

CaseSet parse_case_set(const std::string& name, const std::string& field) {
  if (name == "tuning") return CaseSet::kTuning;
  if (name == "validation") return CaseSet::kValidation;
  throw InvalidParams(field, "one of tuning, validation (got '" + name + "')");
}

std::vector<ValidationCase> make_case_set(CaseSet set, std::uint64_t seed, int random_cases) {
  require(random_cases >= 0 && random_cases <= 1000, "cases", "must lie in [0, 1000]", random_cases);
  // The validation set is judged only: its draws must not be the tuning set's.
  require(set == CaseSet::kTuning || seed != kTuningSeed, "seed",
          fmt::format("must differ from the tuning set's ({}): the sets are kept apart", kTuningSeed),
          static_cast<double>(seed));
  std::vector<ValidationCase> cases;
  if (set == CaseSet::kTuning) {
    // The named cases (CLI defaults: power-up, 2e-3 m/s^2, sensor seed 1).
    const auto trap = [&](const char* name, double sign, double d, double v, double a) {
      ValidationCase c;
      c.name = name;
      c.sign = sign;
      c.distance_m = d;
      c.velocity_m_s = v;
      c.acceleration_m_s2 = a;
      cases.push_back(c);
    };
    trap("i15-200um/s-fwd", 1.0, 100e-6, 200e-6, 2e-3);
    trap("i15-200um/s-bwd", -1.0, 100e-6, 200e-6, 2e-3);
    trap("i15-50um/s", 1.0, 100e-6, 50e-6, 2e-3);
    trap("i15-500um/s", 1.0, 100e-6, 500e-6, 2e-3);
    trap("i15-500um/s-2e-2", 1.0, 100e-6, 500e-6, 2e-2);
    trap("i31-300um/s-1e-2", 1.0, 150e-6, 300e-6, 1e-2);
    ValidationCase s;
    s.name = "i15-sine";
    s.profile = CaseProfile::kSine;
    s.amplitude_m = 20e-6;
    s.frequency_Hz = 1.0;
    cases.push_back(s);
    ValidationCase l;
    l.name = "i31-line";
    l.profile = CaseProfile::kLine;
    l.distance_m = 1e-3;
    l.velocity_m_s = 200e-6;
    l.acceleration_m_s2 = 2e-3;
    l.direction = Eigen::Vector3d(0.6, 0.64, 0.48).normalized();
    cases.push_back(l);
    ValidationCase a;
    a.name = "i15-arc";
    a.profile = CaseProfile::kArc;
    a.velocity_m_s = 200e-6;
    a.acceleration_m_s2 = 2e-3;
    a.radius_m = 100e-6;
    a.angle_rad = kPi;
    a.direction = Eigen::Vector3d(0.0, 0.3, 1.0).normalized();
    a.radial = Eigen::Vector3d::UnitX();
    cases.push_back(a);
  }
  // Every kind in fixed proportions (4 trapezoids, 2 sines, 1 line, 1 arc in 8), drawn at random.
  Rng rng(seed);
  constexpr CaseProfile kCycle[8] = {
      CaseProfile::kTrapezoid, CaseProfile::kTrapezoid, CaseProfile::kSine, CaseProfile::kLine,
      CaseProfile::kTrapezoid, CaseProfile::kTrapezoid, CaseProfile::kSine, CaseProfile::kArc};
  for (int k = 0; k < random_cases; ++k) cases.push_back(draw_case(rng, kCycle[k % 8], k));
  return cases;
}

bool starts_backward_from_power_up(const ValidationCase& c) {
  return c.power_up && (c.profile == CaseProfile::kTrapezoid || c.profile == CaseProfile::kSine) &&
         c.sign < 0.0;
}

CaseResult run_case(const stickslip::ActuatorModel& model, const motion::StepMap& map,
                    const TrackerSetup& setup, const ValidationCase& c, const TrackingGoals& goals) {
  TrackerSetup su = setup;
  su.sensor.seed = c.sensor_seed;
  CaseResult r;
  if (c.profile == CaseProfile::kTrapezoid || c.profile == CaseProfile::kSine) {
    double start = 0, duration = 0, from = 0;
    const ReferenceFn ref = one_d_reference(c, start, duration, from);
    const auto rec = run_tracker(model, map, TrackerKind::kTracking, su, start, ref, duration, 100, from);
    r.rms_m = rec.metrics.rms_error_m;
    r.max_m = rec.metrics.max_error_m;
    r.final_m = rec.metrics.final_error_m;
    r.edges = rec.metrics.edges;
  } else {
    const motion::PathGenerator path = make_path(c);
    std::unique_ptr<motion::PathGenerator> lead;
    PathLeadIn lead_in;
    if (!c.power_up) {
      const Eigen::Vector3d to = path.sample(0.0).x_m;
      motion::PathLimits lim;
      lim.max_velocity_m_s = kLeadIn.max_velocity_m_s;
      lim.max_acceleration_m_s2 = kLeadIn.max_acceleration_m_s2;
      lim.max_jerk_m_s3 = kLeadIn.max_acceleration_m_s2 / kJerkRamp_s;
      lead =
          std::make_unique<motion::PathGenerator>(motion::PathGenerator::line(to - c.lead_in_vec_m, to, lim));
      lead_in = PathLeadIn{lead.get(), kLeadInDwell_s};
    }
    const auto rec = run_path(model, map, TrackerKind::kTracking, su, path, kTail_s, 100, lead_in);
    r.rms_m = rec.metrics.rms_error_m;
    r.max_m = rec.metrics.max_error_m;
    r.final_m = rec.metrics.final_error_m;
    r.path_deviation_m = rec.metrics.max_deviation_m;
    r.edges = rec.metrics.edges;
  }
  r.pass = r.rms_m <= goals.rms_m && r.max_m <= goals.max_m &&
           (r.path_deviation_m < 0.0 || r.path_deviation_m <= goals.path_deviation_m) &&
           (!starts_backward_from_power_up(c) || r.max_m <= goals.powerup_backward_m);
  return r;
}

ValidationSummary summarise(const std::vector<ValidationCase>& cases, const std::vector<CaseResult>& results,
                            const TrackingGoals& goals) {
  require(cases.size() == results.size() && !cases.empty(), "results", "one per case, at least one");
  ValidationSummary s;
  s.cases = static_cast<int>(cases.size());
  std::vector<double> rms;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const CaseResult& r = results[i];
    s.passed += r.pass ? 1 : 0;
    rms.push_back(r.rms_m);
    s.worst_rms_m = std::max(s.worst_rms_m, r.rms_m);
    s.worst_max_m = std::max(s.worst_max_m, r.max_m);
    s.worst_path_deviation_m = std::max(s.worst_path_deviation_m, r.path_deviation_m);
    if (starts_backward_from_power_up(cases[i]))
      s.worst_powerup_backward_m = std::max(s.worst_powerup_backward_m, r.max_m);
  }
  std::sort(rms.begin(), rms.end());
  const std::size_t n = rms.size();
  s.median_rms_m = n % 2 ? rms[n / 2] : 0.5 * (rms[n / 2 - 1] + rms[n / 2]);
  s.rms_ok = s.worst_rms_m <= goals.rms_m;
  s.median_ok = s.median_rms_m <= goals.median_rms_m;
  s.max_ok = s.worst_max_m <= goals.max_m;
  s.path_ok = s.worst_path_deviation_m <= goals.path_deviation_m;
  s.powerup_ok = s.worst_powerup_backward_m <= goals.powerup_backward_m;
  return s;
}

std::string describe(const ValidationCase& c) {
  const bool one_d = c.profile == CaseProfile::kTrapezoid || c.profile == CaseProfile::kSine;
  const std::string from =
      c.power_up ? "power-up"
                 : fmt::format("rest (lead-in {:.3g} m)", one_d ? c.lead_in_m : c.lead_in_vec_m.norm());
  const std::string dir = c.sign > 0 ? "forward" : "backward";
  switch (c.profile) {
    case CaseProfile::kTrapezoid:
      return fmt::format("trapezoid {} {:.3g} m, <= {:.3g} m/s, <= {:.3g} m/s^2, from {}", dir, c.distance_m,
                         c.velocity_m_s, c.acceleration_m_s2, from);
    case CaseProfile::kSine:
      return fmt::format("sine {} {:.3g} m at {:.3g} Hz ({:.3g} s), from {}", dir, c.amplitude_m,
                         c.frequency_Hz, sine_duration_s(c), from);
    case CaseProfile::kLine:
      return fmt::format(
          "line {:.3g} m along ({:.2f}, {:.2f}, {:.2f}), <= {:.3g} m/s, <= {:.3g} m/s^2, from {}",
          c.distance_m, c.direction.x(), c.direction.y(), c.direction.z(), c.velocity_m_s,
          c.acceleration_m_s2, from);
    case CaseProfile::kArc:
      return fmt::format("arc R {:.3g} m, {:.3g} rad, <= {:.3g} m/s, <= {:.3g} m/s^2, from {}", c.radius_m,
                         c.angle_rad, c.velocity_m_s, c.acceleration_m_s2, from);
  }
  return {};
}

}  // namespace mc::studies
