#include "microcobot/stickslip/ident_synthetic.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"

namespace mc::stickslip {

MeasuredRecord measure_sawtooth(const ActuatorModel& model, double amplitude_V, double frequency_Hz,
                                Direction direction, const CampaignPlan& plan, const SensorEffects& sensor) {
  const Waveform w =
      make_waveform(WaveKind::kSawtooth, amplitude_V, frequency_Hz, direction, model.params().drive);
  const double duration = std::max(plan.sawtooth_periods / frequency_Hz, plan.sawtooth_min_s);
  MeasuredRecord r = measure(model, w, duration, plan.sawtooth_fs_Hz, sensor);
  r.source = sawtooth_file_name(amplitude_V, frequency_Hz, direction);
  return r;
}

std::size_t write_campaign(const std::filesystem::path& dir, const StickSlipParams& truth,
                           const CampaignPlan& plan, const SensorEffects& sensor,
                           const std::function<void(std::size_t, std::size_t)>& progress) {
  ensure_writable_dir(dir);
  std::size_t files = 0;
  const std::vector<std::string> note = {
      "synthetic measurement (microcobot identify synth): simulated axis + sensor "
      "effects"};
  {
    StickSlipParams pe = truth;
    pe.slider.attached = false;
    const ActuatorModel m(pe, 1.0 / plan.pe_fs_Hz);
    const Waveform w = make_waveform(WaveKind::kStep, plan.pe_step_V, 1.0, Direction::kForward, pe.drive);
    SensorEffects s = sensor;
    s.seed = sensor.seed + 1;
    write_record(dir / "pe_step.csv",
                 measure(m, w, plan.pe_duration_s, plan.pe_fs_Hz, s, Measured::kPiezo, plan.pe_pre_trigger_s),
                 note);
    ++files;
  }
  const ActuatorModel model(truth);
  {
    // 1 us steps: the scanning-mode transient is the physics being measured; the default step
    // would shift the heavily damped asperity mode by ~1% (docs/concepts/stick-slip.md).
    const ActuatorModel fine(truth, std::min(truth.integrator.dt_s, 1e-6));
    const Waveform w = make_waveform(WaveKind::kStep, plan.step_V, 1.0, Direction::kForward, truth.drive);
    SensorEffects s = sensor;
    s.seed = sensor.seed + 2;
    write_record(dir / "step.csv",
                 measure(fine, w, plan.step_duration_s, plan.step_fs_Hz, s, Measured::kSlider,
                         plan.step_pre_trigger_s),
                 note);
    ++files;
  }
  {
    const Waveform w =
        make_waveform(WaveKind::kSine, plan.sine_V, plan.sine_Hz, Direction::kForward, truth.drive);
    SensorEffects s = sensor;
    s.seed = sensor.seed + 3;
    write_record(dir / "sine.csv", measure(model, w, plan.sine_periods / plan.sine_Hz, plan.sine_fs_Hz, s),
                 note);
    ++files;
  }
  struct Job {
    double a, f;
    Direction d;
  };
  std::vector<Job> jobs;
  for (double a : plan.amplitudes_V) {
    for (double f : plan.frequencies_Hz) {
      for (Direction d : {Direction::kForward, Direction::kBackward}) jobs.push_back({a, f, d});
    }
  }
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex mutex;
  std::exception_ptr error;  // the first failure, rethrown with its own type (and exit code)
  auto worker = [&] {
    for (std::size_t i = next++; i < jobs.size(); i = next++) {
      try {
        SensorEffects s = sensor;
        s.seed = sensor.seed + 100 + i;
        const auto& j = jobs[i];
        const MeasuredRecord r = measure_sawtooth(model, j.a, j.f, j.d, plan, s);
        write_record(dir / r.source, r, note);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
      }
      const std::size_t d = ++done;
      if (progress) {
        const std::lock_guard<std::mutex> lock(mutex);
        progress(d, jobs.size());
      }
    }
  };
  const unsigned threads = std::min<unsigned>(std::max(1u, std::thread::hardware_concurrency()),
                                              static_cast<unsigned>(std::max<std::size_t>(1, jobs.size())));
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return files + jobs.size();
}

}  // namespace mc::stickslip
