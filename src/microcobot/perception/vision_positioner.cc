#include "microcobot/perception/vision_positioner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/devices/grey_frame.h"
#include "microcobot/perception/camera_map.h"
#include "microcobot/perception/finger_templates.h"

namespace mc::perception {

void VisionPositionerParams::validate() const {
  servo.validate();  // names its fields servo.*
  try {
    tracker.validate();
  } catch (const InvalidParams& e) {
    throw e.nested_in("tracker");  // the tracker's fields under their key here
  }
  require(std::isfinite(margin_s) && margin_s >= 0.0 && margin_s < 0.1, "margin_s",
          "must be within [0, 0.1) s", margin_s);
  require(std::isfinite(min_run_s) && min_run_s > 0.0 && min_run_s < 1.0, "min_run_s",
          "must be within (0, 1) s", min_run_s);
  require(settle_frames >= 0 && settle_frames <= 100, "settle_frames", "must be within [0, 100]",
          settle_frames);
  require(std::isfinite(in_position_m) && in_position_m > 0.0 && in_position_m <= servo.converged_m,
          "in_position_m", "must be within (0, servo.converged_m]", in_position_m);
  require(max_hunt_frames > settle_frames && max_hunt_frames <= 1000, "max_hunt_frames",
          "must be within (settle_frames, 1000]", max_hunt_frames);
}

VisionPositioner::VisionPositioner(const CameraRig& rig, const VisionPositionerParams& params)
    : rig_(rig),
      p_(params),
      home_xy_m_(rig.stage_home_m),
      trackers_{vision::TemplateTracker(params.tracker), vision::TemplateTracker(params.tracker)} {
  p_.validate();
  rig_.camera.validate();
}

vision::AffineMap VisionPositioner::map_for(int objective, bool* calibrated) const {
  return camera_stage_map(rig_, objective, calibrated);
}

void VisionPositioner::request_goal_world(double x_m, double y_m) noexcept {
  if (goal_kind_.load(std::memory_order_relaxed) == 1 && goal_a_.load(std::memory_order_relaxed) == x_m &&
      goal_b_.load(std::memory_order_relaxed) == y_m)
    return;  // the same goal, asked again at every tick
  goal_a_.store(x_m, std::memory_order_relaxed);
  goal_b_.store(y_m, std::memory_order_relaxed);
  goal_kind_.store(1, std::memory_order_relaxed);
  goal_seq_.fetch_add(1, std::memory_order_release);
}

void VisionPositioner::request_goal_pixel(double u_px, double v_px) noexcept {
  if (goal_kind_.load(std::memory_order_relaxed) == 2 && goal_a_.load(std::memory_order_relaxed) == u_px &&
      goal_b_.load(std::memory_order_relaxed) == v_px)
    return;
  goal_a_.store(u_px, std::memory_order_relaxed);
  goal_b_.store(v_px, std::memory_order_relaxed);
  goal_kind_.store(2, std::memory_order_relaxed);
  goal_seq_.fetch_add(1, std::memory_order_release);
}

void VisionPositioner::clear_goal() noexcept {
  if (goal_kind_.load(std::memory_order_relaxed) == 0) return;
  goal_kind_.store(0, std::memory_order_relaxed);
  goal_seq_.fetch_add(1, std::memory_order_release);
}

void VisionPositioner::switch_objective(int objective, int width_px, int height_px) {
  objective_ = objective;
  width_ = width_px;
  height_ = height_px;
  map_ = map_for(objective, &calibrated_);
  servo_.emplace(p_.servo, map_, width_px, height_px);
  taught_ = false;  // the tips look different through another objective: taught again
  moved_px_.setZero();
  if (goal_kind_.load(std::memory_order_relaxed) == 2) clear_goal();  // a pixel means another point now
  taken_goal_seq_ = ~std::uint64_t{0};                                // a world goal is mapped again
}

void VisionPositioner::take_goal(PositionerStatus& st) {
  const std::uint64_t seq = goal_seq_.load(std::memory_order_acquire);
  if (seq == taken_goal_seq_) return;
  const int kind = goal_kind_.load(std::memory_order_relaxed);
  const double a = goal_a_.load(std::memory_order_relaxed), b = goal_b_.load(std::memory_order_relaxed);
  if (goal_seq_.load(std::memory_order_acquire) != seq) return;  // being written: the next frame takes it
  taken_goal_seq_ = seq;
  has_goal_ = false;
  st.error.clear();
  if (kind == 0) return;
  const Eigen::Vector2d goal_px =
      kind == 1 ? map_.pixel_of(Eigen::Vector2d(a, b) - home_xy_m_) : Eigen::Vector2d(a, b);
  const Eigen::Vector2d target = goal_px;
  try {
    servo_->set_target(target.x(), target.y());
  } catch (const Error&) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "goal (%.1f, %.1f) px is outside the %d x %d image: not moving",
                  goal_px.x(), goal_px.y(), width_, height_);
    st.error = buf;
    return;
  }
  has_goal_ = true;
  converged_frames_ = hunt_frames_ = 0;
  in_position_ = false;
  st.goal_u_px = goal_px.x();
  st.goal_v_px = goal_px.y();
}

std::optional<PositionerCommand> VisionPositioner::on_frame(const devices::CameraFrame& frame, double t_mid_s,
                                                            const std::function<double()>& now) {
  if (!devices::to_grey_frame(frame.image, frame.sequence, frame_)) return std::nullopt;
  ++frames_;
  if (reset_.exchange(false, std::memory_order_acquire)) {
    objective_ = -1;  // taught again, from the home
    stage_m_.setZero();
    run_end_s_ = -1e9;
  }
  PositionerStatus st = status();
  st.frames = frames_;
  if (frame.objective != objective_ || frame_.width != width_ || frame_.height != height_)
    switch_objective(frame.objective, frame_.width, frame_.height);
  st.m_per_px = map_m_per_px(map_);
  st.calibrated = calibrated_;
  // The fingers' yaw (the rotary axis turns them about the tool point): while they turn the tips
  // move about the tool point and would read as the stage's motion, so the stage holds; still
  // for kPositionerStillFrames frames at a new yaw, the tips are taught again there (the tool point, on the
  // axis, has not moved) and tracked turned.
  constexpr double kTurned_rad = 1e-3;              // 1 mrad moves a tip 0.1 um across a 200 um opening
  constexpr double kPositionerStillYaw_rad = 1e-4;  // a frame's change of yaw that counts as turning
  constexpr int kPositionerStillFrames = 3;
  const double yaw = std::isfinite(frame.tool_yaw_rad) ? frame.tool_yaw_rad : 0.0;
  still_frames_ = std::isfinite(last_frame_yaw_) && std::abs(yaw - last_frame_yaw_) <= kPositionerStillYaw_rad
                      ? still_frames_ + 1
                      : 0;
  last_frame_yaw_ = yaw;
  if (std::abs(yaw - taught_yaw_) > kTurned_rad) {
    if (still_frames_ < kPositionerStillFrames) {
      st.found = false;
      st.state = "hold (fingers turning)";
      servo_->clear_history();
      converged_frames_ = hunt_frames_ = 0;
      in_position_ = st.in_position = false;
      moved_px_.setZero();
      publish(st);
      return std::nullopt;
    }
    taught_yaw_ = yaw;
    taught_ = false;  // taught again below, where the tool point is
  }

  // Where the tool is: taught where it is expected, then tracked near where the commands put it.
  bool found = false;
  double confidence = 0.0;
  if (!taught_) {
    if (!teach(map_.pixel_of(stage_m_), frame.gripper_opening_m, st)) {
      st.in_position = false;  // not tracked
      publish(st);
      return std::nullopt;
    }
    found = true;
    confidence = 1.0;
  } else {
    const Eigen::Vector2d predicted_tool = tool_px_ + moved_px_;
    std::array<Eigen::Vector2d, 2> tool_k;
    std::array<double, 2> rho{-2.0, -2.0};  // the agreeing tips' correlations (-2: left out)
    for (std::size_t k = 0; k < 2; ++k) {
      if (!tip_taught_[k]) continue;
      const Eigen::Vector2d tip_step = tip_step_px(k, frame.gripper_opening_m);
      const Eigen::Vector2d predicted = predicted_tool + tip_step + tip_offset_px_[k];
      // A tip the commands took out of the image is left out, not searched for over the whole
      // frame (tens of milliseconds on the camera thread, every frame, for nothing).
      if (!trackers_[k].fits(predicted.x(), predicted.y(), width_, height_)) continue;
      const vision::TrackEstimate e = trackers_[k].track_near(frame_, predicted.x(), predicted.y());
      tool_k[k] = Eigen::Vector2d(e.u_px, e.v_px) - tip_offset_px_[k] - tip_step;
      if (e.found && (tool_k[k] - predicted_tool).norm() <= p_.tracker.search_margin_px)
        rho[k] = e.confidence;
    }
    found = rho[0] > -2.0 || rho[1] > -2.0;
    if (found) {
      // Both seen: their mean, unless they disagree by more than kTipsDisagree_px; then one of
      // them holds something that does not move with the tip (a part's edge under its template,
      // which lowers its match): the better-matching tip alone.
      constexpr double kTipsDisagree_px = 1.0;
      const bool both = rho[0] > -2.0 && rho[1] > -2.0;
      const std::size_t best = rho[0] >= rho[1] ? 0 : 1;
      tool_px_ = both && (tool_k[0] - tool_k[1]).norm() <= kTipsDisagree_px ? 0.5 * (tool_k[0] + tool_k[1])
                                                                            : tool_k[best];
      confidence = both ? std::min(rho[0], rho[1]) : rho[best];
      // A tip not yet taught (out of the image when the others were): taught where the tool is.
      std::string unused;
      for (std::size_t k = 0; k < 2; ++k)
        if (!tip_taught_[k]) teach_tip(k, tool_px_, frame.gripper_opening_m, unused);
    }
    // Both lost for a second: taught again where the tool was last seen.
    lost_frames_ = found ? 0 : lost_frames_ + 1;
    if (lost_frames_ > rig_.camera.frame_rate_Hz()) taught_ = false;
  }
  moved_px_.setZero();
  if (found) stage_m_ = map_.stage_of(tool_px_);
  st.taught = true;
  st.found = found;
  st.confidence = confidence;
  st.tool_u_px = tool_px_.x();
  st.tool_v_px = tool_px_.y();
  st.stage_x_m = stage_m_.x();
  st.stage_y_m = stage_m_.y();

  take_goal(st);
  st.has_goal = has_goal_;
  std::optional<PositionerCommand> out;
  const double frame_start_s = t_mid_s - 0.5 * frame.exposure_s;
  if (!has_goal_) {
    st.state = "no-goal";
  } else if (!enabled_.load(std::memory_order_relaxed)) {
    st.state = "no-deadman";
    servo_->clear_history();  // nothing it asked is moving the stage
    converged_frames_ = hunt_frames_ = 0;
    in_position_ = false;
  } else if (frame_start_s < run_end_s_) {
    // Exposed while the last run may still play: the slider is anywhere within a period's stroke.
  } else {
    // The run ends before the first exposure that starts late enough to leave it min_run_s.
    const double t_now_s = now();
    const double T = 1.0 / rig_.camera.frame_rate_Hz();
    double next_start = frame_start_s + T;
    while (next_start - t_now_s - p_.margin_s < p_.min_run_s) next_start += T;
    const double hold = next_start - t_now_s - p_.margin_s;
    vision::ServoFeature f;
    f.u_px = tool_px_.x();
    f.v_px = tool_px_.y();
    f.found = found;
    f.t_mid_exposure_s = t_mid_s;
    const vision::ServoCommand c = servo_->step(f, t_now_s, hold);
    st.state = vision::to_string(c.status);
    st.error_m = c.error_m.norm();
    // In position: after settle_frames frames in a row within in_position_m the stage is left at
    // rest until the error leaves the converged window (hysteresis). A stick-slip axis' finest steps are its
    // least reliable (near the break-away amplitude the step map's step may be off several times): chasing
    // the last tens of nanometres made it jump by up to half a micrometre.
    const bool within = c.status == vision::ServoStatus::kConverged;
    const bool tight = within && st.error_m <= p_.in_position_m;
    converged_frames_ = tight ? converged_frames_ + 1 : 0;
    hunt_frames_ = within ? hunt_frames_ + 1 : 0;
    if (converged_frames_ > p_.settle_frames || hunt_frames_ > p_.max_hunt_frames) in_position_ = true;
    if (!within) in_position_ = false;
    if (in_position_) {
      servo_->clear_history();  // nothing of what it just asked is played
    } else if (c.velocity_m_s.squaredNorm() > 0.0) {
      out = PositionerCommand{c.velocity_m_s, hold, t_now_s};
      run_end_s_ = t_now_s + hold + p_.margin_s;
      moved_px_ = map_.pixel_step(c.velocity_m_s * hold);
      ++commands_;
    }
  }
  st.commands = commands_;
  st.in_position = in_position_;
  publish(st);
  return out;
}

Eigen::Vector2d VisionPositioner::tip_step_px(std::size_t k, double opening_m) const {
  // Tip k lies -+ opening / 2 from the tool point along the fingers' x, turned by their yaw.
  const double h = (k == 0 ? -0.5 : 0.5) * opening_m;
  return map_.pixel_step(Eigen::Vector2d(h * std::cos(taught_yaw_), h * std::sin(taught_yaw_)));
}

bool VisionPositioner::teach_tip(std::size_t k, const Eigen::Vector2d& tool_px, double opening_m,
                                 std::string& why) {
  const auto inside = [&](const imaging::PixelRoi& r) {
    return r.x >= 0 && r.y >= 0 && r.x + r.width <= width_ && r.y + r.height <= height_;
  };
  const int side = k == 0 ? -1 : 1;
  const double w = rig_.finger_width_m;
  imaging::PixelRoi roi = finger_tip_template(map_, tool_px, side, opening_m, w, false, taught_yaw_);
  // The finger's outer side out of the image (a wide-open gripper under a small field): its
  // inner half, until the tips are taught again.
  if (!inside(roi)) roi = finger_tip_template(map_, tool_px, side, opening_m, w, /*inner=*/true, taught_yaw_);
  const char* name = k == 0 ? "left" : "right";
  if (!inside(roi)) {
    why = std::string("the ") + name + " tip's template is not inside the image";
    return false;
  }
  try {
    trackers_[k].set_template(frame_, roi);
  } catch (const Error& e) {
    why = std::string("cannot see the gripper's ") + name + " tip where expected: " + e.what();
    return false;
  }
  const Eigen::Vector2d tip = tool_px + tip_step_px(k, opening_m);
  tip_offset_px_[k] = Eigen::Vector2d(trackers_[k].last().u_px, trackers_[k].last().v_px) - tip;
  tip_taught_[k] = true;
  return true;
}

bool VisionPositioner::teach(const Eigen::Vector2d& tool_px, double opening_m, PositionerStatus& st) {
  // Each tip whose template lies inside the image (a wide-open gripper under a small field may
  // show one); the other is taught once it comes into view.
  std::string why[2];
  for (std::size_t k = 0; k < 2; ++k) {
    tip_taught_[k] = false;
    teach_tip(k, tool_px, opening_m, why[k]);
  }
  if (!tip_taught_[0] && !tip_taught_[1]) {
    st.taught = st.found = false;
    st.state = "error";
    st.error = why[0] + "; " + why[1];
    return false;
  }
  taught_ = true;
  lost_frames_ = 0;
  tool_px_ = tool_px;
  taken_goal_seq_ = ~std::uint64_t{0};  // a goal asked before is taken again
  st.error.clear();
  return true;
}

PositionerStatus VisionPositioner::status() const {
  std::lock_guard lock(status_mutex_);
  return status_;
}

void VisionPositioner::publish(const PositionerStatus& st) {
  std::lock_guard lock(status_mutex_);
  status_ = st;
}

}  // namespace mc::perception
