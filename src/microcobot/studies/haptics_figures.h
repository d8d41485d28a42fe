#pragma once
/// @file
/// The figures of the dual-stage haptic interface (thesis ch. 3): the identification of its two
/// channels, the crossover and its 1/3-octave evaluation, the optical-tweezers recordings replayed
/// on the interface, and the full report's part on the default parameters.

#include <string>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/haptics/evaluation.h"
#include "microcobot/haptics/identification.h"
#include "microcobot/microworld/tweezers_scenario.h"
#include "microcobot/report/report.h"

namespace mc::studies {

/// The parameters of the haptic interface's studies (`haptics --params`): the plant, the
/// pipeline and the optical trap.
struct HapticsParams {
  haptics::DualStagePlantParams plant;
  haptics::RenderPipelineParams pipeline;
  microworld::OpticalTrapParams trap;
  template <class V>
  void visit(V& v) {
    v("plant", plant);
    v("pipeline", pipeline);
    v("trap", trap);
  }
  /// Names a violated parameter by its full key (e.g. "pipeline.cutoff_Hz").
  void validate() const {
    in_section("plant", [this] { plant.validate(); });
    in_section("pipeline", [this] { pipeline.validate(); });
    in_section("trap", [this] { trap.validate(); });
  }

 private:
  template <class F>
  static void in_section(const std::string& section, F check) {
    try {
      check();
    } catch (const InvalidParams& e) {
      // The message is "invalid parameter <field>: <constraint>"; keep the constraint.
      const std::string what = e.what();
      const std::string head = "invalid parameter " + e.field() + ": ";
      throw InvalidParams(section + "." + e.field(),
                          what.rfind(head, 0) == 0 ? what.substr(head.size()) : what);
    }
  }
};

/// An optical-tweezers recording replayed through the pipeline and the plant: the handle's
/// acceleration, its Gaussian statistics and the trap's corner frequency, measured and expected.
struct TweezersOut {
  microworld::TweezersRecord rec;
  std::vector<double> accel;
  haptics::GaussianStats stats;
  double corner_Hz = 0.0;
  double expected_corner_Hz = 0.0;
  double peak_time_s = -1.0;
};

/// Simulates `duration` s of scenario `sc` in the trap of `p` and replays the hand force through
/// the pipeline designed from the identified plant (as the demonstrator, section 3.5.2).
TweezersOut run_tweezers_core(const HapticsParams& p, microworld::TweezersScenario sc, double duration);

/// The two channels' FRFs and their models (section 3.4.2, Fig. 3.10-3.11).
void identify_report(report::Report& r, const haptics::IdentificationResult& id);
/// The LR4 crossover and the 1/3-octave evaluation (Fig. 3.8, 3.13).
void evaluate_report(report::Report& r, const haptics::EvaluationResult& ev,
                     const haptics::RenderPipelineParams& rp);
/// The Brownian histogram (Fig. 3.15) or the contact trace (`contact`, Fig. 3.16).
void tweezers_report(report::Report& r, const TweezersOut& t, bool contact);

/// The haptic interface's part of the full report, on the default parameters.
void haptics_figures(report::Report& r);

}  // namespace mc::studies
