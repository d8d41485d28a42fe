#pragma once
/// @file
/// Closed-loop trajectory-tracking runs of one axis: the tracking controller and its
/// baselines (the hybrid position controller, position_controller.h, fed the moving target, the thesis's PID
/// on the sawtooth amplitude, §2.7 Fig. 2.18) on the same model, sensor noise and reference, with the
/// tracking metrics: RMS and max error during motion, lag, final error. The runner allocates
/// its records only; the controllers inside never allocate.

#include <functional>
#include <string>
#include <vector>

#include <array>

#include "microcobot/motion/baseline_position.h"
#include "microcobot/motion/control_params.h"
#include "microcobot/motion/iterative_learning.h"
#include "microcobot/motion/path_generator.h"
#include "microcobot/motion/position_controller.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/motion/reference.h"
#include "microcobot/motion/tracking_controller.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::studies {

enum class TrackerKind { kTracking, kHybrid, kThesisPid };
std::string to_string(TrackerKind k);
/// "tracking", "hybrid" or "thesis-pid"; anything else throws mc::InvalidParams naming `field`.
TrackerKind parse_tracker_kind(const std::string& name, const std::string& field = "tracker");

struct TrackingMetrics {
  double rms_error_m = 0.0;    ///< RMS of x - r (true position) while the reference moves
  double max_error_m = 0.0;    ///< max |x - r| while the reference moves
  double rms_all_m = 0.0;      ///< RMS over the whole run
  double lag_s = 0.0;          ///< the delay tau that minimises RMS(x(t) - r(t - tau)) in motion
  double final_error_m = 0.0;  ///< |x - r| at the end of the run (reference at rest)
  long edges = 0;              ///< steps taken (tracking controller: edges)
};

struct TrackingRecord {
  std::vector<double> t_s, ref_m, x_m, u_V;
  TrackingMetrics metrics;
};

/// Everything the three trackers need.
struct TrackerSetup {
  motion::TrackingParams tracking;
  motion::PositionControlParams hybrid;
  motion::BaselinePositionParams pid;
  motion::PositionSensorParams sensor;
};

/// The three trackers set up from an axis' parameters. Today's hybrid controller gets a scanning
/// reference fast enough to keep up with the trajectory (1.5x the motion limits), or it would
/// lag by construction rather than by its control law.
TrackerSetup tracker_setup(const motion::ControlParams& p);

using ReferenceFn = std::function<motion::ReferenceSample(double t_s, double dt_s)>;

/// Tracks `reference` (called once per 10 kHz control tick in time order) from `start_m` for
/// `duration_s` with tracker `kind`. The axis starts from power-up (drive at 0 V); the reference
/// rests at `start_m` until the tracker is ready (the tracking controller's power-up ramp-in) and
/// its time starts then. The metrics count the ticks whose reference time is >= `metrics_from_s`
/// (a lead-in move before it leaves the drive where a previous move would). Divergence throws
/// mc::ComputationFailed.
///
/// With `learning` (the tracking controller only), its correction for the reference's tick i is
/// added to the reference position the controller follows (the metrics keep the reference itself),
/// and the measured error x - r after each tick is recorded for it; the caller calls
/// begin_trial() before and learn() after. A position offset rather than a voltage: the controller
/// turns a wanted position into its voltage through the exact hysteresis inverse and phases its
/// edges by it, so an offset is followed as any reference is, while a voltage added after the
/// controller would be undone by its integral and unseen by its edge planning.
TrackingRecord run_tracker(const stickslip::ActuatorModel& model, const motion::StepMap& map,
                           TrackerKind kind, const TrackerSetup& setup, double start_m,
                           const ReferenceFn& reference, double duration_s, int max_records = 20000,
                           double metrics_from_s = 0.0, motion::IterativeLearning* learning = nullptr);

/// The metrics of per-tick records: `moving[k]` marks ticks where the reference moves.
TrackingMetrics tracking_metrics(const std::vector<double>& ref_m, const std::vector<double>& x_m,
                                 const std::vector<char>& moving, double tick_s);

struct PathMetrics {
  double max_deviation_m = 0.0;  ///< max distance of the true 3-D position to the ideal path
  double rms_deviation_m = 0.0;  ///< RMS of that distance while the path runs
  double rms_error_m = 0.0;      ///< RMS of |x - r| (3-D, to the timed reference) while it runs
  double max_error_m = 0.0;
  double final_error_m = 0.0;  ///< |x - r| (3-D) at the end
  long edges = 0;              ///< steps of the three axes
};

struct PathRecord {
  std::vector<double> t_s, deviation_m;
  std::array<std::vector<double>, 3> x_m, ref_m;
  PathMetrics metrics;
};

/// A move before the measured path (it must end where the path starts), then a rest: the drives
/// are then where a previous move left them rather than at power-up.
struct PathLeadIn {
  const motion::PathGenerator* path = nullptr;
  double dwell_s = 0.0;
};

/// The three axes of the XYZ stage (one model, three states, per-axis sensor noise streams:
/// seed + axis) follow `path` with tracker `kind`, then `hold_s` at rest. From power-up the path
/// (or the lead-in) starts once every axis is ready; the metrics cover `path` only.
PathRecord run_path(const stickslip::ActuatorModel& model, const motion::StepMap& map, TrackerKind kind,
                    const TrackerSetup& setup, const motion::PathGenerator& path, double hold_s = 0.03,
                    int max_records = 20000, const PathLeadIn& lead_in = {});

}  // namespace mc::studies
