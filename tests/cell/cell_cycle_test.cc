// The automatic insertion on the simulated platform: a cycle inserts its pin
// under the platform's limits and ends with every axis holding; pausing stops the commanded
// motion at the next tick; confirming, taking over and handing back never jump; a jam the
// search cannot clear fails and holds.
#include "microcobot/cell/cell_run.h"
#include "microcobot/cell/task_io.h"

#include <gtest/gtest.h>

#include "cell/cell_test_support.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "microcobot/core/error.h"
#include "support/counting_allocator.h"

namespace mc::cell {
namespace {

using test::default_platform;

using Status = AssemblyTask::Status;
using Step = AssemblyTask::Step;

// One pin of a batch seeded apart from the ones the defaults were chosen on (seeds 1-2).
AssemblyJob job(int seed = 41, double clearance_m = 0.0) {
  AssemblyBatchParams p;
  p.parts = 1;
  p.seed = seed;
  if (clearance_m > 0.0) p.min_clearance_m = p.max_clearance_m = clearance_m;
  return assembly_jobs(p).front();
}

Eigen::Vector3d target(platform::Platform& p) { return p.teleop().slave_target_m; }

TEST(CellCycle, TheRobotInsertsAPinUnderTheLimitsAndEndsHolding) {
  CellCycle c(job(), CellRunParams{}, default_platform());
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
  EXPECT_LE(r.peak_grip_N, c.platform().config().world.grip_force_limit_N);
  EXPECT_TRUE(r.ended_holding);
  EXPECT_LE(r.placement_error_m, r.clearance_m * std::sqrt(2.0) + 1e-9) << "inside its bore";
  EXPECT_LT(r.cycle_s, 30.0);
  // The pin was turned to its bore (their orientations differ by more than the fit allows) and
  // sits square in it, to the task's tolerance.
  const AssemblyJob j = job();
  const double turn = microworld::wrap_quarter_turn(j.target_yaw_rad - j.world.part_yaw_rad);
  EXPECT_GT(std::abs(turn), 0.03) << "a part that needed turning";
  const auto& g = *c.platform().simulation().gripper;
  EXPECT_LT(std::abs(g.world().orientation_error_rad(g.world_state())), 1e-3);
  // Holding: the stage stays where it ended, the rotary axis too.
  const Eigen::Vector3d before = target(c.platform());
  const double yaw = c.platform().yaw_rad();
  c.platform().run(0.5);
  EXPECT_LT((target(c.platform()) - before).norm(), 1e-12);
  EXPECT_NEAR(c.platform().yaw_rad(), yaw, 1e-6);
}

// Fingers whose adhesion beats the substrate's (van der Waals 50 times the default's): the
// released pin sticks to a finger and comes up with the retract. The task's own evidence (the
// contact at the bore's depth) said inserted; its verify step looks, fails the task saying why,
// and the cycle ends holding.
TEST(CellCycle, APinThatCameUpWithAFingerFailsTheVerifyStepAndTheCycleEndsHolding) {
  AssemblyJob sticky = job();
  sticky.world.finger_pulloff_N = 100e-6;
  CellCycle c(sticky, CellRunParams{}, default_platform());
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_FALSE(r.success);
  EXPECT_EQ(c.task()->status(), Status::kFailed);
  EXPECT_EQ(c.task()->step(), Step::kVerify);
  EXPECT_NE(r.verdict.find("not down in its bore"), std::string::npos) << r.verdict;
  EXPECT_TRUE(r.ended_holding);
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
  // The same pin with the default fingers passes the look.
  const CycleResult plain = run_cycle(job(), CellRunParams{}, default_platform());
  EXPECT_TRUE(plain.success) << plain.verdict;
  EXPECT_GT(plain.step_s[static_cast<std::size_t>(Step::kVerify)], 0.0);
}

// A flat part on a dry seat of 20 uN (microworld/release.h): opened, the fingers (2 x 16.6 uN) keep
// it and it comes up with the retract; rolled or shaken off, it stays on its seat. Each cycle
// ends holding, the rotary axis too, the burst off.
TEST(CellCycle, AFlatPartOnADrySeatIsLeftThereOnlyByTheReleaseStrategyItsAdhesionNeeds) {
  AssemblyBatchParams p;
  p.parts = 1;
  p.seed = 43;
  p.flat_fraction = 1.0;
  p.flat_seat_min_pulloff_N = p.flat_seat_max_pulloff_N = 20e-6;
  for (const char* release : {"open", "roll", "shake"}) {
    p.release = release;
    const AssemblyJob flat = assembly_jobs(p).front();
    ASSERT_TRUE(flat.flat);
    CellCycle c(flat, CellRunParams{}, default_platform());
    c.run_to_end();
    const CycleResult r = c.result();
    EXPECT_EQ(r.part, "flat");
    EXPECT_EQ(r.release, release);
    EXPECT_TRUE(r.ended_holding) << release;
    EXPECT_EQ(r.grip_violations + r.contact_violations, 0) << release;
    EXPECT_FALSE(c.platform().simulation().gripper->world_state().gripper.shaking) << release;
    const auto phase = c.platform().simulation().gripper->world_state().phase;
    if (std::string(release) == "open") {
      EXPECT_FALSE(r.success);
      EXPECT_EQ(phase, microworld::PartPhase::kStuckToFinger);
      EXPECT_NE(r.verdict.find("not down on its seat"), std::string::npos) << r.verdict;
    } else {
      EXPECT_TRUE(r.success) << release << ": " << r.verdict;
      EXPECT_EQ(r.verdict, "placed and released");
      EXPECT_LE(r.placement_error_m, p.seat_tolerance_m);
      EXPECT_GT(r.step_s[static_cast<std::size_t>(Step::kRelease)], 0.05) << "the strategy takes its time";
    }
  }
}

// A full tray (layout grid): the middle part of a 3 x 3 load, four placed parts and four standing
// pins round it. The robot carries the pin above their tops and never strikes one.
TEST(CellCycle, AmongItsNeighboursTheRobotCarriesThePinOverThemAndStrikesNone) {
  AssemblyBatchParams p;
  p.parts = 9;
  p.seed = 45;
  p.layout = "grid";
  const AssemblyJob middle = assembly_jobs(p)[4];
  ASSERT_EQ(middle.world.neighbour_count, 8);
  const AssemblyGoal goal = assembly_goal(middle);
  EXPECT_EQ(goal.keep_out_count, 8);
  EXPECT_DOUBLE_EQ(goal.tallest_neighbour_m, p.part_height_m);
  CellCycle c(middle, CellRunParams{}, default_platform());
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_EQ(r.neighbour_contacts, 0);
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
  EXPECT_TRUE(r.ended_holding);
}

// Flat parts with a person: the person grasps a plate at half its thickness, sets it
// down until the seat is felt and lets go by its process sheet's strategy: a plate whose seat holds
// less than the fingers (it stays on a finger when they open) is placed once the console's Shake is
// held, or once the dial rolls the fingers; the haptic master has no burst, so its person rolls.
// The scripted watchmaker only opens: a batch with plates is refused for it before its first cycle.
TEST(CellCycle, ThePersonPlacesFlatPartsWithTheirReleaseAndTheScriptedWatchmakerIsRefused) {
  AssemblyBatchParams p;
  p.parts = 1;
  p.seed = 59;
  p.flat_fraction = 1.0;
  AssemblyJob plate = assembly_jobs(p).front();
  plate.world.substrate_pulloff_N = 20e-6;  // under 2 x 16.6 uN: opening alone leaves it on a finger
  plate.world.validate();
  for (const auto& [master, release] : {std::pair{"console", microworld::ReleaseStrategy::kShake},
                                        std::pair{"click", microworld::ReleaseStrategy::kShake},
                                        std::pair{"console", microworld::ReleaseStrategy::kRoll},
                                        std::pair{"haptic", microworld::ReleaseStrategy::kShake}}) {
    AssemblyJob j = plate;
    j.release = release;
    CellRunParams manual;
    manual.mode = "manual";
    manual.person.master = master;
    const CycleResult r = run_cycle(j, manual, default_platform());
    EXPECT_TRUE(r.success) << master << ", " << microworld::name(release) << ": " << r.verdict;
    EXPECT_LT(r.placement_error_m, j.world.seat_tolerance_m);
    EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
    EXPECT_TRUE(r.ended_holding);
  }
  AssemblyJob opened = plate;
  opened.release = microworld::ReleaseStrategy::kOpen;
  CellRunParams console;
  console.mode = "manual";
  console.person.master = "console";
  EXPECT_FALSE(run_cycle(opened, console, default_platform()).success)
      << "opening alone left the plate on its seat: the case above is not the one it is about";

  CellRunParams scripted;
  scripted.mode = "scripted";
  const std::vector<AssemblyJob> pin_then_flat = {job(), plate};
  const auto t0 = std::chrono::steady_clock::now();
  try {
    run_batch(pin_then_flat, scripted, default_platform());
    ADD_FAILURE() << "accepted";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("flat_fraction"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0)
      << "refused before its first cycle";
}

TEST(CellCycle, PauseStopsTheCommandedMotionAtTheNextTickAndResumeGoesOn) {
  CellCycle c(job(), CellRunParams{}, default_platform());
  // Mid-transport the operator pauses for a second, then resumes.
  double paused_at = -1.0, transport_at = -1.0;
  Eigen::Vector3d at_pause, last = target(c.platform());
  double moved_while_paused = 0.0, step_before = 0.0;
  bool was_paused = false;
  c.set_observer([&](double t) {
    const Eigen::Vector3d now = target(c.platform());
    AssemblyTask& task = *c.task();
    if (task.step() == Step::kTransport && transport_at < 0.0) transport_at = t;
    if (transport_at >= 0.0 && paused_at < 0.0 && t >= transport_at + 0.5) {
      step_before = (now - last).norm();  // moving at the travel speed
      task.pause();
      paused_at = t;
    } else if (paused_at >= 0.0 && t <= paused_at + 1e-3 + 1e-9) {
      at_pause = now;  // the tick that sees the pause
      was_paused = task.status() == Status::kPaused;
    } else if (paused_at >= 0.0 && t < paused_at + 1.0) {
      moved_while_paused = std::max(moved_while_paused, (now - at_pause).norm());
    } else if (paused_at >= 0.0 && task.status() == Status::kPaused) {
      task.resume();
    }
    last = now;
  });
  c.run_to_end();
  ASSERT_GE(paused_at, 0.0);
  EXPECT_GT(step_before, 1e-7) << "moving before the pause";
  EXPECT_TRUE(was_paused);
  EXPECT_EQ(moved_while_paused, 0.0) << "the target stopped within one tick and stayed";
  EXPECT_TRUE(c.result().success) << c.result().verdict;
  EXPECT_TRUE(c.result().ended_holding);
}

TEST(CellCycle, ConfirmTakeOverAndHandBackNeverJump) {
  CellCycle c(job(), CellRunParams{}, default_platform());
  c.task()->set_autonomy(Step::kInsert, AssemblyTask::Autonomy::kConfirm);
  // The operator confirms the insertion after half a second, takes over 0.3 s into it and hands
  // back 0.2 s later (the simulated haptic master's deadman is not pressed: the stage holds);
  // the insertion then goes on from where the stage is.
  double waiting_at = -1.0, confirmed_at = -1.0, taken_at = -1.0, largest = 0.0, moved_waiting = 0.0;
  bool saw_operator = false;
  Eigen::Vector3d last = target(c.platform()), waiting;
  c.set_observer([&](double t) {
    AssemblyTask& task = *c.task();
    const Eigen::Vector3d now = target(c.platform());
    largest = std::max(largest, (now - last).norm());
    last = now;
    if (task.status() == Status::kAwaitingConfirm) {
      if (waiting_at < 0.0) waiting_at = t, waiting = now;
      moved_waiting = std::max(moved_waiting, (now - waiting).norm());
      if (t >= waiting_at + 0.5) task.confirm(), confirmed_at = t;
    } else if (confirmed_at >= 0.0 && taken_at < 0.0 && t >= confirmed_at + 0.3) {
      task.take_over();
      taken_at = t;
    } else if (taken_at >= 0.0 && task.status() == Status::kOperator) {
      saw_operator = true;
      if (t >= taken_at + 0.2) task.hand_back();
    }
  });
  c.run_to_end();
  ASSERT_GE(taken_at, 0.0);
  EXPECT_TRUE(saw_operator);
  EXPECT_EQ(moved_waiting, 0.0) << "holds until confirmed";
  // At most the fastest move's step per 1 ms operator tick (every goal move is speed-bounded).
  EXPECT_LE(largest, CellRunParams{}.task.travel_speed_m_s * 1e-3 * 1.001);
  EXPECT_TRUE(c.result().success) << c.result().verdict;
  EXPECT_TRUE(c.result().ended_holding);
}

TEST(CellCycle, AJamTheSearchCannotClearFailsAndHolds) {
  CellRunParams params;
  params.task.search_range_m = 0.0;  // no search: a pin off its bore jams for good
  // A pin far off its slot (|dy| > clearance), by moving its true start.
  AssemblyJob j = job(43, 4e-6);
  j.world.part_start_m.y() = j.nominal_part_m.y() + 12e-6;
  CellCycle c(j, params, default_platform());
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.verdict.find("jammed"), std::string::npos) << r.verdict;
  EXPECT_TRUE(r.ended_holding);
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
  // With the search, the same pin goes in.
  CellCycle searched(j, CellRunParams{}, default_platform());
  searched.run_to_end();
  EXPECT_TRUE(searched.result().success) << searched.result().verdict;
  EXPECT_GE(searched.result().search_tries, 2);
}

// With the cell's camera the pin far off its slot is seen there: grasped centred, it goes in at the
// first descent, where without the camera the search took tries; the looks see it within 0.3 um
// (the least play is 3 um) and the cycle ends holding.
TEST(CellCycle, WithTheCameraAPinOffItsSlotGoesInWithoutASearch) {
  AssemblyJob j = job(43, 4e-6);
  j.world.part_start_m.y() = j.nominal_part_m.y() + 12e-6;
  CellRunParams params;
  params.camera.enabled = true;
  CellCycle c(j, params, default_platform());
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_EQ(r.search_tries, 0);
  EXPECT_EQ(r.looks, 4);  // the slot, the bore, the pin held and placed
  EXPECT_EQ(r.looks_found, 4);
  EXPECT_LT(r.look_error_m, 0.3e-6);
  EXPECT_LT(r.placement_error_m, 1e-6);
  EXPECT_TRUE(r.ended_holding);
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
  const CycleResult blind = run_cycle(j, CellRunParams{}, default_platform());
  EXPECT_TRUE(blind.success) << blind.verdict;
  EXPECT_GE(blind.search_tries, 2);
  EXPECT_EQ(blind.looks, 0);
}

// A bore 12 um off its drawing along x and y (AssemblyBatchParams::bore_error_m): the blind robot,
// told the drawing, jams on the rim and its search along the fingers cannot find the bore; with
// the camera the bore look sees it before the transport, and the pin goes in at the first descent.
TEST(CellCycle, WithTheCameraABoreOffItsDrawingIsSeenAndThePinGoesIn) {
  AssemblyJob j = job(47, 4e-6);
  j.world.target_m.head<2>() += Eigen::Vector2d(12e-6, 12e-6);
  j.world.validate();
  CellRunParams params;
  params.camera.enabled = true;
  const CycleResult r = run_cycle(j, params, default_platform());
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_EQ(r.search_tries, 0);
  EXPECT_EQ(r.looks_found, 4);
  EXPECT_LT(r.look_error_m, 0.3e-6);
  EXPECT_LT(r.placement_error_m, 1e-6);
  EXPECT_TRUE(r.ended_holding);
  const CycleResult blind = run_cycle(j, CellRunParams{}, default_platform());
  EXPECT_FALSE(blind.success) << "the blind robot inserted a pin into a bore 17 um from where it was told";
  EXPECT_TRUE(blind.ended_holding);
  EXPECT_EQ(blind.grip_violations + blind.contact_violations, 0);
}

// The camera's view off where the cell believes it by micrometres (CellCameraParams::view_error_m,
// drawn per station): every position a look reports is off by as much. Look-then-move places the
// tool by the stage's sensors over a bore seen through that error, and the pin lands micrometres
// off its axis (or jams on the rim of a 4 um clearance); the visual servo sees the pin against its
// bore from one camera pose, where the error cancels, and puts it on the axis.
TEST(CellCycle, WithTheServoAnErrorInWhereTheCameraLooksFromCancels) {
  const AssemblyJob j = job(53, 4e-6);
  CellRunParams params;
  params.camera.enabled = true;
  params.camera.view_error_m = 8e-6;
  const CycleResult servo = run_cycle(j, params, default_platform());
  EXPECT_TRUE(servo.success) << servo.verdict;
  EXPECT_EQ(servo.search_tries, 0);
  EXPECT_GE(servo.looks, 5) << "the servo corrected at least once";
  EXPECT_GT(servo.look_error_m, 3e-6) << "the view is off";
  EXPECT_LT(servo.placement_error_m, 1e-6);
  EXPECT_TRUE(servo.ended_holding);
  params.camera.servo = false;
  params.task.step_timeout_s = 8.0;  // a jam's search ends sooner (the test's time)
  const CycleResult moved = run_cycle(j, params, default_platform());
  std::printf("view %.1f um off: servo placement %.2f um (%d looks), look-then-move %.2f um (%s, %d tries)\n",
              1e6 * servo.look_error_m, 1e6 * servo.placement_error_m, servo.looks,
              1e6 * moved.placement_error_m, moved.verdict.c_str(), moved.search_tries);
  EXPECT_TRUE(!moved.success || moved.placement_error_m > 2e-6);
  EXPECT_TRUE(moved.ended_holding);
}

// The pin that sticks to a finger, with the camera: its placed look sees no pin top at the height
// of a pin down in its bore, and the verify fails saying so; the cycle ends holding.
TEST(CellCycle, TheCamerasVerifySeesAPinThatCameUpWithAFinger) {
  AssemblyJob sticky = job();
  sticky.world.finger_pulloff_N = 100e-6;
  CellRunParams params;
  params.camera.enabled = true;
  CellCycle c(sticky, params, default_platform());
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_FALSE(r.success);
  EXPECT_EQ(c.task()->step(), Step::kVerify);
  EXPECT_NE(r.verdict.find("the camera does not see the pin down in its bore"), std::string::npos)
      << r.verdict;
  EXPECT_EQ(r.looks, 4);
  EXPECT_EQ(r.looks_found, 3);
  EXPECT_TRUE(r.ended_holding);
}

// A camera whose field cannot hold the pin (a 64 x 64 sensor) finds nothing: the robot falls back
// to the slot's nominal place and the search, and the verify fails saying why; holding at the end.
TEST(CellCycle, ACameraThatSeesNothingFailsTheVerifySayingWhyAndHolds) {
  CellRunParams params;
  params.camera.enabled = true;
  params.camera.width_px = params.camera.height_px = 64;
  CellCycle c(job(), params, default_platform());
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.looks, 4);
  EXPECT_EQ(r.looks_found, 0);
  EXPECT_NE(r.verdict.find("the bore is not inside the camera's field"), std::string::npos) << r.verdict;
  EXPECT_TRUE(r.ended_holding);
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
}

// The task and the cycle's meter run on the loop (the operator task): they never allocate.
TEST(CellCycle, TheTaskAndItsMeterDoNotAllocateOnTheLoop) {
  CellCycle c(job(), CellRunParams{}, default_platform());
  c.platform().loop().run_for(1000);  // warm-up: 0.1 s of base ticks
  std::size_t allocations = 0;
  {
    mc::test::AllocationGuard guard;
    c.platform().loop().run_for(250000);  // 25 s: every step of the cycle
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_TRUE(c.finished()) << "in step " << AssemblyTask::name(c.task()->step());
}

// A step the operator skips on the platform: the retract, as it starts (the pin is released in
// its bore); the task succeeds from there, without a jump, and ends holding.
TEST(CellCycle, SkippingAStepGoesOnFromWhereTheStageIsWithoutAJump) {
  CellCycle c(job(), CellRunParams{}, default_platform());
  bool skipped = false;
  double largest = 0.0;
  Eigen::Vector3d last = target(c.platform());
  c.set_observer([&](double) {
    const Eigen::Vector3d now = target(c.platform());
    largest = std::max(largest, (now - last).norm());
    last = now;
    if (!skipped && c.task()->step() == Step::kRetract) {
      c.task()->skip();
      skipped = true;
    }
  });
  c.run_to_end();
  EXPECT_TRUE(skipped);
  EXPECT_EQ(c.task()->status(), Status::kSucceeded);
  EXPECT_TRUE(c.result().success) << c.result().verdict;
  EXPECT_TRUE(c.result().ended_holding);
  EXPECT_LE(largest, CellRunParams{}.task.travel_speed_m_s * 1e-3 * 1.001);
}

// Headless, the supervisor confirms a `confirm` step after confirm_delay_s: the cycle is longer by
// about that; a `manual` step has nobody to do it and is refused.
TEST(CellCycle, AConfirmStepCostsTheSupervisorsDelayAndAManualStepIsRefusedHeadless) {
  const CycleResult plain = run_cycle(job(), CellRunParams{}, default_platform());
  CellRunParams confirmed;
  confirmed.confirm_delay_s = 2.0;
  confirmed.autonomy[static_cast<std::size_t>(Step::kInsert)] = AssemblyTask::Autonomy::kConfirm;
  const CycleResult r = run_cycle(job(), confirmed, default_platform());
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_EQ(r.confirmations, 1);
  EXPECT_EQ(plain.confirmations, 0);
  EXPECT_NEAR(r.cycle_s - plain.cycle_s, 2.0, 0.1);

  // A manual step needs the person's console (the TéléTweez would command the held pin's grip from
  // its own levers); an assisted one a person under shared control, which a headless run has not.
  CellRunParams manual;
  manual.autonomy[static_cast<std::size_t>(Step::kGrasp)] = AssemblyTask::Autonomy::kManual;
  for (const auto level : {AssemblyTask::Autonomy::kManual, AssemblyTask::Autonomy::kAssisted}) {
    manual.autonomy[static_cast<std::size_t>(Step::kGrasp)] = level;
    try {
      CellCycle(job(), manual, default_platform());
      ADD_FAILURE() << "a headless " << AssemblyTask::name(level) << " step with the haptic master";
    } catch (const InvalidParams& e) {
      EXPECT_NE(std::string(e.what()).find("steps.grasp"), std::string::npos) << e.what();
    }
  }
}

// A manual step headless (the hand-over): the simulated person takes the task's
// insertion over with the console (joystick, gripper slider), inserts, and hands back once the pin is
// down; the task releases, retracts and verifies. Neither the take-over nor the hand-back jumps: the
// commanded position moves at most the joystick's top speed a tick, the gripper's command while the
// person has it at most the slider's, and the pin the robot grasped stays grasped until the task's
// release.
TEST(CellCycle, AManualStepIsTakenOverByThePersonAndHandedBackWithoutAJump) {
  CellRunParams params;
  params.person.master = "console";
  params.autonomy[static_cast<std::size_t>(Step::kInsert)] = AssemblyTask::Autonomy::kManual;
  CellCycle c(job(), params, default_platform());
  Eigen::Vector3d last = target(c.platform());
  double last_opening = c.platform().teleop().gripper_opening_m, largest = 0.0, largest_opening = 0.0;
  double taken_at = -1.0, handed_at = -1.0, opened_at = -1.0;
  c.set_observer([&](double t) {
    const Eigen::Vector3d now = target(c.platform());
    const double opening = c.platform().teleop().gripper_opening_m;
    largest = std::max(largest, (now - last).norm());
    const AssemblyTask& task = *c.task();
    // The gripper's command while the person has the step (the task's release opens at once after).
    if (task.status() == Status::kOperator)
      largest_opening = std::max(largest_opening, std::abs(opening - last_opening));
    last = now, last_opening = opening;
    if (taken_at < 0.0 && task.status() == Status::kOperator) taken_at = t;
    if (taken_at >= 0.0 && opened_at < 0.0 && c.platform().gripper().grip_force_N() <= 0.0) opened_at = t;
    if (taken_at >= 0.0 && handed_at < 0.0 && task.status() != Status::kOperator) handed_at = t;
  });
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_EQ(r.handovers, 1);
  EXPECT_EQ(r.master, "console");
  EXPECT_GT(r.submovements, 0) << "the person moved";
  ASSERT_GT(taken_at, 0.0);
  ASSERT_GT(handed_at, taken_at);
  EXPECT_GE(opened_at, handed_at) << "the grasped pin held through the person's step";
  EXPECT_GT(r.step_s[static_cast<std::size_t>(Step::kRetract)], 0.0) << "the task went on after";
  const double joystick = c.platform().config().teleop.console_max_speed_m_s;
  std::printf(
      "taken over at %.2f s, handed back at %.2f s; largest step %.3f um a tick (joystick %.3f um), "
      "gripper %.3f um\n",
      taken_at, handed_at, 1e6 * largest, 1e3 * joystick, 1e6 * largest_opening);
  EXPECT_LE(largest, std::max(joystick, params.task.travel_speed_m_s) * 1e-3 * 1.001);
  EXPECT_LE(largest_opening, params.person.slider_m_s * 1e-3 * 1.001 + 1e-12);
  EXPECT_TRUE(r.ended_holding);
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
}

TEST(CellCycle, BadParametersAreRefusedWithTheKeyNamed) {
  CellRunParams p;
  p.mode = "remote";
  EXPECT_THROW(CellCycle(job(), p, default_platform()), InvalidParams);
  p = CellRunParams{};
  p.task.search_step_factor = 2.5;
  try {
    CellCycle(job(), p, default_platform());
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("search_step_factor"), std::string::npos);
  }
}

}  // namespace
}  // namespace mc::cell
