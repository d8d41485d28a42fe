#include "microcobot/perception/vision_grip_force.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "microcobot/core/error.h"
#include "microcobot/devices/grey_frame.h"
#include "microcobot/perception/camera_map.h"
#include "microcobot/perception/finger_templates.h"

namespace mc::perception {

void VisionGripForceParams::validate() const {
  try {
    tracker.validate();
  } catch (const InvalidParams& e) {
    throw e.nested_in("tracker");
  }
}

namespace {
// A part holds the fingers apart by more than this (and by more than kNoise_px): the next gap is
// predicted from the last, and a turn chains the gap rather than taring afresh.
constexpr double kLoadedGap = 1e-6;
// A frame's tips' distance is good to about a pixel (at 2x with the tips out of focus, 0.8 px rms):
// a gap this many pixels off the drive's opening is beyond a frame's noise.
constexpr double kNoise_px = 3.0;
// The fingers' yaw the tips are taught at holds within this: 1 mrad moves a tip 0.1 um across a
// 100 um gap (turned further, they are taught again).
constexpr double kMaxYaw_rad = 1e-3;
// The fingers turned less than this since the last frame are still (the rotary axis' sensor noise
// is 1 urad; its slowest console turn, 0.05 rad/s, is 1.7 mrad a frame at 30 frames/s).
constexpr double kStillYaw_rad = 0.1e-3;
// Frames the fingers must stay still before they are taught at a new yaw: a turn the console's
// commands pause for a moment (a busy page) is not taught halfway.
constexpr int kStillFrames = 3;
// A tare's reference is the mean tips' distance over this many frames (the drive still): the
// teaching frame's noise is in the templates; averaging the frames after it takes it out.
constexpr int kTareFrames = 15;
}  // namespace

VisionGripForce::VisionGripForce(const CameraRig& rig, const VisionGripForceParams& params)
    : rig_(rig),
      p_(params),
      stiffness_N_m_(rig.finger_stiffness_N_m),
      trackers_{vision::TemplateTracker(params.tracker), vision::TemplateTracker(params.tracker)} {
  p_.validate();
  rig_.camera.validate();
  still_frames_ = kStillFrames;  // nothing has turned yet
  require(std::isfinite(stiffness_N_m_) && stiffness_N_m_ > 0.0, "world.gripper.finger_stiffness_N_m",
          "must be > 0", stiffness_N_m_);
}

Eigen::Vector2d VisionGripForce::tip_step_px(int side, double gap_m) const {
  const double h = side * 0.5 * gap_m;
  return map_.pixel_step(Eigen::Vector2d(h * std::cos(yaw_), h * std::sin(yaw_)));
}

void VisionGripForce::set_directions(double yaw_rad) {
  yaw_ = yaw_rad;
  const Eigen::Vector2d ex = map_.pixel_step(Eigen::Vector2d(std::cos(yaw_rad), std::sin(yaw_rad)));
  scale_px_m_ = ex.norm();
  e_x_ = ex / scale_px_m_;
}

bool VisionGripForce::teach(const Eigen::Vector2d& tool_px, double gap_m, double free_opening_m,
                            double bend_m) {
  for (int k = 0; k < 2; ++k) {
    const int side = k == 0 ? -1 : 1;
    const imaging::PixelRoi roi =
        finger_tip_template(map_, tool_px, side, gap_m, rig_.finger_width_m, false, yaw_);
    try {
      trackers_[static_cast<std::size_t>(k)].set_template(frame_, roi);
    } catch (const Error& e) {
      st_.state = "error";
      st_.error = std::string("cannot see the gripper's ") + (k == 0 ? "left" : "right") +
                  " tip where expected: " + e.what();
      taught_ = false;
      return false;
    }
    const vision::TrackEstimate& t = trackers_[static_cast<std::size_t>(k)].last();
    offset_px_[static_cast<std::size_t>(k)] =
        Eigen::Vector2d(t.u_px, t.v_px) - tool_px - tip_step_px(side, gap_m);
  }
  const vision::TrackEstimate &l = trackers_[0].last(), &r = trackers_[1].last();
  ref_d_px_ = (Eigen::Vector2d(r.u_px, r.v_px) - Eigen::Vector2d(l.u_px, l.v_px)).dot(e_x_);
  ref_gap_m_ = last_gap_m_ = gap_m;
  // The offsets hold this frame's bend: the midpoint's offset from the tool point is 0 now.
  ref_bend_m_ = last_bend_m_ = bend_m;
  ref_c_px_ = 0.0;
  measured_free_opening_m_ = free_opening_m;
  // A tare (nothing held: the gap is the drive's opening) is refined over the next frames.
  tare_frames_ = gap_m == free_opening_m ? 1 : 0;
  tare_d_sum_px_ = ref_d_px_;
  tare_c_sum_px_ = 0.0;
  last_tool_px_ = tool_px;
  loaded_ = gap_m - free_opening_m > kLoadedGap;
  taught_ = true;
  return true;
}

const VisionGripStatus& VisionGripForce::on_frame(const devices::CameraFrame& frame, const ToolHint& hint) {
  if (!devices::to_grey_frame(frame.image, frame.sequence, frame_)) return st_;
  ++st_.frames;
  st_.t_mid_s = frame.t_mid_s;
  st_.grip_force_N = st_.gap_m = st_.contact_force_N = st_.bend_m = std::nan("");
  st_.confidence = 0.0;
  if (reset_.exchange(false, std::memory_order_acq_rel)) {
    taught_ = st_.tared = false;
    st_.state = "untared";
    st_.error.clear();
    auto_tare_ = p_.tare_at_start;
  }
  const double o = frame.gripper_free_opening_m;
  st_.free_opening_m = o;
  if (!std::isfinite(o)) {
    st_.state = "error";
    st_.error = "the gripper's drive has no model of its free opening: no force by vision";
    publish();
    return st_;
  }
  // The fingers' yaw (the rotary axis): turning, the tips' templates no longer match and the
  // gap's direction moves; still at a new yaw, they are taught again there.
  const double yaw = std::isfinite(frame.tool_yaw_rad) ? frame.tool_yaw_rad : 0.0;
  const bool moved = std::isfinite(last_frame_yaw_) && std::abs(yaw - last_frame_yaw_) > kStillYaw_rad;
  last_frame_yaw_ = yaw;
  still_frames_ = moved ? 0 : std::min(still_frames_ + 1, kStillFrames);
  const bool turned = std::abs(yaw - yaw_) > kMaxYaw_rad;
  // A frame taken while the fingers turn, even within kMaxYaw_rad of their taught yaw, measures
  // nothing: its blurred tips would enter a tare's average or mark the fingers loaded, and the
  // next teaching would then chain from that wrong gap.
  if (still_frames_ < kStillFrames) {
    st_.state = st_.tared ? "lost" : "untared";
    st_.error = "the fingers are turning: measured again once they stop";
    publish();
    return st_;
  }
  const bool new_view = frame.objective != objective_ || frame_.width != width_ || frame_.height != height_;
  if (new_view) {
    objective_ = frame.objective;
    width_ = frame_.width;
    height_ = frame_.height;
    map_ = camera_stage_map(rig_, objective_);
  }
  if (new_view || turned) set_directions(yaw);
  if (!hint.pixel && !hint.stage_sensed && !taught_) {
    st_.state = st_.tared ? "lost" : "untared";
    st_.error = "waiting for the vision positioner to see the tool";
    publish();
    return st_;
  }
  const Eigen::Vector2d tool = hint.pixel ? *hint.pixel
                               : hint.stage_sensed
                                   ? map_.pixel_of(Eigen::Vector2d(frame.tool_m[0] - rig_.stage_home_m.x(),
                                                                   frame.tool_m[1] - rig_.stage_home_m.y()))
                                   : last_tool_px_;
  if (tare_.exchange(false, std::memory_order_acq_rel) || auto_tare_) {
    // Nothing between the fingers: the gap is the drive's free opening. The scene's own tare is
    // tried at each frame until the tips are in view.
    if (teach(tool, o, o, 0.0)) {
      auto_tare_ = false;
      st_.tared = true;
      ++st_.tares;
      st_.state = "measuring";
      st_.error.clear();
    }
    st_.gap_m = taught_ ? o : st_.gap_m;
    st_.grip_force_N = taught_ ? 0.0 : st_.grip_force_N;
    if (taught_ && hint.stage_sensed && !hint.pixel) st_.contact_force_N = st_.bend_m = 0.0;
    st_.confidence = taught_ ? 1.0 : 0.0;
    publish();
    return st_;
  }
  if (!st_.tared) {
    publish();
    return st_;
  }
  if (new_view || turned || !taught_) {
    // Another objective or another yaw: the tips look different. Taught again where they are, the
    // gap carried over from the last one measured (the reference chains; a part may be held) ...
    if (turned && std::abs(o - measured_free_opening_m_) > kLoadedGap) {
      // ... unless the drive moved while the fingers turned: the gap now is unknown.
      taught_ = st_.tared = false;
      st_.state = "untared";
      st_.error = "the gripper moved while the fingers turned: tare again with nothing between them";
      publish();
      return st_;
    }
    // Nothing held before the turn (and the drive still): nothing is now, the gap is the drive's
    // opening, a fresh tare rather than a chained one (whose error would add up turn after turn).
    const bool fresh = turned && !loaded_;  // nothing held: nothing presses on the fingers either
    if (teach(tool, fresh ? o : last_gap_m_, o, fresh ? 0.0 : last_bend_m_)) {
      st_.state = "measuring";
      st_.error.clear();
    }
    publish();
    return st_;
  }

  // The gap lies between the drive's opening and the last gap while they close (a part may stop
  // the fingers anywhere between), at the drive's opening while they open, and no lower than it.
  const double predicted_gap = loaded_ ? std::max(o, last_gap_m_) : o;
  const double closing_from = std::max(predicted_gap, last_gap_m_);
  // The tips are looked for bent as much as last seen (their bend since the offsets were taught).
  const Eigen::Vector2d bent = tool + (last_bend_m_ - ref_bend_m_) * scale_px_m_ * e_x_;
  std::array<Eigen::Vector2d, 2> p;
  double confidence = 1.0;
  for (int k = 0; k < 2; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const int side = k == 0 ? -1 : 1;
    const Eigen::Vector2d at = bent + tip_step_px(side, predicted_gap) + offset_px_[i];
    const Eigen::Vector2d from = bent + tip_step_px(side, closing_from) + offset_px_[i];
    const vision::TrackEstimate e = trackers_[i].track_along(frame_, at.x(), at.y(), from.x(), from.y());
    if (!e.found) {
      st_.state = "lost";
      st_.error = std::string("the ") + (k == 0 ? "left" : "right") + " tip is not found";
      publish();
      return st_;
    }
    p[i] = {e.u_px, e.v_px};
    confidence = std::min(confidence, e.confidence);
  }
  // Two matches that are not the two tips: the right one on the left, or rows apart.
  const Eigen::Vector2d d = p[1] - p[0] - (offset_px_[1] - offset_px_[0]);
  const double along = d.dot(e_x_), across = std::abs(d.x() * e_x_.y() - d.y() * e_x_.x());
  if (along <= 0.0 || across > p_.tracker.search_margin_px) {
    st_.state = "lost";
    st_.error = "the two matches are not the gripper's two tips";
    publish();
    return st_;
  }
  const double d_px = (p[1] - p[0]).dot(e_x_);
  // The common mode: the tips' midpoint against the tool point (where the stage puts the fingers),
  // known only from the stage's sensors.
  const bool stage_known = hint.stage_sensed && !hint.pixel;
  const double c_px = (0.5 * (p[0] - offset_px_[0] + p[1] - offset_px_[1]) - tool).dot(e_x_);
  // Still the tare's scene (the drive unmoved; nothing between the fingers, by the tare's
  // definition, whatever a noisy frame says): its references averaged.
  const bool taring = tare_frames_ > 0 && tare_frames_ < kTareFrames && o == measured_free_opening_m_;
  if (taring) {
    tare_d_sum_px_ += d_px;
    tare_c_sum_px_ += c_px;
    ++tare_frames_;
    ref_d_px_ = tare_d_sum_px_ / tare_frames_;
    ref_c_px_ = tare_c_sum_px_ / tare_frames_;
  } else {
    tare_frames_ = 0;
  }
  const double gap = ref_gap_m_ + (d_px - ref_d_px_) / scale_px_m_;
  const double beyond_noise_m = std::max(kLoadedGap, kNoise_px / scale_px_m_);
  if (gap < o - beyond_noise_m) {
    // Closer than the drive puts them: nothing pushes fingers inward; these are not the tips.
    st_.state = "lost";
    st_.error = "the tips seen closer than the drive puts them";
    publish();
    return st_;
  }
  last_gap_m_ = gap;
  measured_free_opening_m_ = o;
  last_tool_px_ =
      0.5 * (p[0] - offset_px_[0] - tip_step_px(-1, gap) + p[1] - offset_px_[1] - tip_step_px(1, gap));
  loaded_ = !taring && gap - o > beyond_noise_m;
  st_.state = "measuring";
  st_.error.clear();
  st_.gap_m = gap;
  st_.confidence = confidence;
  st_.grip_force_N = 0.5 * stiffness_N_m_ * (gap - o);  // F = k (w - o) / 2, piezo_gripper.h
  if (stage_known) {
    last_bend_m_ = ref_bend_m_ + (c_px - ref_c_px_) / scale_px_m_;
    st_.bend_m = last_bend_m_;
    st_.contact_force_N = 2.0 * stiffness_N_m_ * last_bend_m_;  // F_c = 2 k b, pick_place_world.h
  }
  publish();
  return st_;
}

VisionGripStatus VisionGripForce::status() const {
  std::lock_guard lock(status_mutex_);
  return published_;
}

void VisionGripForce::publish() {
  std::lock_guard lock(status_mutex_);
  published_ = st_;
}

}  // namespace mc::perception
