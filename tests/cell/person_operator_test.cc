// The simulated person on the simulated platform, alone and with shared
// control: a cycle goes through under the platform's limits, the funnel round the rim
// is never entered under tremor, the person lets go at the end.
#include "microcobot/cell/person_operator.h"

#include <algorithm>

#include <thread>

#include <gtest/gtest.h>

#include "cell/cell_test_support.h"
#include "microcobot/cell/cell_run.h"
#include "microcobot/core/error.h"
#include "support/counting_allocator.h"

namespace mc::cell {
namespace person_operator_test {
namespace {

using test::default_platform;

// A part of a batch none of the defaults were chosen on (they were tuned on seed 5).
AssemblyJob person_job() {
  AssemblyBatchParams p;
  p.parts = 1;
  p.seed = 53;
  return assembly_jobs(p).front();
}

TEST(PersonOperator, WithSharedControlThePersonIsFasterAndThePinNeverMeetsTheRim) {
  const AssemblyJob job = person_job();
  CellRunParams params;
  params.mode = "manual";
  const CycleResult manual = run_cycle(job, params, default_platform());
  params.mode = "assisted";
  CellCycle c(job, params, default_platform());
  // The funnel is a forbidden region: whatever the trembling hand does, the commanded target
  // is never inside it (stage coordinates, where the fixtures live).
  long funnel_ticks = 0;
  double deepest_inside = 0.0, off_axis_in_bore = 0.0;
  // The person plans moves for twice the stage's pace; the platform paces the target (the
  // fixtures' max_speed_m_s) in the plane and along the height stops.
  double fastest_m_s = 0.0, last_t = -1.0;
  Eigen::Vector3d last_target = Eigen::Vector3d::Zero();
  c.set_observer([&](double t) {
    const Eigen::Vector3d& target = c.platform().teleop().slave_target_m;
    if (last_t >= 0.0 && c.platform().teleop().engaged)
      fastest_m_s = std::max(fastest_m_s, (target - last_target).head<2>().norm() / (t - last_t));
    last_t = t;
    last_target = target;
    const auto& f = c.platform().fixtures();
    if (!f.fixtures().funnel) return;
    ++funnel_ticks;
    const Eigen::Vector3d& x = c.platform().teleop().slave_target_m;
    // Above the rim: above the cone. Below it (the pin in its bore): within the bore's radius of
    // the axis, give or take what the contact limit moved it toward the measured tool.
    if (x.z() >= f.fixtures().rim_z_m) {
      deepest_inside = std::max(deepest_inside, f.lowest_z(x.head<2>()) - x.z());
    } else {
      off_axis_in_bore = std::max(
          off_axis_in_bore, (x.head<2>() - f.fixtures().guide_xy_m).norm() - f.fixtures().funnel_radius_m);
    }
  });
  c.run_to_end();
  const CycleResult assisted = c.result();
  for (const CycleResult* r : {&manual, &assisted}) {
    EXPECT_TRUE(r->success) << r->mode << ": " << r->verdict;
    EXPECT_EQ(r->grip_violations + r->contact_violations, 0) << r->mode;
    EXPECT_TRUE(r->ended_holding) << r->mode;  // the person let go: the stage holds
    EXPECT_GT(r->submovements, 3) << r->mode;
  }
  EXPECT_GT(funnel_ticks, 1000);
  EXPECT_LE(deepest_inside, 1e-12);
  EXPECT_LE(off_axis_in_bore, 1e-12);
  EXPECT_EQ(assisted.search_tries, 0);  // the pin never landed on the rim
  EXPECT_LT(assisted.cycle_s, manual.cycle_s);
  EXPECT_LE(assisted.clutches, manual.clutches);
  EXPECT_LE(fastest_m_s, c.platform().config().teleop.fixtures.max_speed_m_s * 1.001);
  EXPECT_GT(fastest_m_s, 0.9 * c.platform().config().teleop.fixtures.max_speed_m_s);  // paced, not slow
  using Step = AssemblyTask::Step;
  const auto in = [](const CycleResult& r, Step s) { return r.step_s[static_cast<std::size_t>(s)]; };
  EXPECT_LT(in(assisted, Step::kTransport), in(manual, Step::kTransport));
  // Where the time went adds up to the cycle.
  for (const CycleResult* r : {&manual, &assisted}) {
    double sum = 0.0;
    for (const double s : r->step_s) sum += s;
    EXPECT_NEAR(sum, r->cycle_s, 2e-3) << r->mode;
  }
  std::printf("seed 53: manual %.1f s, %.2f um; assisted %.1f s, %.2f um\n", manual.cycle_s,
              1e6 * manual.placement_error_m, assisted.cycle_s, 1e6 * assisted.placement_error_m);
}

TEST(PersonOperator, TheConsoleJoystickDoesTheSameCycle) {
  CellRunParams params;
  params.mode = "manual";
  params.person.master = "console";
  const CycleResult r = run_cycle(person_job(), params, default_platform());
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_EQ(r.master, "console");
  EXPECT_EQ(r.clutches, 0);  // a rate control has no workspace to index
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
}

// The console's click-to-go (master click): the person moves in the plane only by clicks (the
// console's input carries a goal and no x-y rate), the platform's closed loop takes the stage
// there, and the cycle goes through under the limits, each click on a point the stage then
// reaches. Shared control with clicks is refused naming the key.
TEST(PersonOperator, TheConsolesClickToGoDoesTheSameCycleByClicks) {
  CellRunParams params;
  params.mode = "manual";
  params.person.master = "click";
  CellCycle c(person_job(), params, default_platform());
  int goal_ticks = 0, rate_ticks = 0;
  c.set_observer([&](double) {
    const teleop::ConsoleInput& in = c.platform().console_input();
    if (in.has_goal) ++goal_ticks;
    if (in.velocity_m_s.head<2>().norm() > 0.0) ++rate_ticks;
  });
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_EQ(r.master, "click");
  EXPECT_GT(goal_ticks, 1000) << "the plane by clicks";
  EXPECT_EQ(rate_ticks, 0) << "no x-y rate from a person who clicks";
  EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
  EXPECT_TRUE(r.ended_holding);
  params.mode = "assisted";
  try {
    params.validate();
    ADD_FAILURE() << "assisted click-to-go accepted";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("person.master"), std::string::npos) << e.what();
  }
}

// The person aims the tips a press below the height where the pin would bottom, judged by eye
// (z_tolerance_m: the depth of field). When the pin was taken a little high in the fingers, the
// hand arrives within that tolerance with the pin a micrometre short of the bore's floor: no
// contact to feel, and nothing left to aim at. The person sees the pin go no lower, well into its
// bore, and lets go (part 9 of seed 4111; waiting there would last until the step's timeout).
TEST(PersonOperator, APinThatStopsShortOfTheFloorUnfeltIsReleased) {
  AssemblyBatchParams batch;
  batch.parts = 10;
  batch.seed = 4111;
  CellRunParams params;
  params.mode = "manual";
  CellCycle c(assembly_jobs(batch).at(9), params, default_platform());
  double felt_in_insert = 0.0;
  c.set_observer([&](double) {
    if (c.person()->step() == AssemblyTask::Step::kInsert)
      felt_in_insert = std::max(felt_in_insert, c.platform().gripper().contact_force_N().z);
  });
  c.run_to_end();
  const CycleResult r = c.result();
  EXPECT_LT(felt_in_insert, params.person.person.feel_contact_N)
      << "the case this test is about: no floor felt";
  EXPECT_TRUE(r.success) << r.verdict;
  EXPECT_LT(r.cycle_s, 60.0);
  EXPECT_TRUE(r.ended_holding);
}

// The person, the fixtures and the coupling run on the loop: a whole assisted cycle, and a manual
// one by clicks, no allocation.
TEST(PersonOperator, ThePersonAndTheFixturesDoNotAllocateOnTheLoop) {
  for (const auto& [mode, master] : {std::pair{"assisted", "haptic"}, std::pair{"manual", "click"}}) {
    CellRunParams params;
    params.mode = mode;
    params.person.master = master;
    CellCycle c(person_job(), params, default_platform());
    c.platform().loop().run_for(1000);  // warm-up: 0.1 s of base ticks
    std::size_t allocations = 0;
    {
      // This thread's only: run_for() ticks the loop here, while the cell's other threads (its
      // camera's) may allocate as they please.
      mc::test::AllocationGuard guard(std::this_thread::get_id());
      c.platform().loop().run_for(400000);  // 40 s: every step of the cycle
      allocations = guard.allocations();
    }
    EXPECT_EQ(allocations, 0u) << mode << ", " << master;
    EXPECT_TRUE(c.person()->done()) << mode << ", " << master << ": in step "
                                    << AssemblyTask::name(c.person()->step());
  }
}

TEST(PersonOperator, BadParametersAreNamed) {
  CellRunParams params;
  params.mode = "manual";
  params.person.master = "joystick";
  try {
    params.validate();
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("joystick"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace person_operator_test
}  // namespace mc::cell
