#pragma once
/// @file
/// Image-based visual servoing of the stage: a feature seen in the camera's
/// frames (the gripper's tips, a pin) driven onto a target pixel (a part, a hole) by stage
/// velocity commands, with the stage's own position sensors unused.
///
/// The law is ViSP's vpServo (Chaumette & Hutchinson, "Visual servo control, Part I", IEEE RAM
/// 13(4), 2006, eq. 1-5):
///     e = s - s*,    de/dt = L_e v,    v = -lambda L_e^+ e
/// For a camera looking down at a planar stage through a known pixel <-> stage affine map
/// p = A s + b (affine_calibration.h), a point carried by the stage moves in the image by
/// dp/dt = A v: the interaction matrix is the calibration's linear part, L_e = A (constant, no
/// depth), and L_e^+ = A^-1. With an estimate A_hat = A (I + D) the closed loop is
/// de/dt = -lambda (I + D)^-1 e: it converges for any calibration error whose symmetric part keeps
/// (I + D)^-1 positive definite (a 5 % scale error slows or speeds it by 5 %).
///
/// Latency (a frame is exposed, read out and tracked before its command leaves): each feature
/// carries its frame's mid-exposure time t_m. The error used is the one predicted for now,
///     e(t) = e(t_m) + A_hat * integral_{t_m}^{t} v_cmd dt,
/// the stage motion since t_m integrated from the servo's own past commands (never from the
/// stage's sensors): a Smith predictor on the commanded motion. Without it a gain that converges
/// in a few frames overshoots by the motion made during the latency. A command holds until the
/// next step, or for `hold_s` when the stage is to be still before then (a stick-slip axis
/// between its runs: the next exposure then sees it at rest, not mid-way through a sawtooth
/// period, where its slider is off by up to the piezo's stroke).
///
/// A lost feature (or a stale one) holds: zero velocity until the tracker finds it again.
/// step() never allocates, locks or throws: it is stepped from the camera thread's loop, frame
/// in -> stage command out.

#include <array>
#include <cstddef>
#include <limits>

#include <Eigen/Core>

#include "microcobot/vision/affine_calibration.h"

namespace mc::vision {

struct VisualServoParams {
  /// lambda [1/s]: the error decays as exp(-lambda t) while commands act. Chosen on the tuning
  /// set of `microcobot vision servo` (start seed 1; docs/benchmarks.md): 40 1/s, with the stage
  /// moving 13 ms of each 33 ms frame (lambda x 13 ms = 0.53 of the error per frame).
  double gain_per_s = 40.0;
  /// The stage's top speed asked for [m/s] (a stick-slip axis steps at up to ~0.5 mm/s).
  double max_speed_m_s = 0.5e-3;
  /// No motion is commanded when the predicted error is under this [m]: the stage's smallest
  /// reliable open-loop step is ~30-60 nm; a smaller command only dithers it.
  double deadband_m = 0.05e-6;
  /// The predicted error under which the servo reports itself converged [m] (0.3 um).
  double converged_m = 0.3e-6;
  /// A feature older than this at step() is stale: hold [s].
  double max_feature_age_s = 0.2;

  template <class V>
  void visit(V& v) {
    v("gain_per_s", gain_per_s);
    v("max_speed_m_s", max_speed_m_s);
    v("deadband_m", deadband_m);
    v("converged_m", converged_m);
    v("max_feature_age_s", max_feature_age_s);
  }
  /// Throws mc::InvalidParams naming the field (a NaN or negative gain among them).
  void validate() const;
};

/// The tracked feature of one frame.
struct ServoFeature {
  double u_px = 0.0, v_px = 0.0;
  bool found = false;             ///< false: the tracker lost it (the servo holds)
  double t_mid_exposure_s = 0.0;  ///< the frame's mid-exposure time (the loop's clock)
};

enum class ServoStatus { kMoving, kConverged, kHoldLost, kHoldStale, kNoTarget };
const char* to_string(ServoStatus s);

/// What the servo asks of the stage until its next step.
struct ServoCommand {
  Eigen::Vector2d velocity_m_s = Eigen::Vector2d::Zero();  ///< stage (x, y)
  Eigen::Vector2d error_px = Eigen::Vector2d::Zero();      ///< predicted e = s - s* now
  Eigen::Vector2d error_m = Eigen::Vector2d::Zero();       ///< the same in stage metres, A_hat^-1 e
  ServoStatus status = ServoStatus::kNoTarget;
};

class VisualServo {
 public:
  /// `calibration`: the map the servo believes (pixel = A stage + b); `width_px`, `height_px`:
  /// the frame's size (targets outside it are refused). Throws InvalidParams (params, a
  /// non-invertible or non-finite map, a size under 1 px).
  VisualServo(const VisualServoParams& params, const AffineMap& calibration, int width_px, int height_px);

  const VisualServoParams& params() const { return p_; }
  /// The target pixel s*. Throws mc::InvalidInput naming it when it is not finite or not inside
  /// the frame. Forgets the command history (a new move).
  void set_target(double u_px, double v_px);
  bool has_target() const { return has_target_; }
  Eigen::Vector2d target_px() const { return target_; }

  /// One frame: the feature (with its mid-exposure time) in, the stage velocity to apply from
  /// `t_now_s` for `hold_s` (or until the next step, whichever is first) out. The command is
  /// remembered for the latency prediction. Never allocates or throws.
  ServoCommand step(const ServoFeature& feature, double t_now_s,
                    double hold_s = std::numeric_limits<double>::infinity()) noexcept;
  /// Forgets the commands (the stage stopped by someone else: nothing of them is still moving it).
  void clear_history() noexcept;

 private:
  /// Stage displacement commanded over [t0, t1] by the remembered piecewise-constant commands.
  Eigen::Vector2d commanded_motion(double t0_s, double t1_s) const noexcept;
  void remember(double t_s, double hold_s, const Eigen::Vector2d& v) noexcept;

  struct Segment {
    double t_s = 0.0;     ///< the command's start
    double hold_s = 0.0;  ///< ... and how long it lasts at most
    Eigen::Vector2d v = Eigen::Vector2d::Zero();
  };
  static constexpr std::size_t kHistory = 32;  ///< >= the frames a feature may lag (~1 s)

  VisualServoParams p_;
  Eigen::Matrix2d A_;      ///< px/m
  Eigen::Matrix2d A_inv_;  ///< m/px: L_e^+
  int width_, height_;
  Eigen::Vector2d target_ = Eigen::Vector2d::Zero();
  bool has_target_ = false;
  std::array<Segment, kHistory> history_{};  ///< ring, newest at head_ - 1
  std::size_t head_ = 0, count_ = 0;
};

}  // namespace mc::vision
