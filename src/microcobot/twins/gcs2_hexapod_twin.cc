#include "microcobot/twins/gcs2_hexapod_twin.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <thread>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/drivers/gcs2_hexapod.h"
#include "microcobot/motion/parallel_workspace.h"
#include "microcobot/motion/pose_trajectory.h"

namespace mc::twins {

namespace g = drivers::gcs2;
using motion::PlatformTransform;

namespace {

constexpr double kM = 1e-3;                        // m per mm
constexpr double kRad = std::numbers::pi / 180.0;  // rad per deg
constexpr std::size_t kMaxSystems = 16;            // KSD systems the twin keeps

PlatformTransform compose(const PlatformTransform& a, const PlatformTransform& b) {
  PlatformTransform t;
  t.R = a.R * b.R;
  t.d = a.R * b.d + a.d;
  return t;
}

PlatformTransform inverse(const PlatformTransform& a) {
  PlatformTransform t;
  t.R = a.R.transpose();
  t.d = -(t.R * a.d);
  return t;
}

motion::PiPose to_si(const std::array<double, 6>& p) {
  return {p[0] * kM, p[1] * kM, p[2] * kM, p[3] * kRad, p[4] * kRad, p[5] * kRad};
}

/// How far coordinate `i` alone goes from home in direction `sign` (mm or deg): the largest value in
/// [0, span] whose pose motion's check_pose() passes, by bisection to span / 2^40.
double travel(const motion::ParallelKinematics& k, int i, double sign, double span) {
  auto ok = [&](double v) {
    std::array<double, 6> p{};
    p[static_cast<std::size_t>(i)] = sign * v;
    return motion::check_pose(k, motion::to_transform(to_si(p))).ok();
  };
  if (ok(span)) return sign * span;
  double lo = 0.0, hi = span;
  for (int n = 0; n < 40; ++n) {
    const double mid = 0.5 * (lo + hi);
    (ok(mid) ? lo : hi) = mid;
  }
  return sign * lo;
}

const motion::ParallelKinematics& positioner_of(const TwinStage& stage) {
  const motion::ParallelKinematics* k = stage.positioner_kinematics();
  if (k == nullptr)
    throw InvalidParams("--emulate gcs2-hexapod",
                        "needs the platform's parallel positioner (positioner: parallel)");
  return *k;
}

}  // namespace

void Gcs2HexapodTwinParams::validate() const {
  require(address >= 1 && address <= 254, "gcs2_hexapod.address", "must be within [1, 254]", address);
  require(std::isfinite(velocity_mm_s) && velocity_mm_s > 0, "gcs2_hexapod.velocity_mm_s", "must be > 0",
          velocity_mm_s);
  require(std::isfinite(max_velocity_mm_s) && max_velocity_mm_s >= velocity_mm_s,
          "gcs2_hexapod.max_velocity_mm_s", "must be >= velocity_mm_s", max_velocity_mm_s);
  require(std::isfinite(stop_wait_s) && stop_wait_s > 0 && stop_wait_s <= 1.0, "gcs2_hexapod.stop_wait_s",
          "must be within (0, 1] s", stop_wait_s);
  require(!idn.empty() && idn.size() < 200 && idn.find('\n') == std::string::npos, "gcs2_hexapod.idn",
          "must be one line of fewer than 200 characters");
}

Gcs2HexapodTwin::Gcs2HexapodTwin(TwinStage& stage, Gcs2HexapodTwinParams params)
    : stage_(stage),
      kin_(positioner_of(stage)),
      params_(std::move(params)),
      velocity_mm_s_(params_.velocity_mm_s) {
  params_.validate();
  // Translations searched within 50 mm, rotations within 89 deg (PI's angles are unique below 90).
  for (int i = 0; i < 6; ++i) {
    const double span = i < 3 ? 50.0 : 89.0;
    tmn_[static_cast<std::size_t>(i)] = travel(kin_, i, -1.0, span);
    tmx_[static_cast<std::size_t>(i)] = travel(kin_, i, +1.0, span);
  }
  target_ = last_goal_ = stage_.positioner_view().reference;
}

PlatformTransform Gcs2HexapodTwin::cs_frame() const {
  if (enabled_ == g::kZeroCs) return {};
  return motion::to_transform(systems_.at(enabled_));
}

Gcs2HexapodTwin::Pose6 Gcs2HexapodTwin::to_protocol(const PlatformTransform& T) const {
  const motion::PiPose p = motion::to_pi(compose(inverse(cs_frame()), T), pivot_m_);
  return {p.X / kM, p.Y / kM, p.Z / kM, p.U / kRad, p.V / kRad, p.W / kRad};
}

PlatformTransform Gcs2HexapodTwin::from_protocol(const Pose6& p) const {
  return compose(cs_frame(), motion::to_transform(to_si(p), pivot_m_));
}

live::PositionerView Gcs2HexapodTwin::refresh() {
  const live::PositionerView v = stage_.positioner_view();
  if (v.rejected_seq > seen_rejected_) {
    seen_rejected_ = v.rejected_seq;
    error_ = g::kStopped;  // the platform dropped it unstarted (halted, control lost): it stands stopped
  }
  if (v.interrupted_seq > seen_interrupted_) {
    // The platform held the move under way short of its goal (the heartbeat went stale, a console
    // user took control): it stands stopped where the legs hold, as after a stop.
    seen_interrupted_ = v.interrupted_seq;
    error_ = g::kStopped;
    target_ = last_goal_ = v.reference;
  }
  if (v.halted && !halted_) {
    // The platform's e-stop (or a device's fault): every leg at 0 V where it was, the target there.
    halted_ = true;
    settled_ = false;
    error_ = g::kStopped;
    target_ = last_goal_ = v.measured;
    after_stop_ = false;
    unsent_stop_ = 0;
    referencing_ = 0;
    mover_ = 0;
  } else if (!v.halted && halted_) {
    halted_ = false;  // reset: the legs hold where they were measured
    target_ = last_goal_ = v.reference;
  }
  // Control lost to another operator (a console user): the platform held the positioner; the
  // target is where it holds once the loop has stopped the move.
  if (mover_ != 0 && !stage_.controls(mover_)) {
    mover_ = 0;
    control_lost_ = true;
  }
  if (control_lost_ && !v.moving) {
    control_lost_ = false;
    if (!halted_) target_ = last_goal_ = v.reference;
  }
  // A reference stopped, dropped or interrupted before its end leaves the platform unreferenced.
  if (referencing_ &&
      (stop_sent_ > referencing_ || v.rejected_seq >= referencing_ || v.interrupted_seq >= referencing_))
    referencing_ = 0;
  if (referencing_ && v.started_seq >= referencing_ && !v.moving && v.at_rest) {
    referenced_ = true;
    referencing_ = 0;
  }
  return v;
}

bool Gcs2HexapodTwin::busy(const live::PositionerView& v) const {
  const bool pending = last_move_ > stop_sent_ && last_move_ > v.started_seq && last_move_ > v.rejected_seq;
  return pending || v.moving;
}

bool Gcs2HexapodTwin::send_stop(ClientId client) {
  std::uint64_t seq = 0;
  switch (stage_.stop_pose(client, seq)) {
    case TwinStage::Refusal::kNone:
      stop_sent_ = seq;
      after_stop_ = true;
      unsent_stop_ = 0;
      return true;
    case TwinStage::Refusal::kBusy:
      after_stop_ = true;
      unsent_stop_ = client;
      return true;
    default:
      after_stop_ = false;
      unsent_stop_ = 0;
      return false;
  }
}

bool Gcs2HexapodTwin::settle_stop() {
  if (unsent_stop_ != 0) send_stop(unsent_stop_);  // a stop the full ring refused: again
  if (!after_stop_) return true;
  if (unsent_stop_ != 0) return false;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(params_.stop_wait_s);
  for (;;) {
    const live::PositionerView v = stage_.positioner_view();
    if (v.stop_seq >= stop_sent_) {
      target_ = last_goal_ = v.reference;
      after_stop_ = false;
      return true;
    }
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

PlatformTransform Gcs2HexapodTwin::plan_start(const live::PositionerView& v) const {
  return busy(v) ? last_goal_ : v.reference;
}

std::optional<motion::PoseTrajectory> Gcs2HexapodTwin::plan(const PlatformTransform& goal,
                                                            const live::PositionerView& v) const {
  // VLS is the tool point's speed. The angular rate slows with it below the library's speed but
  // never exceeds the library's rate: turning drives the legs faster than translating does.
  motion::PoseMoveLimits lim = stage_.positioner_limits();
  const double scale = velocity_mm_s_ * kM / lim.max_speed_m_s;
  lim.max_speed_m_s *= scale;
  lim.max_angular_speed_rad_s *= std::min(1.0, scale);
  // The goal's own check first: it bounds the path's length, and so check_move()'s samples.
  if (!motion::check_pose(kin_, goal).ok()) return std::nullopt;
  try {
    // A move whose legs would outrun their speed limit runs slower, as a hexapod controller keeps
    // every strut within its velocity: speeds scaled by the legs' margin (accelerations by its
    // square, which scales a short move's triangular peak alike), checked again.
    for (int attempt = 0; attempt < 4; ++attempt) {
      motion::PoseTrajectory traj(plan_start(v), goal, lim);
      const motion::MoveCheck c = motion::check_move(kin_, traj);
      if (c.ok) return traj;
      if (c.reach != motion::Reach::kReachable || !(c.peak_leg_speed_m_s > lim.max_leg_speed_m_s))
        return std::nullopt;  // a pose on the way is out of the workspace
      const double f = 0.95 * lim.max_leg_speed_m_s / c.peak_leg_speed_m_s;
      lim.max_speed_m_s *= f;
      lim.max_angular_speed_rad_s *= f;
      lim.max_acceleration_m_s2 *= f * f;
      lim.max_angular_acceleration_rad_s2 *= f * f;
    }
  } catch (const std::exception&) {
    // a pose that is not finite
  }
  return std::nullopt;
}

bool Gcs2HexapodTwin::send(ClientId client, const PlatformTransform& goal) {
  if (!settle_stop()) return error_ = g::kControllerBusy, false;
  const live::PositionerView v = refresh();
  if (v.halted) return error_ = g::kStopped, false;
  const auto traj = plan(goal, v);
  if (!traj) return error_ = g::kPositionOutOfLimits, false;  // refused: nothing moves
  std::uint64_t seq = 0;
  std::string reason;
  switch (stage_.move_pose(client, *traj, seq, reason)) {
    case TwinStage::Refusal::kNone:
      break;
    case TwinStage::Refusal::kUnreachable:
      return error_ = g::kPositionOutOfLimits, false;
    case TwinStage::Refusal::kBusy:
      return error_ = g::kControllerBusy, false;
    case TwinStage::Refusal::kHalted:
    case TwinStage::Refusal::kOtherOperator:
      return error_ = g::kStopped, false;  // as the GCS 2.0 twin: the platform is not this client's
  }
  last_move_ = seq;
  last_goal_ = target_ = goal;
  mover_ = client;
  return true;
}

void Gcs2HexapodTwin::stop_all(ClientId client) {
  referencing_ = 0;
  mover_ = 0;
  if (send_stop(client)) return;
  // Nothing sent: another operator holds the platform (which holds the positioner) or it is halted.
  const live::PositionerView v = refresh();
  if (!busy(v) && !halted_) target_ = last_goal_ = v.reference;
}

void Gcs2HexapodTwin::on_disconnect(ClientId client) {
  if (client != 0 && client == mover_ && busy(refresh())) stop_all(client);
  stage_.release(client);
}

std::string Gcs2HexapodTwin::on_byte(ClientId client, char byte) {
  const live::PositionerView v = refresh();
  if (byte == g::kMotionStatus) return fmt::format("{:X}\n", busy(v) ? 0x3Fu : 0u);
  if (byte == g::kReadyStatus)
    return std::string(1, static_cast<char>(referencing_ ? g::kBusy : g::kReady)) + "\n";
  if (byte == g::kStopAll) {
    stop_all(client);
    error_ = g::kStopped;
  }
  return "";
}

std::string Gcs2HexapodTwin::on_line(ClientId client, std::string_view line) {
  const auto r = g::parse_line(line);
  if (!r) return "";
  if (r->target_address != 0 && r->target_address != params_.address) return "";  // another controller's
  Lines reply;
  if (!execute(client, *r, reply) || reply.empty()) return "";
  return g::format_reply(reply, r->target_address);
}

bool Gcs2HexapodTwin::execute(ClientId client, const g::Request& r, Lines& reply) {
  const std::string& m = r.mnemonic;
  if (m == "MOV" || m == "MVR" || m == "FRF") return move(client, r);
  if (m == "KSD" || m == "KEN" || m == "KEN?") return coordinate_system(r, reply);
  if (m == "STP" || m == "HLT") {
    if (m == "HLT") {
      const auto q = g::parse_hexapod_query(r.args);
      if (q.error) return error_ = q.error, false;
    }
    stop_all(client);  // the six axes move as one: halting one halts them all
    error_ = g::kStopped;
    return true;
  }
  if (m == "SVO") {
    const auto pv = g::parse_hexapod_values(r.args);
    if (pv.error) return error_ = pv.error, false;
    for (const auto& v : pv.values)
      if (v && *v != 1.0) return error_ = g::kParameterOutOfRange, false;  // a hexapod's servo stays on
    return true;
  }
  if (m == "VLS") {
    const auto v = r.args.size() == 1 ? g::parse_number(r.args[0]) : std::nullopt;
    if (!v) return error_ = g::kParameterSyntax, false;
    if (!(*v > 0.0 && *v <= params_.max_velocity_mm_s)) return error_ = g::kVelocityOutOfLimits, false;
    velocity_mm_s_ = *v;
    return true;
  }
  if (m == "SPI") {
    const auto pv = g::parse_pivot_values(r.args);
    if (pv.error) return error_ = pv.error, false;
    if (!settle_stop()) return error_ = g::kControllerBusy, false;
    // The pivot moves only while the platform is not turned (PI: U, V and W all 0).
    if (motion::pi_angles(target_.R).cwiseAbs().maxCoeff() > 1e-9)
      return error_ = g::kSetPivotNotPossible, false;
    for (std::size_t i = 0; i < 3; ++i)
      if (pv.values[i]) pivot_m_(static_cast<Eigen::Index>(i)) = *pv.values[i] * kM;
    return true;
  }
  return query(r, reply);
}

bool Gcs2HexapodTwin::move(ClientId client, const g::Request& r) {
  if (r.mnemonic == "FRF") {
    const auto q = g::parse_hexapod_query(r.args);
    if (q.error) return error_ = q.error, false;
    // The reference move: the whole platform to its home pose (whatever axes are named).
    if (!send(client, PlatformTransform{})) return false;
    referencing_ = last_move_;
    referenced_ = false;
    return true;
  }
  const auto pv = g::parse_hexapod_values(r.args);
  if (pv.error) return error_ = pv.error, false;
  refresh();
  if (!referenced_ || referencing_) return error_ = g::kUnallowableMove, false;
  if (!settle_stop()) return error_ = g::kControllerBusy, false;
  // Axes not named keep their target; MVR adds to the target (PI: "relative to current target").
  Pose6 p = to_protocol(target_);
  for (std::size_t i = 0; i < 6; ++i)
    if (pv.values[i]) p[i] = r.mnemonic == "MOV" ? *pv.values[i] : p[i] + *pv.values[i];
  return send(client, from_protocol(p));
}

bool Gcs2HexapodTwin::coordinate_system(const g::Request& r, Lines& reply) {
  const std::string& m = r.mnemonic;
  if (m == "KEN?") {
    if (!r.args.empty()) return error_ = g::kParameterSyntax, false;
    reply.push_back(enabled_ == g::kZeroCs ? "ZERO=ZERO" : enabled_ + "=KSD");
    return true;
  }
  if (r.args.empty()) return error_ = g::kParameterSyntax, false;
  const auto name = g::parse_cs_name(r.args[0]);
  if (!name) return error_ = g::kCsNameInvalid, false;
  if (m == "KEN") {
    if (r.args.size() != 1) return error_ = g::kParameterSyntax, false;
    if (*name != g::kZeroCs && !systems_.contains(*name)) return error_ = g::kCsDoesNotExist, false;
    enabled_ = *name;  // the target stays where it is; it reads in the new system
    return true;
  }
  // KSD <name> {<axis> <value>}: a system whose frame is the offsets' pose from home.
  if (*name == g::kZeroCs) return error_ = g::kCsNameInvalid, false;
  const auto pv = g::parse_hexapod_values(std::vector<std::string>(r.args.begin() + 1, r.args.end()));
  if (pv.error) return error_ = pv.error, false;
  if (busy(refresh())) return error_ = g::kCsWhileMoving, false;
  if (*name == enabled_) return error_ = g::kCsInUse, false;
  if (!systems_.contains(*name) && systems_.size() >= kMaxSystems)
    return error_ = g::kParameterOutOfRange, false;
  motion::PiPose& o = systems_[*name];
  const double scale[6] = {kM, kM, kM, kRad, kRad, kRad};
  double* fields[6] = {&o.X, &o.Y, &o.Z, &o.U, &o.V, &o.W};
  for (std::size_t i = 0; i < 6; ++i)
    if (pv.values[i]) *fields[i] = *pv.values[i] * scale[i];
  return true;
}

bool Gcs2HexapodTwin::query(const g::Request& r, Lines& reply) {
  const std::string& m = r.mnemonic;
  const live::PositionerView v = refresh();
  auto per_axis = [&](auto&& value_of) {
    const auto q = g::parse_hexapod_query(r.args);
    if (q.error) return error_ = q.error, false;
    for (int i : q.axes) reply.push_back(value_of(i));
    return true;
  };
  auto name = [](int i) { return g::kHexapodAxes[static_cast<std::size_t>(i)]; };
  if (m == "*IDN?") {
    reply.push_back(params_.idn);
  } else if (m == "CSV?") {
    reply.push_back("2.0");
  } else if (m == "HLP?") {
    for (const char* h : {"The following commands are valid:",
                          "*IDN? Get Device Identification",
                          "CSV? Get Current Syntax Version",
                          "ERR? Get Error Number",
                          "FRF [{<AxisID>}] Fast Reference Move To Reference Switch",
                          "FRF? [{<AxisID>}] Get Referencing Result",
                          "HLP? Get List Of Available Commands",
                          "HLT [{<AxisID>}] Halt Motion Smoothly",
                          "KEN <CoordSys> Enable Coordinate System",
                          "KEN? Get Enabled Coordinate System",
                          "KSD <CoordSys> {<AxisID> <Position>} Define KSD Coordinate System",
                          "MOV {<AxisID> <Position>} Set Target Position",
                          "MOV? [{<AxisID>}] Get Target Position",
                          "MVR {<AxisID> <Distance>} Set Target Relative To Current Target",
                          "ONT? [{<AxisID>}] Get On Target State",
                          "POS? [{<AxisID>}] Get Real Position",
                          "SAI? [ALL] Get List Of Current Axis Identifiers",
                          "SPI {<PivotAxis> <Position>} Set Pivot Point",
                          "SPI? [{<PivotAxis>}] Get Pivot Point",
                          "STP Stop All Axes",
                          "SVO {<AxisID> <ServoState>} Set Servo Mode",
                          "SVO? [{<AxisID>}] Get Servo Mode",
                          "TMN? [{<AxisID>}] Get Minimum Commandable Position",
                          "TMX? [{<AxisID>}] Get Maximum Commandable Position",
                          "VLS <Velocity> Set System Velocity",
                          "VLS? Get System Velocity",
                          "VMO? {<AxisID> <Position>} Virtual Move",
                          "#5 Request Motion Status",
                          "#7 Request Controller Ready Status",
                          "#24 Stop All Axes",
                          "end of help"})
      reply.emplace_back(h);
  } else if (m == "SAI?") {
    if (!r.args.empty() && !(r.args.size() == 1 && (r.args[0] == "ALL" || r.args[0] == "all")))
      return error_ = g::kParameterSyntax, false;
    for (const char* a : g::kHexapodAxes) reply.emplace_back(a);
  } else if (m == "ERR?") {
    reply.push_back(std::to_string(error_));
    error_ = g::kNoError;
  } else if (m == "POS?") {
    const Pose6 p = to_protocol(v.measured);
    return per_axis([&](int i) { return g::axis_value(name(i), p[static_cast<std::size_t>(i)]); });
  } else if (m == "MOV?") {
    if (!settle_stop()) return error_ = g::kControllerBusy, false;
    const Pose6 p = to_protocol(target_);
    return per_axis([&](int i) { return g::axis_value(name(i), p[static_cast<std::size_t>(i)]); });
  } else if (m == "ONT?") {
    const int on = on_target(v) ? 1 : 0;
    return per_axis([&](int i) { return g::axis_value(name(i), on); });
  } else if (m == "SVO?") {
    return per_axis([&](int i) { return g::axis_value(name(i), 1); });
  } else if (m == "FRF?") {
    return per_axis([&](int i) { return g::axis_value(name(i), referenced_ ? 1 : 0); });
  } else if (m == "TMN?") {
    return per_axis([&](int i) { return g::axis_value(name(i), tmn_[static_cast<std::size_t>(i)]); });
  } else if (m == "TMX?") {
    return per_axis([&](int i) { return g::axis_value(name(i), tmx_[static_cast<std::size_t>(i)]); });
  } else if (m == "VLS?") {
    if (!r.args.empty()) return error_ = g::kParameterSyntax, false;
    reply.push_back(fmt::format("{:.6f}", velocity_mm_s_));
  } else if (m == "SPI?") {
    const auto q = g::parse_pivot_query(r.args);
    if (q.error) return error_ = q.error, false;
    for (int i : q.axes)
      reply.push_back(g::axis_value(g::kPivotAxes[static_cast<std::size_t>(i)], pivot_m_(i) / kM));
  } else if (m == "VMO?") {
    // Would this pose be reached from where the next move starts? Nothing moves.
    const auto pv = g::parse_hexapod_values(r.args);
    if (pv.error) return error_ = pv.error, false;
    if (!settle_stop()) return error_ = g::kControllerBusy, false;
    Pose6 p = to_protocol(target_);
    for (std::size_t i = 0; i < 6; ++i)
      if (pv.values[i]) p[i] = *pv.values[i];
    reply.push_back(plan(from_protocol(p), refresh()) ? "1" : "0");
  } else {
    return error_ = g::kUnknownCommand, false;
  }
  return true;
}

}  // namespace mc::twins
