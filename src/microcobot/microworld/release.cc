#include "microcobot/microworld/release.h"

#include <cmath>
#include <limits>

#include "microcobot/microworld/pick_place_world.h"

namespace mc::microworld {
namespace {

// The fingers' hold on a part stuck to them: both fingers' pull-off, or their edges' once rolled.
double finger_hold_N(const PickPlaceParams& p, bool rolled) noexcept {
  return 2.0 * p.finger_pulloff_N * (rolled ? p.roll_edge_fraction : 1.0);
}

}  // namespace

std::string_view name(ReleaseStrategy r) noexcept {
  switch (r) {
    case ReleaseStrategy::kOpen:
      return "open";
    case ReleaseStrategy::kShake:
      return "shake";
    case ReleaseStrategy::kRoll:
      return "roll";
  }
  return "?";
}

bool parse_release(std::string_view text, ReleaseStrategy& out) noexcept {
  for (ReleaseStrategy r : {ReleaseStrategy::kOpen, ReleaseStrategy::kShake, ReleaseStrategy::kRoll}) {
    if (text == name(r)) {
      out = r;
      return true;
    }
  }
  return false;
}

double shake_force_N(const PickPlaceParams& p) noexcept {
  const double w = 2.0 * M_PI * p.gripper.shake_frequency_Hz;
  return p.part_mass_kg() * p.gripper.shake_amplitude_m * w * w;
}

double seat_moment_Nm(const PickPlaceParams& p) noexcept {
  return p.substrate_friction * (p.substrate_pulloff_N + p.part_weight_N()) * 0.3826 * p.part_side_m;
}

double finger_peel_moment_Nm(const PickPlaceParams& p) noexcept {
  return p.finger_pulloff_N * 0.5 * p.gripper.finger_width_m;
}

double release_margin(const PickPlaceParams& p, ReleaseStrategy r, bool in_bore) noexcept {
  const double inf = std::numeric_limits<double>::infinity();
  const auto ratio = [inf](double keep, double hold) { return hold > 0.0 ? keep / hold : inf; };
  switch (r) {
    case ReleaseStrategy::kOpen:
      return ratio(p.substrate_pulloff_N, finger_hold_N(p, false));
    case ReleaseStrategy::kShake:
      return ratio(p.substrate_pulloff_N + shake_force_N(p), finger_hold_N(p, false));
    case ReleaseStrategy::kRoll: {
      const double peel = in_bore ? inf : ratio(seat_moment_Nm(p), finger_peel_moment_Nm(p));
      return std::min(peel, ratio(p.substrate_pulloff_N, finger_hold_N(p, true)));
    }
  }
  return 0.0;
}

bool seat_keeps(const PickPlaceParams& p, bool shaking, bool rolled) noexcept {
  return p.substrate_pulloff_N + (shaking ? shake_force_N(p) : 0.0) > finger_hold_N(p, rolled);
}

bool drops_off(const PickPlaceParams& p, bool shaking, bool rolled) noexcept {
  return p.part_weight_N() + (shaking ? shake_force_N(p) : 0.0) > finger_hold_N(p, rolled);
}

}  // namespace mc::microworld
