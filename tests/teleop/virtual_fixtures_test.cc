#include "microcobot/teleop/virtual_fixtures.h"

#include <functional>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::teleop {
// The file's own namespace (unity builds, MC_UNITY_TESTS).
namespace virtual_fixtures_test {
namespace {

constexpr double kDt = 1e-4;

FixtureSet axis_at(double x, double y, double level) {
  FixtureSet f;
  f.level = level;
  f.guide = true;
  f.guide_xy_m = {x, y};
  return f;
}

VirtualFixtures settled(const FixtureSet& set) {
  VirtualFixtures v{VirtualFixtureParams{}};
  v.set(set);
  for (int i = 0; i < 20000; ++i) v.tick(kDt);  // the level reached
  return v;
}

TeleoperationInput hand_at(const Eigen::Vector2d& h) {
  TeleoperationInput in;
  in.handle_m = h;
  in.deadman = true;
  in.tweezers_opening_m = 10e-3;
  return in;
}

TEST(VirtualFixtures, BadParametersAreNamed) {
  VirtualFixtureParams p;
  p.far_distance_m = 1e-6;  // inside the capture radius
  try {
    VirtualFixtures v(p);
    FAIL() << "accepted";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("far_distance_m"), std::string::npos) << e.what();
  }
}

TEST(VirtualFixtures, GuidanceHoldsTheAxisWithinTheCaptureRadiusAndFadesWithoutAJump) {
  const VirtualFixtures v = settled(axis_at(1e-3, 2e-3, 1.0));
  const double r = VirtualFixtureParams{}.capture_radius_m;
  // Within R the slave sits on the axis whatever the hand does; beyond 2R it is the hand's.
  EXPECT_LT((v.guided({1e-3 + 0.9 * r, 2e-3 - 0.3 * r}) - Eigen::Vector2d(1e-3, 2e-3)).norm(), 1e-15);
  const Eigen::Vector2d far(1e-3 + 2.5 * r, 2e-3);
  EXPECT_LT((v.guided(far) - far).norm(), 1e-15);
  // Continuous and monotonic along a ray: no step as the target enters or leaves the field.
  double last = 0.0;
  for (double d = 0.0; d <= 3.0 * r; d += r / 1000) {
    const double g = (v.guided({1e-3 + d, 2e-3}) - Eigen::Vector2d(1e-3, 2e-3)).norm();
    EXPECT_GE(g, last - 1e-18);
    // Its slope is at most 3 (at 2R, where d (d - R) / R meets d).
    EXPECT_LE(g - last, 3.0 * r / 1000 * 1.0001) << "jump at d = " << d;
    last = g;
  }
}

FixtureSet path_to(const Eigen::Vector2d& from, const Eigen::Vector2d& to, double level) {
  FixtureSet f = axis_at(to.x(), to.y(), level);
  f.path = true;
  f.path_from_xy_m = from;
  return f;
}

// Guidance along a path: within R of the segment the slave
// sits on it at the hand's place along it (motion along is free, across is taken out); beyond its
// end the end is the point guide; beyond 2R the hand's; no jump as the target crosses the field.
TEST(VirtualFixtures, AlongAPathMotionAlongIsFreeAndMotionAcrossIsTakenOut) {
  const Eigen::Vector2d a(0.0, 0.0), b(1e-3, 0.5e-3);
  const VirtualFixtures v = settled(path_to(a, b, 1.0));
  const double r = VirtualFixtureParams{}.capture_radius_m;
  const Eigen::Vector2d along = (b - a).normalized(), across(-along.y(), along.x());
  for (const double u : {0.1, 0.5, 0.93}) {
    const Eigen::Vector2d on = a + u * (b - a);
    EXPECT_LT((v.guided(on + 0.8 * r * across) - on).norm(), 1e-15) << "across taken out at u = " << u;
    EXPECT_LT((v.guided(on - 0.5 * r * across) - on).norm(), 1e-15);
    EXPECT_LT((v.guided(on + 2.2 * r * across) - (on + 2.2 * r * across)).norm(), 1e-15) << "beyond 2R: free";
  }
  EXPECT_LT((v.guided(b + 0.6 * r * along) - b).norm(), 1e-15) << "past the end: the point guide";
  EXPECT_LT((v.guided(a - 0.6 * r * along) - a).norm(), 1e-15) << "before the start: its end";
  // Continuous across the path: a ray from the middle outward, as for the axis.
  const Eigen::Vector2d mid = 0.5 * (a + b);
  double last = 0.0;
  for (double d = 0.0; d <= 3.0 * r; d += r / 1000) {
    const double g = (v.guided(mid + d * across) - mid).norm();
    EXPECT_GE(g, last - 1e-18);
    EXPECT_LE(g - last, 3.0 * r / 1000 * 1.0001) << "jump at d = " << d;
    last = g;
  }
  EXPECT_LT((v.nearest_guide(mid + 10e-6 * across) - mid).norm(), 1e-15);
}

TEST(VirtualFixtures, TheLevelIsSlewedAndBadSetsRemoveTheFixtures) {
  VirtualFixtures v{VirtualFixtureParams{}};
  v.set(axis_at(0, 0, 1.0));
  v.tick(kDt);
  EXPECT_NEAR(v.level(), VirtualFixtureParams{}.level_rate_1_s * kDt, 1e-15);
  FixtureSet bad = axis_at(0, 0, 1.5);
  v.set(bad);
  EXPECT_FALSE(v.fixtures().guide);
  EXPECT_EQ(v.level(), 0.0);
  bad = axis_at(std::nan(""), 0, 1.0);
  v.set(bad);
  EXPECT_FALSE(v.active());
}

TEST(VirtualFixtures, TheFunnelKeepsThePartOffTheRim) {
  FixtureSet f = axis_at(0, 0, 0.0);
  f.funnel = true;
  f.rim_z_m = 100e-6;
  f.funnel_radius_m = 5e-6;
  const VirtualFixtures v = settled(f);
  const VirtualFixtureParams p;
  EXPECT_EQ(v.lowest_z({4e-6, 0}), -std::numeric_limits<double>::infinity());  // on the axis: free
  const double tan_cone = std::tan(p.funnel_half_angle_deg * M_PI / 180);
  EXPECT_NEAR(v.lowest_z({0, 10e-6}), 100e-6 + 5e-6 / tan_cone, 1e-15);   // on the cone
  EXPECT_NEAR(v.lowest_z({1e-3, 0}), 100e-6 + p.funnel_height_m, 1e-15);  // far: above it all
}

TEST(TeleoperationWithFixtures, WithoutFixturesTheCouplingIsUnchanged) {
  // A set at level 0 without a funnel guides nothing: the same targets as no set at all.
  Teleoperation plain(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  Teleoperation idle(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  idle.set_fixtures(axis_at(0, 0, 0.0));
  std::mt19937 rng(4);
  std::normal_distribution<double> step(0, 1e-4);
  Eigen::Vector2d h(0, 0);
  for (int i = 0; i < 5000; ++i) {
    h += Eigen::Vector2d(step(rng), step(rng));
    auto in = hand_at(h);
    in.z_jog_m_s = 1e-4 * std::sin(i * 1e-3);
    const auto a = plain.tick(in).slave_target_m;
    const auto b = idle.tick(in).slave_target_m;
    ASSERT_EQ(a, b) << "tick " << i;
  }
}

TEST(TeleoperationWithFixtures, RaisingTheAssistanceNeverJumpsTheTarget) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  const Eigen::Vector2d h(0.01, -0.005);
  t.tick(hand_at(h));  // engaged, the slave at 0
  // A guide 20 um away (within R: the slave goes onto it) and 300 um away (beyond 2R: only the
  // scaling changes, and the still hand's slave stays put); the hand still.
  for (const double gx : {300e-6, 20e-6}) {
    const Eigen::Vector3d start = t.output().slave_target_m;
    t.set_fixtures(axis_at(gx, 0, 1.0));
    Eigen::Vector3d last = start;
    double largest = 0.0;
    for (int i = 0; i < 10000; ++i) {
      const auto& out = t.tick(hand_at(h));
      largest = std::max(largest, (out.slave_target_m - last).norm());
      last = out.slave_target_m;
    }
    // The guided target moves by at most the level's rate times the guide's distance per tick.
    EXPECT_LE(largest, VirtualFixtureParams{}.level_rate_1_s * kDt * gx * 1.0001) << gx;
    if (gx > 50e-6) {
      EXPECT_LT((last - start).norm(), 1e-15) << "the scale's change moved the slave";
    } else {
      EXPECT_LT((last - Eigen::Vector3d(gx, 0, 0)).norm(), 1e-12) << "not on the guide";
    }
    // Removing the fixture leaves the slave where the guidance put it.
    t.set_fixtures({});
    for (int i = 0; i < 100; ++i) EXPECT_LT((t.tick(hand_at(h)).slave_target_m - last).norm(), 1e-15);
  }
}

TEST(TeleoperationWithFixtures, ScalingIsCoarseFarAndFineNear) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  t.set_fixtures(axis_at(2e-3, 0, 1.0));
  Eigen::Vector2d h(0, 0);
  for (int i = 0; i < 10000; ++i) t.tick(hand_at(h));
  const VirtualFixtureParams p;
  EXPECT_NEAR(t.motion_scale(), TeleoperationParams{}.motion_scale * p.far_gain, 1e-12);
  // Toward the guide the scale falls to the configured one near it, continuously.
  double last_scale = t.motion_scale();
  while (t.output().slave_target_m.x() < 2e-3 - 1e-12) {  // until the guidance holds it on the axis
    h.x() += 1e-6;
    t.tick(hand_at(h));
    EXPECT_LE(t.motion_scale(), last_scale * (1 + 1e-12));
    last_scale = t.motion_scale();
    ASSERT_LT(h.x(), 1.0);
  }
  t.tick(hand_at(h));
  EXPECT_NEAR(t.motion_scale(), TeleoperationParams{}.motion_scale, 1e-15);
}

// A hand trembling round a path that crosses the guide while `fixture(level)` is installed with the
// level ramping up and down: the lowest energy the passivity observer books, and the largest force.
std::pair<double, double> passivity_under_tremor(const std::function<FixtureSet(double)>& fixture,
                                                 unsigned seed, double across_m) {
  Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 0}, 600e-6);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, 1e-3);
  t.tick(hand_at({0, 0}));
  double lowest = 0.0, force = 0.0;
  for (int i = 0; i < 60000; ++i) {
    const double s = i * kDt;
    if (i % 15000 == 0) t.set_fixtures(fixture((i / 15000) % 2 == 0 ? 1.0 : 0.3));
    const Eigen::Vector2d h(6e-3 * std::sin(2 * M_PI * 0.5 * s) + noise(rng) * 0.1,
                            across_m * std::sin(2 * M_PI * 10 * s) + noise(rng) * 0.1);
    const auto& out = t.tick(hand_at(h));
    lowest = std::min(lowest, t.fixtures().observed_J());
    force = std::max(force, out.haptic_force_N.norm());
  }
  return {lowest, force};
}

TEST(TeleoperationWithFixtures, TheGuidanceDisplayIsPassiveUnderTremor) {
  // The fixture's observed energy never goes below zero, its controller dissipating the rest.
  const auto [lowest, force] =
      passivity_under_tremor([](double a) { return axis_at(30e-6, 0, a); }, 11, 1e-3);
  EXPECT_GT(force, 0.05);  // the guidance was felt
  EXPECT_GE(lowest, -1e-12);
}

TEST(TeleoperationWithFixtures, APathsGuidanceDisplayIsPassiveUnderTremor) {
  // The same with the guide along a path the hand crosses back and forth.
  const auto [lowest, force] = passivity_under_tremor(
      [](double a) {
        return path_to({-40e-6, 10e-6}, {60e-6, -5e-6}, a);
      },
      12, 2e-3);
  EXPECT_GT(force, 0.05);
  EXPECT_GE(lowest, -1e-12);
}

TEST(VirtualFixtures, RaisingTheLevelAddsNoEnergyTheHandCanTakeOut) {
  // The field booked at level 0.2 with the handle 20 um (slave) off the axis; the level then
  // rises to 1 and the hand lets the handle go in to the axis: a plain spring would return five
  // times the energy stored. The controller dissipates the difference: E stays >= 0.
  VirtualFixtures v{VirtualFixtureParams{}};
  v.set(axis_at(0, 0, 0.2));
  for (int i = 0; i < 20000; ++i) v.tick(kDt);
  const double s = 0.01;  // motion scale
  v.rebase_energy({20e-6, 0}, s);
  v.set(axis_at(0, 0, 1.0));
  for (int i = 0; i < 20000; ++i) v.tick(kDt);
  double lowest = v.observed_J();
  const Eigen::Vector2d handle_v(-0.02, 0);  // 20 mm/s of hand: 200 um/s of slave, inward
  for (double x = 20e-6; x > 0; x -= 200e-6 * kDt) {
    const Eigen::Vector2d raw(x, 0);
    v.display_force(raw, v.guided(raw), handle_v, s, kDt);
    lowest = std::min(lowest, v.observed_J());
  }
  EXPECT_GE(lowest, -1e-15);
  EXPECT_GT(v.dissipated_J(), 0.0);
}

FixtureSet height_stop_at(double z, double level) {
  FixtureSet f = axis_at(0, 0, level);
  f.height = true;
  f.height_z_m = z;
  return f;
}

TEST(VirtualFixtures, AHeightStopHoldsWithinItsCaptureAndFadesWithoutAJump) {
  const VirtualFixtures v = settled(height_stop_at(400e-6, 1.0));
  const double h = VirtualFixtureParams{}.height_capture_m;
  EXPECT_TRUE(v.height_active());
  // Within H the slave sits at the height; beyond 2H it is the input's.
  EXPECT_EQ(v.guided_z(400e-6 + 0.9 * h), 400e-6);
  EXPECT_EQ(v.guided_z(400e-6 - 0.5 * h), 400e-6);
  EXPECT_EQ(v.guided_z(400e-6 + 2.5 * h), 400e-6 + 2.5 * h);
  // Continuous and monotonic through the stop, both sides: slope 0 within H, at most 3 in the band.
  double last = v.guided_z(400e-6 - 3.0 * h);
  for (double e = -3.0 * h; e <= 3.0 * h; e += h / 1000) {
    const double g = v.guided_z(400e-6 + e);
    EXPECT_GE(g, last - 1e-18);
    EXPECT_LE(g - last, 3.0 * h / 1000 * 1.0001) << "jump at e = " << e;
    last = g;
  }
  // A set without the stop guides no height, whatever its level.
  EXPECT_EQ(settled(axis_at(0, 0, 1.0)).guided_z(400e-6 + 0.5 * h), 400e-6 + 0.5 * h);
}

TEST(TeleoperationWithFixtures, AHeightStopHoldsTheSlaveAndNeverJumpsIt) {
  // The thumb wheel (haptic) and the joystick (console) rolled down toward a stop 40 um below and on
  // past it by less than its capture: the slave stops at the height, moved at most at the
  // fixtures' pace per tick, and stays there; a new stop, and removing it, never jump the target.
  const VirtualFixtureParams p;
  const double pace_step = p.max_speed_m_s * kDt * (1 + 1e-9);
  for (const bool console : {true, false}) {
    Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 500e-6}, 600e-6);
    t.tick(hand_at({0, 0}));
    t.set_fixtures(height_stop_at(460e-6, 1.0));
    Eigen::Vector3d last = t.output().slave_target_m;
    double largest = 0.0;
    const auto tick = [&](double rate_m_s) {
      TeleoperationInput in = hand_at({0, 0});
      if (console) {
        in.console.active = in.console.fresh = in.console.deadman = true;
        in.console.velocity_m_s = {0, 0, rate_m_s};
      } else {
        in.z_jog_m_s = rate_m_s;
      }
      const Eigen::Vector3d now = t.tick(in).slave_target_m;
      largest = std::max(largest, (now - last).norm());
      last = now;
    };
    for (int i = 0; i < 3000; ++i) tick(-20e-6 / 0.3);  // 60 um down in 0.3 s: 20 um past the stop
    for (int i = 0; i < 5000; ++i) tick(0.0);
    EXPECT_NEAR(last.z(), 460e-6, 1e-12) << (console ? "console" : "haptic");
    EXPECT_LE(largest, pace_step) << (console ? "console" : "haptic");
    // A new stop 20 um up (within its capture): the slave rises onto it, never faster than the pace.
    largest = 0.0;
    t.set_fixtures(height_stop_at(480e-6, 1.0));
    for (int i = 0; i < 10000; ++i) tick(0.0);
    EXPECT_NEAR(last.z(), 480e-6, 1e-12) << (console ? "console" : "haptic");
    EXPECT_LE(largest, pace_step) << (console ? "console" : "haptic");
    // The stop removed: the slave stays where it was put, and the wheel moves it from there.
    t.set_fixtures(axis_at(0, 0, 1.0));
    for (int i = 0; i < 100; ++i) tick(0.0);
    EXPECT_NEAR(last.z(), 480e-6, 1e-15) << (console ? "console" : "haptic");
    for (int i = 0; i < 1000; ++i) tick(10e-6 / 0.1);
    EXPECT_NEAR(last.z(), 490e-6, 1e-9) << (console ? "console" : "haptic");
  }
}

TEST(TeleoperationWithFixtures, NoFixtureMovesTheSlaveWithoutTheDeadman) {
  // A guide (an axis, or a path) and a height stop within their captures pull the slave onto them,
  // but only while the operator holds the deadman: released, on either master, the target does not
  // move at all.
  FixtureSet axis = height_stop_at(480e-6, 1.0);
  axis.guide_xy_m = {15e-6, -10e-6};
  FixtureSet path = axis;
  path.path = true;
  path.path_from_xy_m = {-85e-6, -10e-6};  // the slave's nearest point on it: (0, -10) um
  for (const auto& [f, onto] : {std::pair{axis, Eigen::Vector3d(15e-6, -10e-6, 480e-6)},
                                std::pair{path, Eigen::Vector3d(0.0, -10e-6, 480e-6)}}) {
    for (const bool console : {true, false}) {
      Teleoperation t(TeleoperationParams{}, kDt, {0, 0, 500e-6}, 600e-6);
      t.tick(hand_at({0, 0}));
      const Eigen::Vector3d start = t.output().slave_target_m;
      t.set_fixtures(f);
      for (int i = 0; i < 10000; ++i) {
        TeleoperationInput in = hand_at({0, 0});
        in.deadman = false;
        if (console) {
          in.console.active = in.console.fresh = true;
          in.console.deadman = false;
        }
        ASSERT_EQ(t.tick(in).slave_target_m, start) << (console ? "console" : "haptic") << " tick " << i;
      }
      // Held again: now the fixtures take the slave onto the guide and the height, at the pace.
      for (int i = 0; i < 10000; ++i) {
        TeleoperationInput in = hand_at({0, 0});
        if (console) in.console.active = in.console.fresh = in.console.deadman = true;
        t.tick(in);
      }
      EXPECT_LT((t.output().slave_target_m - onto).norm(), 1e-12)
          << (console ? "console" : "haptic") << (f.path ? ", path" : ", axis");
    }
  }
}

TEST(TeleoperationWithFixtures, TheFunnelIsNeverEnteredWhateverTheInput) {
  // A console joystick and a haptic hand driving down onto the rim beside the axis, with noise:
  // the target never goes below the funnel, and reaches the bore's depth only on the axis.
  FixtureSet f = axis_at(0, 0, 1.0);
  f.funnel = true;
  f.rim_z_m = 0.0;
  f.funnel_radius_m = 4e-6;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 1.0);
  for (const bool console : {true, false}) {
    Teleoperation t(TeleoperationParams{}, kDt, {80e-6, 10e-6, 200e-6}, 600e-6);
    t.set_fixtures(f);
    Eigen::Vector2d h(0, 0);
    for (int i = 0; i < 40000; ++i) {
      TeleoperationInput in = hand_at(h);
      if (console) {
        in.console.active = in.console.fresh = in.console.deadman = true;
        in.console.velocity_m_s = {-2e-4 + 2e-4 * noise(rng), 2e-4 * noise(rng), -3e-4};
      } else {
        h += Eigen::Vector2d(-1e-6 + 3e-5 * noise(rng), 3e-5 * noise(rng));
        in.handle_m = h;
        in.z_jog_m_s = -3e-4;
      }
      const double last_z = t.output().slave_target_m.z();
      const auto& out = t.tick(in);
      const Eigen::Vector3d& x = out.slave_target_m;
      ASSERT_GE(x.z(), t.fixtures().lowest_z(x.head<2>()) - 1e-15) << (console ? "console" : "haptic") << i;
      if (x.z() < 0.0) {
        // In the bore: held within r0 of the axis (its walls), and never lifted out by the cone.
        ASSERT_LE(x.head<2>().norm(), f.funnel_radius_m + 1e-12);
        ASSERT_LE(x.z(), last_z + 1e-15) << (console ? "console" : "haptic") << i;
      }
    }
  }
}

TEST(TeleoperationWithFixtures, APartInItsBoreIsHeldByItsWallsNotLiftedOut) {
  // Guided onto the axis and down into the bore, then dragged sideways far beyond the capture:
  // the target stays within the bore's radius, at its depth (the cone once pulled it up to the rim).
  FixtureSet f = axis_at(0, 0, 1.0);
  f.funnel = true;
  f.rim_z_m = 0.0;
  f.funnel_radius_m = 2e-6;
  for (const bool console : {true, false}) {
    Teleoperation t(TeleoperationParams{}, kDt, {10e-6, 5e-6, 100e-6}, 600e-6);
    t.set_fixtures(f);
    Eigen::Vector2d h(0, 0);
    const auto drive = [&](const Eigen::Vector3d& v_m_s) -> const Eigen::Vector3d& {
      TeleoperationInput in = hand_at(h);
      if (console) {
        in.console.active = in.console.fresh = in.console.deadman = true;
        in.console.velocity_m_s = v_m_s;
      } else {
        h += v_m_s.head<2>() * kDt / TeleoperationParams{}.motion_scale;
        in.handle_m = h;
        in.z_jog_m_s = v_m_s.z();
      }
      return t.tick(in).slave_target_m;
    };
    for (int i = 0; i < 10000; ++i) drive({0, 0, 0});     // the guidance takes it onto the axis
    for (int i = 0; i < 5000; ++i) drive({0, 0, -3e-4});  // 150 um down: 50 um into the bore
    const double z_in = t.output().slave_target_m.z();
    ASSERT_NEAR(z_in, -50e-6, 1e-9) << (console ? "console" : "haptic");
    ASSERT_LE(t.output().slave_target_m.head<2>().norm(), 1e-12);
    for (int i = 0; i < 10000; ++i) {
      const Eigen::Vector3d& x = drive({5e-4, 2e-4, 0.0});  // 0.5 mm sideways
      ASSERT_LE(x.head<2>().norm(), f.funnel_radius_m + 1e-12) << (console ? "console" : "haptic") << i;
      ASSERT_EQ(x.z(), z_in) << (console ? "console" : "haptic") << i;
    }
    EXPECT_NEAR(t.output().slave_target_m.head<2>().norm(), f.funnel_radius_m, 1e-12);  // against the wall
  }
}

}  // namespace
}  // namespace virtual_fixtures_test
}  // namespace mc::teleop
