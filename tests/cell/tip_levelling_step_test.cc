// The cell's first step on a PiezoGripper: the tips levelled by touch on a clear patch before the
// pick, then the insertion as before.
#include "microcobot/cell/tip_levelling_step.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "microcobot/cell/cell_run.h"
#include "microcobot/core/error.h"

namespace mc::cell {
namespace {

TEST(TipLevellingStep, TheCellLevelsMisalignedTipsToWithinAMicrometreBeforeThePickAndThePartsGoIn) {
  // Seed 29: not the seed the step was tried on (5; docs/cell.md).
  AssemblyBatchParams scene;
  scene.parts = 2;
  scene.seed = 29;
  scene.max_tip_misalignment_m = 30e-6;
  const auto jobs = assembly_jobs(scene);
  CellRunParams p;
  p.level_tips.mode = "on";
  for (const AssemblyJob& job : jobs) {
    const CycleResult r = run_cycle(job, p, platform::PlatformConfig{});
    std::printf("part %d: %s; tips %.2f -> %.3f um in %.1f s\n", r.index, r.verdict.c_str(),
                1e6 * r.tip_misalignment_before_m, 1e6 * r.tip_misalignment_after_m, r.level_tips_s);
    EXPECT_NEAR(r.tip_misalignment_before_m, job.world.gripper.tip_misalignment_m, 1e-9);
    EXPECT_TRUE(r.tips_levelled);
    EXPECT_LT(std::abs(r.tip_misalignment_after_m), 1e-6);
    EXPECT_TRUE(r.success) << r.verdict;
    EXPECT_TRUE(r.ended_holding);
    EXPECT_EQ(r.grip_violations + r.contact_violations, 0);
  }
}

TEST(TipLevellingStep, AProcedureThePlatformStopsEndsTheCycleFailedAndHolding) {
  // The patch too high for the procedure to find the substrate within its travel.
  AssemblyBatchParams scene;
  scene.parts = 1;
  scene.max_tip_misalignment_m = 20e-6;
  CellRunParams p;
  p.level_tips.mode = "on";
  platform::PlatformConfig config;
  config.alignment.max_travel_m = 20e-6;
  const CycleResult r = run_cycle(assembly_jobs(scene)[0], p, config);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.verdict.rfind("levelling the tips failed: ", 0), 0u) << r.verdict;
  EXPECT_TRUE(r.ended_holding);
}

TEST(TipLevellingStep, BadParametersAreRefusedWithTheKeyNamed) {
  TipLevellingStepParams p;
  p.mode = "auto";
  EXPECT_THROW(p.validate(), InvalidParams);
  p = {};
  p.height_m = 1e-3;
  EXPECT_THROW(p.validate(), InvalidParams);
  EXPECT_THROW(TipLevellingStep(TipLevellingStepParams{}, 0.0), InvalidParams);
}

}  // namespace
}  // namespace mc::cell
