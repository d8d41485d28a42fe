// Template tracks per second (goal: >= 200 tracks/s of a 128 x 128 template on one core at
// 1280 x 1024): a part's corner under the 10x objective, moving 0.37 px per frame along a
// diagonal, eight pre-rendered frames tracked in turn (the rendering is not timed).
//   BM_Track:           track() around the last position (the steady case)
//   BM_TrackReacquire:  the whole-frame search of a lost target (after an occlusion)
// build/release/bench/tracking_bench --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <vector>

#include "microcobot/imaging/renderer.h"
#include "microcobot/vision/template_tracker.h"

namespace {

namespace vs = mc::vision;

constexpr int kTemplate = 128;
constexpr int kFrames = 8;

struct Frames {
  std::vector<mc::imaging::Frame> frames;
  mc::imaging::Frame first;
  Frames() {
    mc::imaging::CameraParams cam;
    cam.objective = mc::imaging::objective_by_name("10x");
    mc::imaging::Renderer renderer(cam);
    mc::imaging::CameraControls c = renderer.default_controls();
    c.focus_z_m = 100e-6;
    const double px = cam.pixel_size_m();
    const auto scene = [&](double shift_px) {
      mc::imaging::SceneSnapshot s;
      mc::imaging::Part p;
      p.x_m = 150e-6 + shift_px * px;
      p.y_m = -150e-6 - shift_px * px;
      p.size_x_m = p.size_y_m = 300e-6;
      p.z_top_m = 100e-6;
      s.parts.push_back(p);
      return s;
    };
    renderer.render(scene(0.0), c, 1, 0, first);
    frames.resize(kFrames);
    for (int k = 0; k < kFrames; ++k) renderer.render(scene(0.37 * (k + 1)), c, 1, k + 1, frames[k]);
  }
};

const Frames& frames() {
  static const Frames f;
  return f;
}

mc::imaging::PixelRoi roi(const mc::imaging::Frame& f) {
  return {f.width / 2 - kTemplate / 2, f.height / 2 - kTemplate / 2, kTemplate, kTemplate};
}

void BM_Track(benchmark::State& state) {
  const Frames& f = frames();
  vs::TemplateTracker tracker;
  std::size_t k = 0;
  for (auto _ : state) {
    if (k % kFrames == 0) tracker.set_template(f.first, roi(f.first));  // back to the start
    benchmark::DoNotOptimize(tracker.track(f.frames[k % kFrames]));
    ++k;
  }
  state.counters["tracks_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_TrackReacquire(benchmark::State& state) {
  const Frames& f = frames();
  vs::TemplateTracker tracker;
  tracker.set_template(f.first, roi(f.first));
  for (auto _ : state) {
    // Predicted off the frame: the whole-frame search.
    benchmark::DoNotOptimize(tracker.track_near(f.frames[0], -1e4, -1e4));
  }
  state.counters["searches_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_Track)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TrackReacquire)->Unit(benchmark::kMillisecond)->UseRealTime();
