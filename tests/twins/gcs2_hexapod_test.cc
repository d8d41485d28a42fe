// The PI hexapod (C-887) dialect of GCS 2.0 line by line: its codec (pose and pivot pairs, axis
// queries, coordinate system names) and the twin over the live platform's parallel positioner
// (`positioner: parallel`), stepped on the platform's loop: identification, reference, pose moves in PI's U
// -> V -> W convention about the pivot, refusals before motion, stops, velocity and user coordinate systems.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <thread>

#include "hexapod_rig.h"
#include "microcobot/core/error.h"
#include "microcobot/drivers/gcs2_hexapod.h"
#include "microcobot/motion/pose.h"

#include <fmt/format.h>

namespace mc::twins {
namespace gcs2_hexapod_test {

using namespace std::chrono_literals;
using testing::HexapodRig;
namespace g = drivers::gcs2;
constexpr double kDeg = std::numbers::pi / 180.0;

TEST(Gcs2HexapodCodec, ParsesPosePairsPivotPairsQueriesAndNames) {
  auto p = g::parse_hexapod_values({"x", "1", "U", "-0.5"});
  EXPECT_EQ(p.error, 0);
  EXPECT_EQ(p.values[0], 1.0);
  EXPECT_EQ(p.values[3], -0.5);
  EXPECT_FALSE(p.values[1]);
  EXPECT_EQ(g::parse_hexapod_values({"X"}).error, g::kParameterSyntax);
  EXPECT_EQ(g::parse_hexapod_values({}).error, g::kParameterSyntax);
  EXPECT_EQ(g::parse_hexapod_values({"Q", "1"}).error, g::kInvalidAxis);
  EXPECT_EQ(g::parse_hexapod_values({"X", "1", "x", "2"}).error, g::kAxisTwice);
  EXPECT_EQ(g::parse_hexapod_values({"X", "nan"}).error, g::kParameterSyntax);
  EXPECT_EQ(g::parse_hexapod_values({"R", "1"}).error, g::kInvalidAxis);
  const auto s = g::parse_pivot_values({"T", "5"});
  EXPECT_EQ(s.error, 0);
  EXPECT_EQ(s.values[2], 5.0);
  EXPECT_EQ(g::parse_pivot_values({"X", "5"}).error, g::kInvalidAxis);
  EXPECT_EQ(g::parse_hexapod_query({}).axes.size(), 6u);
  EXPECT_EQ(g::parse_hexapod_query({"all"}).axes.size(), 6u);
  EXPECT_EQ(g::parse_hexapod_query({"W", "x"}).axes, (std::vector<int>{5, 0}));
  EXPECT_EQ(g::parse_hexapod_query({"1"}).error, g::kInvalidAxis);
  EXPECT_EQ(g::parse_pivot_query({"s"}).axes, (std::vector<int>{1}));
  EXPECT_EQ(g::parse_cs_name("tool_1"), "TOOL_1");
  EXPECT_FALSE(g::parse_cs_name("1tool"));
  EXPECT_FALSE(g::parse_cs_name(""));
  EXPECT_FALSE(g::parse_cs_name("TOOLONGNAME"));
  EXPECT_FALSE(g::parse_cs_name("A-B"));
  EXPECT_EQ(g::hexapod_error_text(9), "Attempt to set pivot point while U,V and W not all 0");
  EXPECT_EQ(g::hexapod_error_text(7), "Position out of limits");
}

TEST(Gcs2HexapodTwin, IdentifiesAsAC887WithSixAxesWhoseServoIsAlwaysOn) {
  HexapodRig r;
  EXPECT_NE(r.ask("*IDN?").find("C-887"), std::string::npos);
  EXPECT_EQ(r.ask("CSV?"), "2.0\n");
  EXPECT_EQ(r.ask("SAI?"), "X \nY \nZ \nU \nV \nW\n");
  EXPECT_EQ(r.ask("SAI? ALL"), "X \nY \nZ \nU \nV \nW\n");
  EXPECT_EQ(r.ask("SVO?"), "X=1 \nY=1 \nZ=1 \nU=1 \nV=1 \nW=1\n");
  EXPECT_EQ(r.ask("SVO X 1 Y 1"), "");
  EXPECT_EQ(r.err(), "0\n");
  EXPECT_EQ(r.ask("SVO X 0"), "");
  EXPECT_EQ(r.err(), "17\n");
  const std::string help = r.ask("HLP?");
  for (const char* c : {"VMO?", "KSD", "KEN", "SPI", "VLS", "#24"})
    EXPECT_NE(help.find(c), std::string::npos) << c;
  EXPECT_EQ(help.substr(help.size() - 12), "end of help\n");
  EXPECT_EQ(r.ask("FRF?"), "X=0 \nY=0 \nZ=0 \nU=0 \nV=0 \nW=0\n");
  EXPECT_EQ(r.byte(7), "\xb1\n");
  EXPECT_EQ(r.byte(5), "0\n");
  EXPECT_EQ(r.ask("2 CSV?"), "");  // another controller's address
  EXPECT_EQ(r.ask("1 CSV?"), "0 1 2.0\n");
}

TEST(Gcs2HexapodTwin, MovesAreRefusedWithError5UntilTheReferenceMoveEnded) {
  HexapodRig r;
  EXPECT_EQ(r.ask("MOV X 0.01"), "");
  EXPECT_EQ(r.err(), "5\n");
  EXPECT_EQ(r.ask("MVR X 0.01"), "");
  EXPECT_EQ(r.err(), "5\n");
  EXPECT_EQ(r.err(), "0\n");  // read and cleared
  r.reference();
  EXPECT_EQ(r.ask("MOV X 0.01"), "");
  EXPECT_EQ(r.err(), "0\n");
  EXPECT_TRUE(r.wait_on_target());
}

TEST(Gcs2HexapodTwin, APoseSequenceEndsOnTargetWithinAMicronAndAMillidegree) {
  HexapodRig r;
  r.reference();
  ASSERT_EQ(r.ask("VLS 0.5"), "");
  const std::array<std::array<double, 6>, 3> goals{{{0.05, -0.03, 0.02, 0.2, -0.1, 0.3},
                                                    {-0.04, 0.02, -0.01, -0.1, 0.2, -0.2},
                                                    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}}};
  for (const auto& goal : goals) {
    ASSERT_EQ(r.ask(fmt::format("MOV X {} Y {} Z {} U {} V {} W {}", goal[0], goal[1], goal[2], goal[3],
                                goal[4], goal[5])),
              "");
    EXPECT_EQ(r.byte(5), "3F\n");  // moving (or about to)
    EXPECT_EQ(r.ask("ONT? X"), "X=0\n");
    ASSERT_TRUE(r.wait_on_target());
    EXPECT_EQ(r.byte(5), "0\n");
    const auto pos = r.pose();
    const auto target = r.pose("MOV?");
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_NEAR(target[i], goal[i], 1e-9) << i;
      EXPECT_NEAR(pos[i], goal[i], i < 3 ? 1e-3 : 1e-3) << i;
    }
  }
  // MVR adds to the target.
  ASSERT_EQ(r.ask("MVR Z 0.01 W 0.1"), "");
  ASSERT_TRUE(r.wait_on_target());
  const auto pos = r.pose();
  EXPECT_NEAR(pos[2], 0.01, 1e-3);
  EXPECT_NEAR(pos[5], 0.1, 1e-3);
  EXPECT_EQ(r.err(), "0\n");
}

TEST(Gcs2HexapodTwin, AnUnreachablePoseIsRefusedWithError7AndNothingMoves) {
  HexapodRig r;
  r.reference();
  const double tmx = r.twin.travel_max()[2];
  EXPECT_GT(tmx, 0.0);
  EXPECT_LT(r.twin.travel_min()[0], 0.0);
  EXPECT_GT(r.twin.travel_max()[3], 0.0);
  EXPECT_EQ(r.ask("VMO? X 0.01"), "1\n");
  EXPECT_EQ(r.ask(fmt::format("VMO? Z {}", tmx + 0.1)), "0\n");
  EXPECT_EQ(r.ask("VMO? Z 40"), "0\n");
  EXPECT_EQ(r.byte(5), "0\n");  // a virtual move moves nothing
  const auto before = r.pose();
  const double t0 = r.stage.positioner_view().time_s;
  for (const char* line : {"MOV Z 40", "MOV U 80", "MOV X 1e300"}) {
    EXPECT_EQ(r.ask(line), "") << line;
    EXPECT_EQ(r.err(), "7\n") << line;
    EXPECT_EQ(r.byte(5), "0\n") << line;
  }
  std::this_thread::sleep_for(200ms);
  EXPECT_GT(r.stage.positioner_view().time_s, t0 + 0.05);  // the loop ran all along
  const auto after = r.pose();
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(after[i], before[i], 1e-4) << i;
  const auto target = r.pose("MOV?");
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(target[i], 0.0, 1e-12) << i;
  EXPECT_EQ(r.ask("ONT?"), "X=1 \nY=1 \nZ=1 \nU=1 \nV=1 \nW=1\n");
}

TEST(Gcs2HexapodTwin, RotationsTurnAboutThePivotWhichMovesOnlyWhileUnturned) {
  HexapodRig r;
  r.reference();
  ASSERT_EQ(r.ask("SPI T 2 R 0.5"), "");
  EXPECT_EQ(r.err(), "0\n");
  EXPECT_EQ(r.ask("SPI?"), "R=0.500000 \nS=0.000000 \nT=2.000000\n");
  ASSERT_EQ(r.ask("MOV U 0.5 V -0.3 W 0.4"), "");
  ASSERT_TRUE(r.wait_on_target());
  // The platform turned about its pivot point c: R c + d = c (PI's pivot, motion/pose.h).
  const live::PositionerView v = r.stage.positioner_view();
  const Eigen::Vector3d c(0.5e-3, 0.0, 2e-3);
  EXPECT_LT((v.measured.R * c + v.measured.d - c).norm(), 1e-6);
  const Eigen::Vector3d uvw = motion::pi_angles(v.measured.R) / kDeg;
  EXPECT_NEAR(uvw(0), 0.5, 1e-3);
  EXPECT_NEAR(uvw(1), -0.3, 1e-3);
  EXPECT_NEAR(uvw(2), 0.4, 1e-3);
  const auto pos = r.pose();
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(pos[i], 0.0, 1e-3) << i;
  // Turned: the pivot stays.
  EXPECT_EQ(r.ask("SPI T 0"), "");
  EXPECT_EQ(r.err(), "9\n");
  EXPECT_EQ(r.ask("SPI?"), "R=0.500000 \nS=0.000000 \nT=2.000000\n");
  EXPECT_EQ(r.ask("SPI X 1"), "");
  EXPECT_EQ(r.err(), "15\n");
}

TEST(Gcs2HexapodTwin, AUserCoordinateSystemReadsAndMovesInItsFrame) {
  HexapodRig r;
  r.reference();
  EXPECT_EQ(r.ask("KEN?"), "ZERO=ZERO\n");
  ASSERT_EQ(r.ask("KSD work X 0.1 W 1"), "");
  ASSERT_EQ(r.err(), "0\n");
  ASSERT_EQ(r.ask("KEN WORK"), "");
  EXPECT_EQ(r.ask("KEN?"), "WORK=KSD\n");
  // At home, seen from the system whose origin is 0.1 mm along X and turned 1 deg about Z.
  auto pos = r.pose();
  EXPECT_NEAR(pos[5], -1.0, 1e-3);
  EXPECT_NEAR(pos[0], -0.1 * std::cos(kDeg), 1e-3);
  EXPECT_NEAR(pos[1], 0.1 * std::sin(kDeg), 1e-3);
  // The system's origin, unturned in it: the platform at 0.1 mm along X, turned 1 deg about Z.
  ASSERT_EQ(r.ask("MOV X 0 Y 0 Z 0 U 0 V 0 W 0"), "");
  ASSERT_TRUE(r.wait_on_target());
  pos = r.pose();
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(pos[i], 0.0, 1e-3) << i;
  EXPECT_EQ(r.ask("KSD WORK X 0"), "");
  EXPECT_EQ(r.err(), "532\n");  // in use
  EXPECT_EQ(r.ask("KEN NONE"), "");
  EXPECT_EQ(r.err(), "530\n");
  EXPECT_EQ(r.ask("KSD 9LIVES X 1"), "");
  EXPECT_EQ(r.err(), "557\n");
  ASSERT_EQ(r.ask("KEN ZERO"), "");
  pos = r.pose();
  EXPECT_NEAR(pos[0], 0.1, 1e-3);
  EXPECT_NEAR(pos[5], 1.0, 1e-3);
}

TEST(Gcs2HexapodTwin, StopAllMidMoveHoldsWithError10AndTheTargetBecomesWhereItStopped) {
  HexapodRig r;
  r.reference();
  ASSERT_EQ(r.ask("MOV X 0.2"), "");  // 2 s at 0.1 mm/s
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(r.byte(24), "");
  EXPECT_EQ(r.err(), "10\n");
  ASSERT_TRUE(r.wait_on_target(5.0));
  const auto pos = r.pose();
  EXPECT_GT(pos[0], 0.005);
  EXPECT_LT(pos[0], 0.19);
  EXPECT_NEAR(r.pose("MOV?")[0], pos[0], 1e-3);
  std::this_thread::sleep_for(300ms);
  EXPECT_NEAR(r.pose()[0], pos[0], 1e-3);  // holds
  // Moves again from there.
  ASSERT_EQ(r.ask("MOV X 0"), "");
  EXPECT_EQ(r.err(), "0\n");
  ASSERT_TRUE(r.wait_on_target());
  EXPECT_NEAR(r.pose()[0], 0.0, 1e-3);
  ASSERT_EQ(r.ask("MOV Y 0.1"), "");
  ASSERT_EQ(r.ask("STP"), "");
  EXPECT_EQ(r.err(), "10\n");
  ASSERT_TRUE(r.wait_on_target(5.0));
}

TEST(Gcs2HexapodTwin, AMoveSentDuringAnotherStartsWhereThatOneEnds) {
  HexapodRig r;
  r.reference();
  ASSERT_EQ(r.ask("VLS 0.5"), "");
  ASSERT_EQ(r.ask("MOV X 0.03"), "");
  ASSERT_EQ(r.ask("MOV Y 0.03"), "");
  ASSERT_EQ(r.ask("MVR Z 0.01"), "");
  EXPECT_EQ(r.err(), "0\n");
  ASSERT_TRUE(r.wait_on_target());
  const auto pos = r.pose();
  EXPECT_NEAR(pos[0], 0.03, 1e-3);
  EXPECT_NEAR(pos[1], 0.03, 1e-3);
  EXPECT_NEAR(pos[2], 0.01, 1e-3);
}

TEST(Gcs2HexapodTwin, BadLinesGetTheControllersErrors) {
  HexapodRig r;
  EXPECT_EQ(r.ask("VLS 0"), "");
  EXPECT_EQ(r.err(), "8\n");
  EXPECT_EQ(r.ask("VLS 2"), "");
  EXPECT_EQ(r.err(), "8\n");
  EXPECT_EQ(r.ask("VLS fast"), "");
  EXPECT_EQ(r.err(), "1\n");
  EXPECT_EQ(r.ask("VLS 0.25"), "");
  EXPECT_EQ(r.ask("VLS?"), "0.250000\n");
  for (const auto& [line, code] : std::vector<std::pair<std::string, std::string>>{{"FOO", "2\n"},
                                                                                   {"MOV Q 1", "15\n"},
                                                                                   {"MOV X", "1\n"},
                                                                                   {"MOV X 1 X 2", "22\n"},
                                                                                   {"POS? Q", "15\n"},
                                                                                   {"SAI? X", "1\n"},
                                                                                   {"KEN", "1\n"},
                                                                                   {"KEN? WORK", "1\n"},
                                                                                   {"VMO?", "1\n"},
                                                                                   {"HLT Q", "15\n"},
                                                                                   {"FRF Q", "15\n"}}) {
    EXPECT_EQ(r.ask(line), "") << line;
    EXPECT_EQ(r.err(), code) << line;
  }
  r.twin.on_overlong_line();
  EXPECT_EQ(r.err(), "3\n");
  const auto two = g::parse_axis_values(r.ask("POS? X W"));
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].first, "X");
  EXPECT_EQ(two[1].first, "W");
  EXPECT_NEAR(two[0].second, 0.0, 1e-3);
}

TEST(Gcs2HexapodTwin, AFullRingAndAStopTheLoopHasNotAppliedAreRefusedAsBusy) {
  // The loop not started: what is sent waits in the ring, and a stop is never applied.
  HexapodRig r(/*start=*/false);
  Gcs2HexapodTwin& twin = r.twin;
  EXPECT_EQ(twin.on_line(1, "FRF"), "");
  EXPECT_EQ(twin.on_byte(1, 7), "\xb0\n");  // referencing
  EXPECT_EQ(twin.on_byte(1, 5), "3F\n");
  EXPECT_EQ(twin.on_line(1, "ERR?"), "0\n");
  // The live platform's protocol ring (256 commands) fills: then the controller is busy.
  std::string code = "0\n";
  for (int k = 0; k < 300 && code == "0\n"; ++k) {
    EXPECT_EQ(twin.on_line(1, "FRF"), "");
    code = twin.on_line(1, "ERR?");
  }
  EXPECT_EQ(code, "1005\n");
  EXPECT_EQ(twin.on_line(1, "KSD WORK X 1"), "");
  EXPECT_EQ(twin.on_line(1, "ERR?"), "536\n");  // not while moving
  EXPECT_EQ(twin.on_byte(1, 24), "");
  EXPECT_EQ(twin.on_byte(1, 7), "\xb1\n");  // the stop ended the referencing
  EXPECT_EQ(twin.on_line(1, "ERR?"), "10\n");
  EXPECT_EQ(twin.on_line(1, "MOV? X"), "");  // the stopped pose is not known yet
  EXPECT_EQ(twin.on_line(1, "ERR?"), "1005\n");
  EXPECT_FALSE(twin.referenced());
}

TEST(Gcs2HexapodTwin, RefusesToServeAPlatformWithoutAParallelPositioner) {
  live::LiveParams p;  // positioner: cartesian
  live::LivePlatform live(p);
  LiveStage stage(live);
  try {
    Gcs2HexapodTwin twin(stage, Gcs2HexapodTwinParams{});
    FAIL() << "served without a positioner";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("positioner: parallel"), std::string::npos) << e.what();
  }
}

}  // namespace gcs2_hexapod_test
}  // namespace mc::twins
