#pragma once
/// @file
/// Tracking that generalises: the tracking controller's gains are chosen on a
/// tuning set and judged on a validation set drawn apart from it. Both are seeded random draws
/// over the operating envelope (trapezoids 20-800 um/s, 10 um-2 mm, 2e-3-0.1 m/s^2, both
/// directions; sines 0.1-5 Hz of 2-50 um; 3-D lines and arcs; each from power-up or from rest);
/// the tuning set also holds named cases (trapezoids of 50-500 um/s, a sine, a 3-D
/// line and an arc). A case from rest starts after
/// a short lead-in move and a rest, so the drive sits where a previous move left it; a case from
/// power-up starts with the drive at 0 V. run_validation() runs each case on the model (one axis,
/// or the three axes of the XYZ stage) and checks the goals (TrackingGoals).

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "microcobot/motion/step_map.h"
#include "microcobot/stickslip/actuator.h"
#include "microcobot/studies/tracking_run.h"

namespace mc::studies {

enum class CaseProfile { kTrapezoid, kSine, kLine, kArc };
std::string to_string(CaseProfile p);

enum class CaseSet { kTuning, kValidation };
std::string to_string(CaseSet s);
/// "tuning" or "validation"; anything else throws mc::InvalidParams naming `field`.
CaseSet parse_case_set(const std::string& name, const std::string& field = "set");

/// The default seeds. The validation seed must differ from the tuning seed (the sets are kept apart).
inline constexpr std::uint64_t kTuningSeed = 15;
inline constexpr std::uint64_t kValidationSeed = 31;
/// The default sizes: the validation set >= 30 references.
inline constexpr int kTuningRandomCases = 32;
inline constexpr int kValidationCases = 32;
/// Longest reference drawn [s]: a draw whose move would last longer is drawn again, so that a
/// 2 mm move at 20 um/s (100 s of simulation) does not dominate the run time; the sine runs one
/// period or this long, whichever is shorter.
inline constexpr double kMaxCaseDuration_s = 1.5;

struct ValidationCase {
  std::string name;
  CaseProfile profile = CaseProfile::kTrapezoid;
  bool power_up = true;   ///< from power-up (drive at 0 V), else from rest after a lead-in move
  double sign = 1.0;      ///< 1-D: +1 forward, -1 backward
  double distance_m = 0;  ///< trapezoid, line: length
  double velocity_m_s = 0, acceleration_m_s2 = 0;        ///< trapezoid, line, arc: limits
  double amplitude_m = 0, frequency_Hz = 0;              ///< sine
  double radius_m = 0, angle_rad = 0;                    ///< arc
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< line direction, arc axis
  Eigen::Vector3d radial = Eigen::Vector3d::UnitY();     ///< arc: start point = centre + R radial
  /// From rest: the lead-in move, ending where the case starts (1-D: signed length; 3-D: vector).
  double lead_in_m = 0;
  Eigen::Vector3d lead_in_vec_m = Eigen::Vector3d::Zero();
  int sensor_seed = 1;  ///< sensor noise stream of the case (3-D: + axis)
};

/// The tuning set (the named cases, then `random_cases` drawn with `seed`)
/// or the validation set (`random_cases` drawn with `seed`). Deterministic in the seed.
std::vector<ValidationCase> make_case_set(CaseSet set, std::uint64_t seed, int random_cases);

/// The tracking goals every run_validation() checks [m].
struct TrackingGoals {
  double rms_m = 150e-9;               ///< every case's RMS error in motion
  double median_rms_m = 100e-9;        ///< the median of the cases' RMS
  double max_m = 300e-9;               ///< every case's max error in motion
  double path_deviation_m = 200e-9;    ///< every 3-D case's max distance to the path
  double powerup_backward_m = 250e-9;  ///< max error of a 1-D case that starts backward from power-up
};

struct CaseResult {
  double rms_m = 0, max_m = 0, final_m = 0;
  double path_deviation_m = -1;  ///< 3-D cases only (-1: not applicable)
  long edges = 0;
  bool pass = false;  ///< every per-case goal that applies
};

struct ValidationSummary {
  int cases = 0, passed = 0;
  double median_rms_m = 0, worst_rms_m = 0, worst_max_m = 0, worst_path_deviation_m = 0;
  double worst_powerup_backward_m = 0;  ///< 0 when the set has no such case
  bool rms_ok = false, median_ok = false, max_ok = false, path_ok = false, powerup_ok = false;
  bool all_ok() const { return rms_ok && median_ok && max_ok && path_ok && powerup_ok; }
};

/// One case with the tracking controller of `setup` (its sensor seed replaced by the case's).
CaseResult run_case(const stickslip::ActuatorModel& model, const motion::StepMap& map,
                    const TrackerSetup& setup, const ValidationCase& c, const TrackingGoals& goals = {});

/// Whether the case's first motion is backward from power-up (the transient goal applies).
bool starts_backward_from_power_up(const ValidationCase& c);

ValidationSummary summarise(const std::vector<ValidationCase>& cases, const std::vector<CaseResult>& results,
                            const TrackingGoals& goals = {});

/// Whether the case runs on one axis (a trapezoid or a sine) rather than the XYZ stage.
bool is_one_d(const ValidationCase& c);

/// A 1-D case's reference, fresh (its limiters at their start): `start_m` where the axis starts,
/// `duration_s` the run (lead-in, move, tail), `from_s` where the move starts on the reference's
/// clock (after the lead-in and its rest). Throws mc::InvalidParams for a 3-D case.
ReferenceFn one_d_reference(const ValidationCase& c, double& start_m, double& duration_s, double& from_s);

/// A one-line description of the case's reference (SI units).
std::string describe(const ValidationCase& c);

}  // namespace mc::studies
