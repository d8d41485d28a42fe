#pragma once
/// @file
/// The PI hexapod controller's dialect of GCS 2.0 (a C-887 and its six axes X, Y, Z in mm and U, V,
/// W in deg) over the live platform's parallel positioner (`positioner: parallel`;
/// devices/parallel_positioner.h), reached through the twins' stage (twin_stage.h, live_stage.h):
/// a protocol layer only. The pose conventions are motion/pose.h's (PI's U -> V -> W about moving
/// axes, the pivot moving with the platform), the reachability and the refusal of a move motion/'s
/// (check_move(): the goal and the straight path to it), the motion the platform's: a move runs on
/// the platform's loop under its safety (the client's control and heartbeat as the GCS 2.0 twin's,
/// the console's e-stop: error 10, the target where the positioner stopped).
///
/// Commands (docs/hardware.md, "PI hexapod (C-887) dialect"): *IDN?, CSV?, HLP?, SAI? [ALL], SVO?,
/// SVO (1 only: a hexapod's servo is always on), FRF, FRF?, MOV, MVR, MOV?, POS?, ONT?, VMO?,
/// VLS, VLS?, SPI, SPI?, TMN?, TMX?, KSD, KEN, KEN?, STP, HLT, ERR?, and the single bytes #5, #7,
/// #24. The controller's state (reference, target, velocity, pivot, coordinate systems, the error
/// register) is shared by every connection, as one controller's is. Protocol thread only.

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/motion/pose.h"
#include "microcobot/twins/twin_stage.h"

namespace mc::twins {

struct Gcs2HexapodTwinParams {
  int address = 1;  ///< the daisy-chain address (1..254); lines for another address get no reply
  std::string idn = "microcobot, C-887 digital twin, 0, 1.0";  ///< the *IDN? reply
  /// VLS at power-up [mm/s]: the library's move speed (motion::PoseMoveLimits::max_speed_m_s).
  double velocity_mm_s = 0.1;
  /// VLS's upper limit [mm/s]: within the legs' speed limit for a pure translation
  /// (PoseMoveLimits::max_leg_speed_m_s, 0.8 mm/s) with a margin.
  double max_velocity_mm_s = 0.5;
  /// How long a command after a stop waits for the loop to have applied it (the stopped pose is
  /// the next move's start) before it is refused as busy.
  double stop_wait_s = 0.05;
  void validate() const;
};

class Gcs2HexapodTwin {
 public:
  /// `stage` must outlive the twin (its loop may run or not: unstarted, nothing moves). Throws
  /// mc::InvalidParams when the stage has no parallel positioner.
  Gcs2HexapodTwin(TwinStage& stage, Gcs2HexapodTwinParams params);
  /// The reply bytes to one line from `client` (empty when none is due).
  std::string on_line(ClientId client, std::string_view line);
  /// The reply bytes to a single-byte command (#5, #7, #24).
  std::string on_byte(ClientId client, char byte);
  /// A line longer than gcs2::kMaxLineLength arrived (its rest discarded): error 3.
  void on_overlong_line() { error_ = drivers::gcs2::kCommandTooLong; }
  /// The client went away: if its move runs, the platform stops and holds, and its control is
  /// released (as the project's other twins: a protocol client gone leaves every axis holding).
  void on_disconnect(ClientId client);
  int last_error() const { return error_; }
  bool referenced() const { return referenced_; }

  /// The travel of each axis alone from the home pose (TMN?, TMX?): mm, deg.
  const std::array<double, 6>& travel_min() const { return tmn_; }
  const std::array<double, 6>& travel_max() const { return tmx_; }

 private:
  using Lines = std::vector<std::string>;
  using Pose6 = std::array<double, 6>;  ///< X, Y, Z [mm], U, V, W [deg]
  bool execute(ClientId client, const drivers::gcs2::Request& r, Lines& reply);
  bool query(const drivers::gcs2::Request& r, Lines& reply);
  bool move(ClientId client, const drivers::gcs2::Request& r);
  bool coordinate_system(const drivers::gcs2::Request& r, Lines& reply);
  /// The loop's view, with the referencing, a rejected move and a halt brought up to date.
  live::PositionerView refresh();
  /// A move sent and not yet started, or one running.
  bool busy(const live::PositionerView& v) const;
  /// No move sent or running, the last stop applied, and the legs at rest; once so, on target until
  /// the next move, stop or halt. The legs' rest is their trackers' 3 nm in-position flag, which
  /// the sensor's noise flickers while they hold; a PI controller's ONT? does not flicker once its
  /// move has settled.
  bool on_target(const live::PositionerView& v) {
    if (busy(v) || v.stop_seq < stop_sent_ || v.halted) return false;
    if (v.at_rest) {
      settled_move_ = last_move_;
      settled_stop_ = stop_sent_;
      settled_ = true;
    }
    return settled_ && settled_move_ == last_move_ && settled_stop_ == stop_sent_;
  }
  /// Waits (bounded) for the last stop to be applied; then the target is the stopped pose.
  bool settle_stop();
  /// The pose the next move starts from: the last move's goal while one is queued or runs, the
  /// held pose otherwise.
  motion::PlatformTransform plan_start(const live::PositionerView& v) const;
  /// The move from plan_start() to `goal` when motion's check_move() passes it; nullopt otherwise.
  std::optional<motion::PoseTrajectory> plan(const motion::PlatformTransform& goal,
                                             const live::PositionerView& v) const;
  /// Plans, checks and queues a move to `goal`; false with the error set (7 refused, 1005 busy).
  bool send(ClientId client, const motion::PlatformTransform& goal);
  void stop_all(ClientId client);
  /// Sends `client`'s stop; one the full ring refuses is kept (unsent_stop_) and sent again by
  /// settle_stop(). False when nothing is in flight.
  bool send_stop(ClientId client);
  /// Protocol units (mm, deg) in the enabled coordinate system, about the pivot, and back. With
  /// K = (R_K, d_K) the enabled system's frame in {H} (identity for ZERO) and c the pivot:
  ///   pose = to_pi(K^-1 T, c),  K^-1 T = (R_K^T R, R_K^T (d - d_K));   T = K to_transform(pose, c),
  /// to_pi and to_transform being PI's U -> V -> W convention about a pivot moving with the platform
  /// (motion/pose.h, after PI's hexapod manuals, MS207E §3.7.4).
  Pose6 to_protocol(const motion::PlatformTransform& T) const;
  motion::PlatformTransform from_protocol(const Pose6& p) const;
  /// The enabled system's frame in {H}: K = to_transform(offsets) of its KSD offsets (pivot 0).
  motion::PlatformTransform cs_frame() const;

  TwinStage& stage_;
  const motion::ParallelKinematics& kin_;  ///< the platform's positioner's (immutable)
  Gcs2HexapodTwinParams params_;
  std::array<double, 6> tmn_{}, tmx_{};
  double velocity_mm_s_;
  Eigen::Vector3d pivot_m_ = Eigen::Vector3d::Zero();
  std::map<std::string, motion::PiPose> systems_;  ///< the KSD systems: offsets in SI
  std::string enabled_ = "ZERO";
  motion::PlatformTransform target_;     ///< the last commanded goal, {H}
  motion::PlatformTransform last_goal_;  ///< the goal of the last move sent, {H}
  std::uint64_t last_move_ = 0, stop_sent_ = 0, referencing_ = 0, seen_rejected_ = 0, seen_interrupted_ = 0;
  // ONT?'s latch: the move and stop last seen settled.
  std::uint64_t settled_move_ = 0, settled_stop_ = 0;
  bool settled_ = false;
  ClientId mover_ = 0;
  ClientId unsent_stop_ = 0;  ///< a stop the full ring refused, to send again
  bool referenced_ = false;
  bool after_stop_ = false;    ///< a stop was sent: the target becomes the stopped pose once applied
  bool halted_ = false;        ///< the platform's e-stop (or a fault) seen: the legs at 0 V
  bool control_lost_ = false;  ///< another operator took the platform mid-move
  int error_ = drivers::gcs2::kNoError;
};

}  // namespace mc::twins
