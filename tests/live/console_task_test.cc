// The supervised task through the console server (`serve --cell`): the task_*
// actions on /console/action, their refusals (one line each: no task, no control, not started,
// nothing to confirm), anyone's pause, and the task tree in /platform/status.
#include "microcobot/live/console_server.h"

#include <gtest/gtest.h>

#include "microcobot/cell/assembly_batch.h"
#include "microcobot/cell/task_io.h"
#include "support/console_client.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

using nlohmann::json;

ConsoleServerParams task_server_params(const std::filesystem::path& out) {
  ConsoleServerParams p;
  p.server.port = 0;
  p.out_dir = out;
  return p;
}

LiveParams task_live_params() {
  cell::AssemblyBatchParams batch;
  batch.parts = 1;
  const cell::AssemblyJob job = cell::assembly_jobs(batch).front();
  LiveParams lp;
  lp.platform.microworld = "pick-place";
  lp.platform.world = job.world;
  lp.platform.devices.camera.driver = "none";
  // The test's client sends its commands from the test's one thread, between reads: a long
  // heartbeat timeout keeps a loaded machine's pauses from reading as a lost supervisor.
  lp.command_timeout_s = 10.0;
  LiveTaskParams tp;
  tp.goal = cell::assembly_goal(job);
  tp.autonomy[static_cast<std::size_t>(cell::AssemblyTask::Step::kInsert)] =
      cell::AssemblyTask::Autonomy::kConfirm;
  lp.task = tp;
  return lp;
}

// The latest status with a task in it (subscription `id`), after `pred` holds on it.
json task_status_until(test::Console& c, std::uint32_t id, const std::function<bool(const json&)>& pred) {
  for (int i = 0; i < 60; ++i) {  // 12 s of 5 Hz statuses
    const std::string p = c.next_on(id);
    if (p.empty()) break;
    const json s = json::parse(p);
    if (pred(s.at("task"))) return s.at("task");
  }
  return nullptr;
}

TEST(ConsoleTask, TheTasksActionsAreAnsweredAndItsTreeIsInTheStatus) {
  test::TempDir dir;
  LivePlatform live(task_live_params());
  ConsoleServer server(live, task_server_params(dir.path()));
  server.start();
  test::Console op(server.port()), observer(server.port());

  // Before control: refused, one line.
  ASSERT_TRUE(op.action("task_start"));
  json refused = op.ws.read_status("control");
  EXPECT_NE(refused.value("message", "").find("take control first"), std::string::npos) << refused;
  ASSERT_TRUE(op.action("take_control"));
  ASSERT_FALSE(op.ws.read_status("control").is_null());
  ASSERT_TRUE(op.action("task_pause"));
  refused = op.ws.read_status("task");
  EXPECT_NE(refused.value("message", "").find("not started"), std::string::npos) << refused;

  op.subscribe("/platform/status", 5);
  json task = task_status_until(op, 5, [](const json& t) { return !t.is_null(); });
  ASSERT_FALSE(task.is_null());
  EXPECT_EQ(task.at("status"), "idle");
  ASSERT_EQ(task.at("steps").size(), 11u);  // approach ... retract, verify
  EXPECT_EQ(task.at("steps")[0].at("name"), "approach");
  EXPECT_EQ(task.at("steps")[7].at("name"), "insert");
  EXPECT_EQ(task.at("steps")[7].at("autonomy"), "confirm");
  EXPECT_EQ(task.at("steps")[10].at("name"), "verify");

  // Started, it runs, with the console's heartbeat.
  ASSERT_TRUE(op.command({{"deadman", false}}));
  ASSERT_TRUE(op.action("task_start"));
  task = task_status_until(op, 5, [](const json& t) { return t.at("status") == "running"; });
  ASSERT_FALSE(task.is_null());
  EXPECT_EQ(task.at("step"), "approach");
  EXPECT_EQ(task.at("step_index"), 0);

  // Nothing awaits a confirmation: refused, named.
  ASSERT_TRUE(op.action("task_confirm"));
  refused = op.ws.read_status("task");
  EXPECT_NE(refused.value("message", "").find("confirm"), std::string::npos) << refused;

  // Anyone may pause (it only stops the stage); resuming needs control.
  ASSERT_TRUE(observer.action("task_pause"));
  task = task_status_until(op, 5, [](const json& t) { return t.at("status") == "paused"; });
  ASSERT_FALSE(task.is_null());
  EXPECT_FALSE(task.at("supervisor_lost").get<bool>());
  ASSERT_TRUE(observer.action("task_resume"));
  refused = observer.ws.read_status("control");
  EXPECT_NE(refused.value("message", "").find("take control first"), std::string::npos) << refused;
  ASSERT_TRUE(op.command({{"deadman", false}}));
  ASSERT_TRUE(op.action("task_resume"));
  task = task_status_until(op, 5, [](const json& t) { return t.at("status") == "running"; });
  ASSERT_FALSE(task.is_null());

  // A misspelt action: an error listing the task's.
  ASSERT_TRUE(op.action("task_go"));
  refused = op.ws.read_status("/console/action");
  EXPECT_EQ(refused.value("level", -1), 2);
  EXPECT_NE(refused.value("message", "").find("task_skip"), std::string::npos) << refused;
  server.stop();
}

TEST(ConsoleTask, WithoutATaskItsActionsSaySo) {
  test::TempDir dir;
  LiveParams lp;
  lp.platform.devices.camera.driver = "none";
  LivePlatform live(lp);
  ConsoleServer server(live, task_server_params(dir.path()));
  server.start();
  test::Console op(server.port());
  ASSERT_TRUE(op.action("take_control"));
  ASSERT_FALSE(op.ws.read_status("control").is_null());
  ASSERT_TRUE(op.action("task_start"));
  const json refused = op.ws.read_status("task");
  EXPECT_NE(refused.value("message", "").find("--cell"), std::string::npos) << refused;
  op.subscribe("/platform/status", 5);
  const json s = json::parse(op.next_on(5));
  EXPECT_TRUE(s.at("task").is_null());
  server.stop();
}

}  // namespace
}  // namespace mc::live
