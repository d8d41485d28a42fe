#pragma once
/// @file
/// The stage answering PI GCS 2.0: an E-873-like controller of three closed-loop
/// linear axes "1", "2", "3" (X, Y, Z: positions in mm, velocities in mm/s) and, when the platform
/// has the rotary axis under the gripper, a rotation stage "4" (theta: deg,
/// deg/s, as PI's rotation stages report with PUN?), over the platform's own position control
/// (twins/twin_stage.h). Every line is parsed by gcs2_codec.h; every value is checked (axis,
/// number, limits) before it reaches the stage. Commands (docs/hardware.md): *IDN?, CSV?, HLP?,
/// SAI?, PUN?, SVO, SVO?, FRF, FRF?, MOV, MOV?, MVR, POS?, ONT?, VEL, VEL?, TMN?, TMX?, HLT, STP,
/// ERR?, and the single bytes #5, #7, #24. The controller's state (servo, reference, targets,
/// velocities, the error register) is shared by every connection, as one controller's is.
/// Protocol thread only.

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/twins/twin_stage.h"

namespace mc::twins {

struct Gcs2TwinParams {
  int address = 1;  ///< the daisy-chain address (1..254); lines for another address get no reply
  std::string idn = "microcobot, E-873 digital twin, 0, 1.0";  ///< the *IDN? reply
  double velocity_mm_s = 0.1;   ///< each linear axis' VEL at power-up (clamped to the stage's cap)
  double velocity_deg_s = 5.0;  ///< the rotation stage's VEL at power-up (clamped to its cap)
  void validate() const;
};

class Gcs2Twin {
 public:
  Gcs2Twin(TwinStage& stage, Gcs2TwinParams params);
  /// The reply bytes to one line from `client` (empty: none is due: a set command, an error, or a
  /// line for another controller address).
  std::string on_line(ClientId client, std::string_view line);
  /// The reply bytes to a single-byte command (#5, #7, #24).
  std::string on_byte(ClientId client, char byte);
  /// A line longer than gcs2::kMaxLineLength arrived (its rest discarded): error 3.
  void on_overlong_line() { set_error(drivers::gcs2::kCommandTooLong); }
  void on_disconnect(ClientId client) { stage_.release(client); }
  int last_error() const { return error_; }

 private:
  using Lines = std::vector<std::string>;
  /// The axes a query names (all without arguments); false (error 15) on an unknown one.
  bool query_axes(const std::vector<std::string>& args, std::vector<int>& axes);
  /// "AXIS VALUE" pairs; false and the error set on a bad axis or number.
  bool pairs(const std::vector<std::string>& args, std::vector<std::pair<int, double>>& out);
  bool execute(ClientId client, const drivers::gcs2::Request& r, Lines& reply);
  /// The goal to the stage; the error set on a refusal. The linear axes' speed is the slowest
  /// VEL among the linear axes in `moved` (a bit per axis; of all three when none is): they move
  /// as one, straight. The rotation stage turns at its own VEL.
  bool send_goal(ClientId client, unsigned moved);
  /// Axis i's position in the protocol's unit (mm, deg).
  double position(int i) const { return stage_.axis(i).position * per_si(i); }
  /// The protocol's unit per the platform's: mm per m, deg per rad.
  static double per_si(int i);
  void stop_all(ClientId client);
  /// The register holds the last error until ERR? reads it (PIPython qERR: "the last occurred error").
  void set_error(int code) { error_ = code; }
  void update_referencing();
  /// The axis named `word` ("1".."4"), -1 for none of this controller's.
  int axis_index(std::string_view word) const;
  std::vector<int> all_axes() const;

  TwinStage& stage_;
  Gcs2TwinParams params_;
  int axes_;  // 3, or 4 with the rotation stage
  std::array<bool, TwinStage::kMaxAxes> servo_{}, referenced_{}, referencing_{};
  /// In the protocol's units: mm, mm/s (X, Y, Z), deg, deg/s (theta).
  std::array<double, TwinStage::kMaxAxes> target_{}, velocity_{};
  int error_ = drivers::gcs2::kNoError;
};

}  // namespace mc::twins
