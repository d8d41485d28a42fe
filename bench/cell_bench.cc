// The assembly cell's speed (goal: the headless cell simulates >= 10x real time per
// core without image rendering, and states its figure with vision in the loop). One automated
// cycle (the robot's AssemblyTask on a fresh simulated platform, as `microcobot cell run --mode
// auto` runs it) per iteration, on parts of a batch no parameter was chosen on (seed 7001).
// Counters: simulated seconds over the thread's CPU seconds (per core: what the goal asks, and
// what a loaded machine does not change much) and over wall seconds.
//   BM_CellAutoCycle             the cycle, its platform's construction included
//   BM_CellAutoCycleLoopOnly     the same, construction excluded (the loop's own rate)
//   BM_CellAutoCycleWithCamera   the cycle with a camera frame rendered at the sensor's frame
//                                rate (30 Hz, 1280x1024, 10x) from the simulation's pose, on the
//                                same thread: what vision in the loop costs
#include <benchmark/benchmark.h>

#include <time.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "microcobot/cell/cell_run.h"
#include "microcobot/devices/simulated_gripper.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/imaging/scene_snapshot.h"
#include "microcobot/imaging/sensor_model.h"
#include "microcobot/platform/camera_scene.h"

namespace {

namespace cl = mc::cell;
namespace pf = mc::platform;
namespace vs = mc::vision;

double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

const std::vector<cl::AssemblyJob>& bench_jobs() {
  static const std::vector<cl::AssemblyJob> jobs = [] {
    cl::AssemblyBatchParams p;
    p.parts = 8;
    p.seed = 7001;
    return cl::assembly_jobs(p);
  }();
  return jobs;
}

// Renders a frame of the cycle's scene every frame period of simulated time.
class CameraInTheLoop {
 public:
  explicit CameraInTheLoop(const cl::AssemblyJob& job) : renderer_(camera(job)) {
    controls_ = renderer_.default_controls();
  }
  void watch(cl::CellCycle& c) {
    c.set_observer([this, &c](double t_s) {
      if (t_s < next_s_) return;
      next_s_ += 1.0 / renderer_.camera().sensor.frame_rate_Hz;
      const mc::devices::SimulatedGripper& g = *c.platform().simulation().gripper;
      pf::CameraScenePose pose;
      const Eigen::Vector3d tip = g.tip_position_m(), part = g.world_state().part_m;
      pose.tool_x_m = tip.x();
      pose.tool_y_m = tip.y();
      pose.tool_z_m = tip.z();
      pose.opening_m = g.opening_m();
      pose.part_x_m = part.x();
      pose.part_y_m = part.y();
      pose.part_z_m = part.z();
      pf::fill_camera_scene(c.platform().config(), pose, scene_);
      controls_.focus_z_m = tip.z();
      renderer_.render(scene_, controls_, 1, frames_++, frame_);
    });
  }
  std::uint64_t frames() const { return frames_; }

 private:
  static mc::imaging::CameraParams camera(const cl::AssemblyJob& job) {
    mc::imaging::CameraParams cam;
    cam.objective = mc::imaging::objective_by_name("10x");
    cam.view_center_x_m = job.nominal_part_m.x();  // the tray's pin (fixed field of view)
    cam.view_center_y_m = job.nominal_part_m.y();
    return cam;
  }
  mc::imaging::Renderer renderer_;
  mc::imaging::CameraControls controls_;
  mc::imaging::SceneSnapshot scene_;
  mc::imaging::Frame frame_;
  double next_s_ = 0.0;
  std::uint64_t frames_ = 0;
};

enum class Variant { kWhole, kLoopOnly, kWithCamera };

void cell_cycles(benchmark::State& state, Variant variant) {
  const pf::PlatformConfig base;
  cl::CellRunParams params;
  params.mode = "auto";
  double sim_s = 0.0, cpu_s = 0.0, wall_s = 0.0;
  std::uint64_t frames = 0;
  int successes = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const cl::AssemblyJob& job = bench_jobs()[i++ % bench_jobs().size()];
    const auto wall0 = std::chrono::steady_clock::now();
    double cpu0 = thread_cpu_s();
    auto cycle = std::make_unique<cl::CellCycle>(job, params, base);
    std::unique_ptr<CameraInTheLoop> camera;
    if (variant == Variant::kWithCamera) {
      camera = std::make_unique<CameraInTheLoop>(job);
      camera->watch(*cycle);
    }
    auto wall1 = wall0;
    if (variant == Variant::kLoopOnly) {
      cpu0 = thread_cpu_s();
      wall1 = std::chrono::steady_clock::now();
    }
    cycle->run_to_end();
    cpu_s += thread_cpu_s() - cpu0;
    wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - wall1).count();
    const cl::CycleResult r = cycle->result();
    sim_s += r.cycle_s;
    successes += r.success ? 1 : 0;
    if (camera) frames += camera->frames();
  }
  state.counters["sim_over_cpu"] = sim_s / cpu_s;
  state.counters["sim_over_wall"] = sim_s / wall_s;
  state.counters["simulated_s"] = sim_s;
  state.counters["inserted"] = successes;
  if (variant == Variant::kWithCamera) state.counters["frames"] = static_cast<double>(frames);
}

void BM_CellAutoCycle(benchmark::State& state) { cell_cycles(state, Variant::kWhole); }
void BM_CellAutoCycleLoopOnly(benchmark::State& state) { cell_cycles(state, Variant::kLoopOnly); }
void BM_CellAutoCycleWithCamera(benchmark::State& state) { cell_cycles(state, Variant::kWithCamera); }
BENCHMARK(BM_CellAutoCycle)->Iterations(4)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_CellAutoCycleLoopOnly)->Iterations(4)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_CellAutoCycleWithCamera)->Iterations(2)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
