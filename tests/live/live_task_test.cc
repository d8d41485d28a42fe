// The automatic insertion supervised live (`serve --cell`): pausing stops the
// commanded motion at the tick that applies it; taking over is bumpless (the deadman and the
// gripper the console held before are re-taken first) and the task goes on to insert the pin
// after the hand-back, ending with every axis holding; a task that loses its supervisor pauses;
// the loop allocates nothing meanwhile.
#include "microcobot/live/live_platform.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "microcobot/cell/assembly_batch.h"
#include "microcobot/cell/task_io.h"
#include "support/counting_allocator.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

using namespace std::chrono_literals;
using cell::AssemblyTask;
using Status = AssemblyTask::Status;
using Step = AssemblyTask::Step;

std::size_t task_channel(const char* name) { return platform::telemetry_channel_index(name); }

struct TaskSample {
  double t_s = 0.0;
  Eigen::Vector3d target, measured;
  bool engaged = false;
  double gripper_command_m = 0.0;
};

// A live platform with the task on one part (as fast as the machine goes), every telemetry sample
// kept, and a console client in control whose heartbeat (`command`) a thread sends at 50 Hz.
struct TaskRig {
  LiveParams params;
  std::unique_ptr<LivePlatform> live;
  std::mutex mutex;
  std::vector<TaskSample> samples;
  ConsoleCommand command;  // under mutex
  std::atomic<bool> beating{true}, quit{false};
  std::thread heart;

  // `paced`: the loop on the wall clock, the console's 0.2 s heartbeat timeout (the test of the
  // heartbeat's gaps); else as fast as the machine goes, with a 10 s timeout.
  // `camera`: the cell camera's looks (a LiveLooker answers them).
  // `assisted`: the step the operator does under the platform's guidance (the rest automatic).
  // `batch`: the console works through this batch's parts (Next part), from its first.
  // `view_error_m`: the cell camera's view that far from where the cell believes it (per axis).
  explicit TaskRig(bool paced = false, bool camera = false, std::optional<Step> assisted = std::nullopt,
                   std::optional<cell::AssemblyBatchParams> batch_served = std::nullopt,
                   double view_error_m = 0.0) {
    cell::AssemblyBatchParams batch;
    batch.parts = 1;
    batch.seed = 41;
    if (batch_served) batch = *batch_served;
    const std::vector<cell::AssemblyJob> jobs = cell::assembly_jobs(batch);
    const cell::AssemblyJob& job = jobs.front();
    params.paced = paced;
    // Unpaced, loop time runs faster than the 50 Hz heartbeat's wall clock.
    if (!paced) params.command_timeout_s = 10.0;
    params.platform.microworld = "pick-place";
    params.platform.world = job.world;
    params.platform.devices.camera.driver = "none";
    LiveTaskParams tp;
    tp.goal = cell::assembly_goal(job);
    tp.camera.enabled = camera;
    tp.camera.view_error_m = view_error_m;
    if (assisted) tp.autonomy[static_cast<std::size_t>(*assisted)] = cell::AssemblyTask::Autonomy::kAssisted;
    if (batch_served)
      for (const cell::AssemblyJob& j : jobs) tp.parts.push_back({j.index, j.world, cell::assembly_goal(j)});
    params.task = tp;
    live = std::make_unique<LivePlatform>(params);
    samples.reserve(200000);
    const std::size_t tx = task_channel("target_x_m"), mx = task_channel("measured_x_m"),
                      en = task_channel("engaged"), gc = task_channel("gripper_command_m");
    live->start([=, this](const platform::TelemetrySample& s, std::size_t) {
      TaskSample x;
      x.t_s = s[0];
      x.target = {s[tx], s[tx + 1], s[tx + 2]};
      x.measured = {s[mx], s[mx + 1], s[mx + 2]};
      x.engaged = s[en] > 0.5;
      x.gripper_command_m = s[gc];
      std::lock_guard lock(mutex);
      samples.push_back(x);
    });
    live->set_console_in_control(true);
    heart = std::thread([this] {
      while (!quit.load()) {
        if (beating.load()) {
          ConsoleCommand c;
          {
            std::lock_guard lock(mutex);
            c = command;
          }
          live->push_command(c);
        }
        std::this_thread::sleep_for(20ms);
      }
    });
    // Supervised from the first tick of the test: a task started unsupervised pauses at once.
    if (!test::eventually([&] { return live->status().console_fresh; }))
      throw std::runtime_error("the heartbeat never reached the loop");
  }
  // Sets the heartbeat's command and waits until the loop has it (a few heartbeats).
  void hold_command(const ConsoleCommand& c) {
    set_command(c);
    std::this_thread::sleep_for(100ms);
  }
  ~TaskRig() {
    quit.store(true);
    heart.join();
    live->stop();
  }
  void set_command(const ConsoleCommand& c) {
    std::lock_guard lock(mutex);
    command = c;
  }
  LiveTaskStatus task() const { return *live->status().task; }
  bool wait_for(const std::function<bool(const LiveTaskStatus&)>& f, std::chrono::seconds limit = 60s) {
    return test::eventually([&] { return f(task()); }, limit);
  }
  std::vector<TaskSample> copy() {
    std::lock_guard lock(mutex);
    return samples;
  }
  // Waits until the telemetry holds `duration_s` of loop time after now.
  bool run_for(double duration_s) {
    const double t = live->status().t_s + duration_s;
    return test::eventually([&] {
      std::lock_guard lock(mutex);
      return !samples.empty() && samples.back().t_s > t;
    });
  }
};

// The largest change of the commanded position from one 1 ms sample to the next over [from, to).
double largest_step(const std::vector<TaskSample>& s, std::size_t from, std::size_t to) {
  double largest = 0.0;
  for (std::size_t i = from + 1; i < to && i < s.size(); ++i)
    largest = std::max(largest, (s[i].target - s[i - 1].target).norm());
  return largest;
}

TEST(LiveTask, PauseHoldsAtTheTickTakeOverIsBumplessAndTheHandedBackTaskInserts) {
  TaskRig rig;
  EXPECT_EQ(rig.task().status_name(), "idle");
  ASSERT_TRUE(rig.run_for(0.2));
  EXPECT_EQ(rig.copy().back().engaged, false) << "nothing moves before the start";
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kStart));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.step == Step::kTransport; }));
  ASSERT_TRUE(rig.run_for(0.3));  // carrying the pin across at the travel speed

  // Pause: the target stops at the tick that applies it and stays; the stage settles onto it.
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kPause));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kPaused; }));
  ASSERT_TRUE(rig.run_for(0.5));
  std::vector<TaskSample> s = rig.copy();
  std::size_t pause = s.size() - 1;
  while (pause > 0 && !s[pause - 1].engaged) --pause;  // the first sample of the pause
  ASSERT_GT(pause, 2u);
  EXPECT_GT((s[pause - 1].target - s[pause - 2].target).norm(), 0.2e-6) << "moving up to the pause";
  const Eigen::Vector3d held = s[pause].target;
  for (std::size_t i = pause; i < s.size(); ++i) ASSERT_EQ(s[i].target, held) << "at " << s[i].t_s << " s";
  EXPECT_LT((s.back().measured - held).norm(), 2e-6) << "the stage holds at the target";
  const double gripping = s.back().gripper_command_m;

  // Take over while the console holds the deadman and the gripper slider wide open (as a page
  // would before the hand-over): neither counts until re-taken, so nothing moves, the pin stays.
  ConsoleCommand c;
  c.deadman = true;
  c.velocity_m_s = {50e-6, 0, 0};
  c.has_gripper = true;
  c.gripper_opening_m = 600e-6;
  rig.hold_command(c);
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kTakeOver));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kOperator; }));
  ASSERT_TRUE(rig.run_for(0.3));
  s = rig.copy();
  EXPECT_EQ(s.back().target, held) << "a deadman held through the take-over does not move the stage";
  EXPECT_EQ(s.back().gripper_command_m, gripping) << "nor does the slider drop the pin";
  // Released and pressed again, the deadman jogs the stage from where it is, at the jog's speed.
  c.deadman = false;
  rig.hold_command(c);
  const std::size_t jog_from = rig.copy().size();
  c.deadman = true;
  c.has_gripper = false;  // the page leaves the slider alone
  rig.hold_command(c);
  ASSERT_TRUE(rig.run_for(0.4));
  c.deadman = false;
  rig.hold_command(c);
  s = rig.copy();
  EXPECT_GT(s.back().target.x() - held.x(), 10e-6) << "the operator moved the stage";
  EXPECT_LE(largest_step(s, jog_from - 1, s.size()), 50e-6 * 1e-3 * 1.01) << "no step at the take-over";
  EXPECT_EQ(s.back().gripper_command_m, gripping);

  // Hand back: the transport again from where the operator left the stage, then the rest.
  const std::size_t back_from = s.size();
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kHandBack));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.ended; }, 120s));
  const LiveTaskStatus end = rig.task();
  EXPECT_EQ(end.status, Status::kSucceeded) << end.failure;
  EXPECT_EQ(end.inserted, 1) << "the pin is in its bore (the simulation's truth)";
  ASSERT_TRUE(rig.run_for(0.3));
  s = rig.copy();
  std::size_t last_drive = s.size() - 1;
  while (last_drive > back_from && !s[last_drive].engaged) --last_drive;
  EXPECT_LE(largest_step(s, back_from - 1, last_drive + 1),
            cell::AssemblyTaskParams{}.travel_speed_m_s * 1e-3 * 1.01)
      << "no step at the hand-back nor after";
  EXPECT_FALSE(s.back().engaged) << "ended holding";
  EXPECT_LT((s.back().measured - s.back().target).norm(), 1e-6);
}

// An assisted transport (a task file's `steps: {transport: assisted}`): the operator carries the pin
// with the console's joystick and aims 12 um off the bore (within the guide's 25 um capture); the
// platform's guide puts the stage on the bore's axis, the task goes on by itself once it is there,
// and the robot turns and inserts the pin. Without the guide the tool would rest 12 um off, never
// within the step's 0.5 um, and the step would not end.
TEST(LiveTask, AnAssistedTransportGuidesTheOperatorOntoTheBoreAndTheRobotInsertsFromThere) {
  TaskRig rig(false, false, Step::kTransport);
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kStart));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kAssisted; }));
  EXPECT_EQ(rig.task().step, Step::kTransport);
  const Eigen::Vector2d bore = rig.params.task->goal.target_m;
  const Eigen::Vector2d aim = bore + Eigen::Vector2d(8e-6, -9e-6);  // 12 um off, by eye
  const std::vector<TaskSample> before = rig.copy();
  const Eigen::Vector2d from = before.back().measured.head<2>();  // where the transport begins
  const double t0 = before.back().t_s;
  // The person: deadman held, clicking 30 um ahead along the way to the aim at a time (300 um/s),
  // wobbling across it by 8 um at 2 Hz (loop time), then on the aim itself.
  const auto done = [&] { return rig.task().step != Step::kTransport || rig.task().ended; };
  const Eigen::Vector2d along = (bore - from).normalized(), across(-along.y(), along.x());
  const double aim_u = (aim - from).dot(along);
  for (int i = 0; i < 6000 && !done(); ++i) {  // up to a minute on a loaded machine
    const TaskSample at = rig.copy().back();
    const double u = (at.target.head<2>() - from).dot(along);
    const Eigen::Vector2d goal = aim_u - u > 60e-6
                                     ? Eigen::Vector2d(from + (u + 30e-6) * along +
                                                       8e-6 * std::sin(2.0 * M_PI * 2.0 * at.t_s) * across)
                                     : aim;
    ConsoleCommand c;
    c.deadman = true;
    c.has_goal = true;
    c.goal_m = {goal.x(), goal.y(), at.target.z()};
    c.goal_speed_m_s = 300e-6;
    rig.set_command(c);
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_GE(static_cast<int>(rig.task().step), static_cast<int>(Step::kRotate)) << rig.task().status_name();
  std::vector<TaskSample> s = rig.copy();
  EXPECT_LT((s.back().measured.head<2>() - bore).norm(), 1e-6) << "on the bore's axis, not at the aim";
  // Along the way (the guide's level up, 0.6 s in; away from both ends) the commanded position
  // stays on the path from where the transport began to the bore, whatever the wobble.
  double off_path = 0.0;
  int counted = 0;
  for (const TaskSample& x : s) {
    const Eigen::Vector2d p = x.target.head<2>() - from;
    const double u = p.dot(along);
    if (x.t_s < t0 + 0.6 || u < 100e-6 || u > (bore - from).norm() - 100e-6) continue;
    off_path = std::max(off_path, std::abs(p.x() * along.y() - p.y() * along.x()));
    ++counted;
  }
  EXPECT_GT(counted, 100);
  EXPECT_LT(off_path, 1e-6) << "the guidance along the path takes the wobble out";
  ConsoleCommand idle;
  rig.set_command(idle);  // the person lets go: the robot drives
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.ended; }, 120s));
  const LiveTaskStatus end = rig.task();
  EXPECT_EQ(end.status, Status::kSucceeded) << end.failure;
  EXPECT_EQ(end.inserted, 1) << "the pin is in its bore (the simulation's truth)";
}

// An assisted insertion: the operator pushes the console's joystick down with the pin 6 um off the
// bore's axis (more than the bore's 5.3 um of radial clearance: alone, it lands on the rim); the
// guide puts it on the axis and the funnel lets it reach the rim there only. The first contact down
// in the bore ends the step and the robot releases, retracts and verifies.
TEST(LiveTask, AnAssistedInsertionIsGuidedDownTheFunnelIntoTheBore) {
  TaskRig rig(false, false, Step::kInsert);
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kStart));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kAssisted; }, 120s));
  EXPECT_EQ(rig.task().step, Step::kInsert);
  const Eigen::Vector2d bore = rig.params.task->goal.target_m;
  const Eigen::Vector2d aim = bore + Eigen::Vector2d(0.0, 6e-6);
  const auto done = [&] { return rig.task().step != Step::kInsert || rig.task().ended; };
  double lowest_off_axis_z = 1.0;  // the lowest height the stage reached off the axis (> 2 um)
  for (int i = 0; i < 3000 && !done(); ++i) {
    const TaskSample at = rig.copy().back();
    const Eigen::Vector2d e = aim - at.target.head<2>();
    ConsoleCommand c;
    c.deadman = true;
    c.velocity_m_s = {0.0, 0.0, -40e-6};  // down, steadily
    if (e.norm() > 1e-6) {
      const Eigen::Vector2d v = e.normalized() * std::min(100e-6, e.norm() / 0.05);
      c.velocity_m_s[0] = v.x();
      c.velocity_m_s[1] = v.y();
    }
    if ((at.measured.head<2>() - bore).norm() > 2e-6)
      lowest_off_axis_z = std::min(lowest_off_axis_z, at.measured.z());
    rig.set_command(c);
    std::this_thread::sleep_for(10ms);
  }
  rig.set_command(ConsoleCommand{});  // the person lets go
  // Past the insertion (unpaced, the robot may already be releasing or beyond).
  ASSERT_GE(static_cast<int>(rig.task().step), static_cast<int>(Step::kRelease)) << rig.task().status_name();
  const LiveTaskStatus in = rig.task();
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.ended; }, 120s));
  const LiveTaskStatus end = rig.task();
  EXPECT_EQ(end.status, Status::kSucceeded) << end.failure;
  EXPECT_EQ(end.inserted, 1) << "the pin is in its bore (the simulation's truth)";
  EXPECT_EQ(in.search_tries, 0) << "no jam on the rim";
}

// With the cell's camera (`serve --cell --cell-camera`): the task holds while the looker thread
// renders and measures its looks (the target does not move meanwhile), takes each sighting and
// inserts the pin, the camera's verify included, ending with every axis holding.
TEST(LiveTask, WithTheCellCameraTheTaskHoldsForItsLooksAndInserts) {
  TaskRig rig(/*paced=*/false, /*camera=*/true);
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kStart));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kAwaitingLook; }));
  EXPECT_EQ(rig.task().step, Step::kApproach);
  const Eigen::Vector3d before = rig.copy().back().target;
  ASSERT_TRUE(rig.run_for(0.02));
  EXPECT_EQ(rig.copy().back().target, before) << "the stage holds while the camera looks";
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.ended; }, 180s));
  const LiveTaskStatus end = rig.task();
  EXPECT_EQ(end.status, Status::kSucceeded) << end.failure;
  EXPECT_EQ(end.inserted, 1);
  EXPECT_EQ(end.looks, 4);  // the slot, the bore, the pin held and placed
  EXPECT_EQ(end.looks_found, 4);
  EXPECT_EQ(end.search_tries, 0);
  ASSERT_TRUE(rig.run_for(0.3));
  const std::vector<TaskSample> s = rig.copy();
  EXPECT_FALSE(s.back().engaged) << "ended holding";
  EXPECT_LT((s.back().measured - s.back().target).norm(), 1e-6);
}

// The plate's errors live (`serve --cell --cell-camera` on a batch with bore_error_m): the looker
// answers the bore look before the transport (the fourth kind of look: the request word holds it),
// the pin goes in at its first descent, and the verify's look, taken where the task aimed (the bore
// as seen, over 5 um from its drawing), finds it.
TEST(LiveTask, WithTheCellCameraABoreOffItsDrawingIsSeenAndThePinGoesIn) {
  cell::AssemblyBatchParams batch;
  batch.parts = 1;
  batch.seed = 41;
  batch.bore_error_m = 10e-6;
  const cell::AssemblyJob job = cell::assembly_jobs(batch).front();
  ASSERT_GT((job.world.target_m.head<2>() - job.target_m).norm(), 5e-6) << "the case this test is about";
  TaskRig rig(/*paced=*/false, /*camera=*/true, std::nullopt, batch);
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kStart));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.ended; }, 180s));
  const LiveTaskStatus end = rig.task();
  EXPECT_EQ(end.status, Status::kSucceeded) << end.failure;
  EXPECT_EQ(end.inserted, 1);
  EXPECT_EQ(end.looks, 4);
  EXPECT_EQ(end.looks_found, 4);
  EXPECT_EQ(end.search_tries, 0);
}

// The visual servo live: the cell camera's view 8 um off where the cell believes it (per axis), so
// the bore look reports the bore micrometres off; the align looks see the pin against the bore from
// that one pose, the task corrects (a fifth look at least) and the pin goes in at its first descent.
TEST(LiveTask, WithTheCellCameraTheServoAlignsThePinOnItsBoreThroughAnOffView) {
  TaskRig rig(/*paced=*/false, /*camera=*/true, std::nullopt, std::nullopt, /*view_error_m=*/8e-6);
  ASSERT_TRUE(rig.live->push_task_action(TaskAction::kStart));
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.ended; }, 180s));
  const LiveTaskStatus end = rig.task();
  EXPECT_EQ(end.status, Status::kSucceeded) << end.failure;
  EXPECT_EQ(end.inserted, 1);
  EXPECT_GE(end.looks, 5) << "the servo corrected at least once";
  EXPECT_EQ(end.looks_found, end.looks);
  EXPECT_EQ(end.search_tries, 0);
}

TEST(LiveTask, ATaskThatLosesItsSupervisorPausesAndARestartGivesAFreshOne) {
  TaskRig rig(/*paced=*/true);
  rig.live->push_task_action(TaskAction::kStart);
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.step == Step::kDescend; }));
  rig.live->set_console_in_control(false);  // the page released control (or closed)
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kPaused; }));
  EXPECT_TRUE(rig.task().supervisor_lost);
  ASSERT_TRUE(rig.run_for(0.3));
  const auto s = rig.copy();
  EXPECT_FALSE(s.back().engaged);
  EXPECT_EQ(s.back().target, s[s.size() - 200].target) << "held";
  // Back in control, the task stays paused until the operator resumes it.
  rig.live->set_console_in_control(true);
  ASSERT_TRUE(rig.run_for(0.2));
  EXPECT_EQ(rig.task().status, Status::kPaused);
  rig.live->push_task_action(TaskAction::kResume);
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kRunning; }));
  EXPECT_FALSE(rig.task().supervisor_lost);
  // The heartbeat stops for a while (a busy browser): paused while it is away, on by itself when
  // it returns within the gap (1 s after the commands went stale).
  rig.beating.store(false);
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.heartbeat_gap; }));
  EXPECT_EQ(rig.task().status, Status::kPaused);
  EXPECT_FALSE(rig.task().supervisor_lost);
  rig.beating.store(true);
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kRunning; }));
  EXPECT_FALSE(rig.task().heartbeat_gap);
  EXPECT_FALSE(rig.task().supervisor_lost);
  // The operator pauses during a gap: it stays paused when the heartbeat returns.
  rig.beating.store(false);
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.heartbeat_gap; }));
  rig.live->push_task_action(TaskAction::kPause);
  rig.beating.store(true);
  ASSERT_TRUE(rig.run_for(0.5));
  EXPECT_EQ(rig.task().status, Status::kPaused);
  EXPECT_FALSE(rig.task().heartbeat_gap);
  EXPECT_FALSE(rig.task().supervisor_lost);
  rig.live->push_task_action(TaskAction::kResume);
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.status == Status::kRunning; }));
  // Away for longer: the pause latches; the heartbeat's return does not resume it.
  rig.beating.store(false);
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.supervisor_lost; }));
  EXPECT_FALSE(rig.task().heartbeat_gap);
  rig.beating.store(true);
  ASSERT_TRUE(rig.run_for(1.0));
  EXPECT_EQ(rig.task().status, Status::kPaused);

  rig.live->request(ConsoleAction::kRestart);
  ASSERT_TRUE(test::eventually([&] { return rig.live->status().restarts == 1; }));
  EXPECT_EQ(rig.task().status_name(), "idle") << "a new scene, a new cycle";
  EXPECT_EQ(rig.task().step, Step::kApproach);
}

// A batch in the console: Next part rebuilds the scene on the batch's next part (its
// world, its neighbours, its goal) with a fresh task, and the task inserts it among the others;
// after the last part the first comes again. Without a batch the action is refused with one line.
TEST(LiveTask, NextPartWorksThroughAGridLoadEachAmongItsNeighbours) {
  cell::AssemblyBatchParams batch;
  batch.parts = 3;
  batch.seed = 43;
  batch.layout = "grid";
  const std::vector<cell::AssemblyJob> jobs = cell::assembly_jobs(batch);
  TaskRig rig(/*paced=*/false, /*camera=*/false, std::nullopt, batch);
  EXPECT_EQ(rig.task().part, 0);
  EXPECT_EQ(rig.task().parts, 3);
  for (int k = 0; k < 2; ++k) {
    const cell::AssemblyJob& j = jobs[static_cast<std::size_t>(k)];
    const microworld::PickPlaceParams& w = rig.live->scene_world();
    EXPECT_EQ(w.part_side_m, j.world.part_side_m) << "part " << k;
    EXPECT_EQ(w.target_m, j.world.target_m) << "part " << k;
    ASSERT_EQ(w.neighbour_count, 2) << "the load's two others";
    // Part 1's scene holds part 0 placed in its bore (its top a bore's depth lower than standing).
    if (k == 1) {
      EXPECT_EQ(w.neighbours[0].xy_m, jobs[0].target_m);
      EXPECT_NEAR(w.neighbours[0].top_z_m, jobs[0].world.height_m() - jobs[0].world.hole_depth_m, 1e-12);
    }
    ASSERT_TRUE(rig.live->push_task_action(TaskAction::kStart));
    ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.ended; }, 180s));
    EXPECT_EQ(rig.task().status, Status::kSucceeded) << "part " << k << ": " << rig.task().failure;
    EXPECT_EQ(rig.task().inserted, 1) << "part " << k;
    rig.live->request(ConsoleAction::kNextPart);
    ASSERT_TRUE(
        test::eventually([&] { return rig.live->status().restarts == static_cast<std::uint64_t>(k + 1); }));
    EXPECT_EQ(rig.task().part, k + 1);
    EXPECT_EQ(rig.task().status_name(), "idle") << "a new part, a task not started";
  }
  rig.live->request(ConsoleAction::kNextPart);
  ASSERT_TRUE(test::eventually([&] { return rig.live->status().restarts == 3; }));
  EXPECT_EQ(rig.task().part, 0) << "after the last part, the first";
  EXPECT_TRUE(rig.live->status().last_error.empty()) << rig.live->status().last_error;

  TaskRig single;
  single.live->request(ConsoleAction::kNextPart);
  EXPECT_EQ(single.live->status().last_error, "next_part: there is no batch here (serve --cell serves one)");
  EXPECT_EQ(single.task().part, -1);
}

// The camera's looks reach the loop through a ring: it allocates nothing taking them (the looker
// thread renders, and allocates, beside it).
TEST(LiveTask, TheLoopAllocatesNothingWhileTheCameraLooks) {
  TaskRig rig(/*paced=*/false, /*camera=*/true);
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard(rig.live->loop_thread_id());
    rig.live->push_task_action(TaskAction::kStart);
    ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.step == Step::kDescend; }));
    EXPECT_EQ(rig.task().looks, 1);
    ASSERT_TRUE(rig.run_for(0.3));
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
}

TEST(LiveTask, TheLoopAllocatesNothingWhileTheTaskRunsPausesAndIsTakenOver) {
  TaskRig rig;
  rig.live->push_task_action(TaskAction::kStart);
  ASSERT_TRUE(rig.wait_for([](const LiveTaskStatus& st) { return st.step == Step::kDescend; }));
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard(rig.live->loop_thread_id());
    ASSERT_TRUE(rig.run_for(1.0));
    rig.live->push_task_action(TaskAction::kPause);
    ASSERT_TRUE(rig.run_for(0.3));
    rig.live->push_task_action(TaskAction::kResume);
    rig.live->push_task_action(TaskAction::kTakeOver);
    ASSERT_TRUE(rig.run_for(0.3));
    rig.live->push_task_action(TaskAction::kStepDone);
    rig.live->push_task_action(TaskAction::kSkip);
    ASSERT_TRUE(rig.run_for(1.0));
    allocations = guard.allocations();
  }
  EXPECT_EQ(allocations, 0u);
}

}  // namespace
}  // namespace mc::live
