#include "microcobot/cell/insertion_search.h"

namespace mc::cell {

void InsertionSearch::restart(double fingers_yaw_rad) noexcept {
  phase_ = Phase::kDescend;
  tries_ = 0;
  offset_y_ = search_base_ = 0.0;
  aim_m_.setZero();
  search_yaw_rad_ = fingers_yaw_rad;
}

void InsertionSearch::centre_on_held(double offset_m) noexcept {
  held_offset_m_ = offset_m;
  search_base_ = offset_y_ = -offset_m;
}

bool InsertionSearch::next_point(double step_m, double range_m) noexcept {
  ++tries_;
  const int k = (tries_ + 1) / 2;
  offset_y_ = search_base_ + (tries_ % 2 == 1 ? 1.0 : -1.0) * k * step_m;
  return std::abs(offset_y_ - search_base_) <= range_m + 1e-12;
}

void InsertionSearch::retreat_from(const Eigen::Vector2d& xy_m, double z_m) noexcept {
  retreat_xy_m_ = xy_m;
  retreat_z_m_ = z_m;
  phase_ = Phase::kRetreat;
}

void InsertionSearch::retreat_from_tip() noexcept {
  retreat_z_m_ = kNaN;
  phase_ = Phase::kRetreat;
}

}  // namespace mc::cell
