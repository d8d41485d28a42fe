// Camera frames per second at 1280 x 1024 (issue #27: >= 30 fps on one core): the pin-in-hole
// scene with the gripper's fingers over the pin, each objective, sensor noise included.
//   focus fixed:   the blurred substrate comes from the renderer's cache (a steady camera)
//   focus moving:  a new focus every frame (the substrate re-blurred: a focus sweep)
// build/release/bench/vision_bench --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include "microcobot/platform/camera_scene.h"
#include "microcobot/vision/renderer.h"

namespace {

namespace vs = mc::vision;
namespace pf = mc::platform;

const char* kObjectives[] = {"2x", "5x", "10x", "20x", "50x"};

void render_frames(benchmark::State& state, bool moving_focus) {
  pf::PlatformConfig config;
  config.world = mc::microworld::pin_in_hole_scene();
  pf::CameraScenePose pose = pf::initial_pose(config);
  pose.tool_x_m = pose.part_x_m, pose.tool_y_m = pose.part_y_m, pose.tool_z_m = 300e-6;
  pose.opening_m = 260e-6;
  pose.vx_m_s = 50e-6;  // the fingers moving: motion blur on
  vs::SceneSnapshot scene;
  pf::fill_camera_scene(config, pose, scene);
  vs::CameraParams cam;
  cam.objective = vs::objective_by_name(kObjectives[state.range(0)]);
  cam.view_center_x_m = pose.part_x_m + 60e-6;
  vs::Renderer renderer(cam);
  vs::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = 300e-6;
  vs::Frame frame;
  renderer.render(scene, controls, 1, 0, frame);  // the substrate's texture: once per camera
  std::uint64_t index = 1;
  for (auto _ : state) {
    if (moving_focus) controls.focus_z_m = 300e-6 + 1e-7 * static_cast<double>(index % 100);
    renderer.render(scene, controls, 1, index++, frame);
    benchmark::DoNotOptimize(frame.pixels.data());
  }
  state.SetLabel(cam.objective.name);
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_RenderFocusFixed(benchmark::State& state) { render_frames(state, false); }
void BM_RenderFocusMoving(benchmark::State& state) { render_frames(state, true); }

}  // namespace

BENCHMARK(BM_RenderFocusFixed)->DenseRange(0, 4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderFocusMoving)->DenseRange(0, 4)->Unit(benchmark::kMillisecond)->UseRealTime();
