#pragma once
/// @file
/// Where a force-guarded insertion aims and how it searches (assembly_task.h, "insert"): the
/// descent's point is the bore's axis, moved by the visual servo's aim and by an offset along the
/// fingers' y, the one direction the pin's place in the fingers is unknown in. A descent that meets
/// the rim retreats, shifts to the next point of the search (0, +s, -s, +2s, -2s, ... about its
/// centre) and descends again, until a fit or beyond the search's range. The task moves the tool;
/// this object keeps the search's phase and points. Never allocates; noexcept.

#include <cmath>
#include <limits>

#include <Eigen/Dense>

namespace mc::cell {

class InsertionSearch {
 public:
  /// Down towards the bore's floor, up clear of the rim, across to the next point.
  enum class Phase { kDescend, kRetreat, kShift };

  /// A fresh insertion, searching along the fingers' y at the yaw `fingers_yaw_rad`.
  void restart(double fingers_yaw_rad) noexcept;

  /// The point the descent aims at, for the bore's axis at `bore_m`.
  Eigen::Vector2d point(const Eigen::Vector2d& bore_m) const noexcept {
    return bore_m + aim_m_ + offset_y_ * along_fingers();
  }
  /// The fingers' y as the insertion began (the search's direction).
  Eigen::Vector2d along_fingers() const noexcept {
    return {-std::sin(search_yaw_rad_), std::cos(search_yaw_rad_)};
  }

  /// The held pin seen `offset_m` along the fingers' y from the tool point: the search centres
  /// on the pin, not on the tool point.
  void centre_on_held(double offset_m) noexcept;
  double held_offset_m() const noexcept { return held_offset_m_; }
  /// The visual servo's correction, added to the aim.
  void shift_aim(const Eigen::Vector2d& d_m) noexcept { aim_m_ += d_m; }
  const Eigen::Vector2d& aim_m() const noexcept { return aim_m_; }

  /// The descent met the rim: the next point of the search, `step_m` apart; false when it lies
  /// beyond `range_m` of the centre (jammed).
  bool next_point(double step_m, double range_m) noexcept;
  /// A rim contact the operator met: counted, the robot's search goes on from the same point.
  void count_try() noexcept { ++tries_; }
  int tries() const noexcept { return tries_; }

  /// Up to `z_m` from `xy_m` (where the descent stopped) before shifting.
  void retreat_from(const Eigen::Vector2d& xy_m, double z_m) noexcept;
  /// Up from wherever the tip is at the next tick (the operator handed back, or met the rim).
  void retreat_from_tip() noexcept;
  bool retreat_known() const noexcept { return std::isfinite(retreat_z_m_); }
  const Eigen::Vector2d& retreat_xy_m() const noexcept { return retreat_xy_m_; }
  double retreat_z_m() const noexcept { return retreat_z_m_; }

  Phase phase() const noexcept { return phase_; }
  void set_phase(Phase p) noexcept { phase_ = p; }
  /// The tip's height where the last descent met its stop (NaN before).
  void record_contact(double z_m) noexcept { contact_z_m_ = z_m; }
  double contact_z_m() const noexcept { return contact_z_m_; }

 private:
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  Phase phase_ = Phase::kDescend;
  int tries_ = 0;                // search points tried
  double offset_y_ = 0.0;        // the current point along the fingers' y
  double search_base_ = 0.0;     // the search's centre along the fingers' y
  double search_yaw_rad_ = 0.0;  // the fingers' yaw as the insertion began
  double held_offset_m_ = kNaN;  // the held pin along the fingers' y, as seen
  Eigen::Vector2d aim_m_{0, 0};  // the servo's correction of the aim
  Eigen::Vector2d retreat_xy_m_{0, 0};
  double retreat_z_m_ = 0.0;  // NaN: from where the tip is
  double contact_z_m_ = kNaN;
};

}  // namespace mc::cell
