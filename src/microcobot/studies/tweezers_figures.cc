#include "microcobot/studies/tweezers_figures.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace mc::studies {
namespace {

namespace tw = mc::tweezers;
using report::Axis;
using report::Figure;
using report::Report;

std::vector<double> scaled(const std::vector<double>& v, double k) {
  std::vector<double> out(v);
  for (double& x : out) x *= k;
  return out;
}

}  // namespace

void identify_section(Report& rep, const tw::BandwidthIdentResult& r) {
  rep.section(
      "TéléTweez bandwidth identification (section 4.5.2)",
      "PRBS motor torque at 10 kHz, finger-contact acceleration (accelerometer, Fig. 4.24), H1 "
      "estimate by Welch averaging, against the analytic FRF of the 7-DOF model. The dominant mode, "
      "the antiresonance of the cantilever tip and the flat band (within +-3 dB, from 20 Hz) are read "
      "off the estimate (thesis Fig. 4.25: 150 Hz, 390 Hz, 100 Hz).");
  rep.add_result("dominant mode", r.features.mode_Hz, "Hz");
  rep.add_result("antiresonance", r.features.antiresonance_Hz, "Hz");
  rep.add_result("flat band upper edge", r.features.bandwidth_Hz, "Hz");
  std::vector<double> f, h, m;
  for (std::size_t i = 0; i < r.f_Hz.size(); ++i) {
    if (r.f_Hz[i] < 2 || r.f_Hz[i] > 2000) continue;
    f.push_back(r.f_Hz[i]);
    h.push_back(20 * std::log10(r.magnitude[i]));
    m.push_back(20 * std::log10(r.model_magnitude[i]));
  }
  const double top = *std::max_element(h.begin(), h.end()), bottom = *std::min_element(h.begin(), h.end());
  rep.add_figure(
      {"TéléTweez FRF: torque to finger acceleration",
       "H1 estimate (PRBS, 10 kHz) and the model's FRF; vertical markers at the identified mode, "
       "antiresonance and flat-band edge.",
       Axis{"Frequency", "Hz", true},
       Axis{"|a/T|", "dB re 1 m/s^2/(N m)", false},
       {{"H1 estimate", f, h, false},
        {"model", f, m, false},
        {"mode", {r.features.mode_Hz, r.features.mode_Hz}, {bottom, top}, false},
        {"antiresonance", {r.features.antiresonance_Hz, r.features.antiresonance_Hz}, {bottom, top}, false},
        {"flat band edge", {r.features.bandwidth_Hz, r.features.bandwidth_Hz}, {bottom, top}, false}}});
}

Figure cube_figure(const std::string& title, const tw::VirtualCubeResult& bare,
                   const tw::VirtualCubeResult& comp, double k) {
  return {
      title,
      fmt::format("Rendered wall force per tip, K = {:.0f} N/m, without and with the lag compensator.", k),
      Axis{"Time", "s", false},
      Axis{"Wall force", "N", false},
      {{"no compensator", bare.t_s, bare.wall_force_N, false},
       {"lag compensator", comp.t_s, comp.wall_force_N, false}}};
}

void robotic_section(Report& rep, const tw::RoboticModeResult& r, const tw::RoboticModeParams& p) {
  rep.section(
      "Robotic control mode (section 4.3.2.1)",
      fmt::format(
          "The operator pinches; the slave gripper's opening follows the tips' opening scaled by {} and "
          "closes on a {:.0f} um object; its contact force, scaled by {:.0f}, is rendered at the fingers.",
          p.position_scale, p.object_width_m * 1e6, p.force_scale));
  rep.add_result("slave contact force", r.final_slave_force_N * 1e6, "uN");
  rep.add_result("rendered finger force", r.final_rendered_force_N, "N");
  rep.add_figure({"Robotic mode: openings",
                  "Tweezers tip opening (mm) and slave opening (um).",
                  Axis{"Time", "s", false},
                  Axis{"Opening", "mm / um", false},
                  {{"tweezers tips [mm]", r.trace.t_s, scaled(r.trace.master_opening_m, 1e3), false},
                   {"slave jaws [um]", r.trace.t_s, scaled(r.trace.slave_opening_m, 1e6), false}}});
  rep.add_figure({"Robotic mode: forces",
                  "Slave contact force (uN) and force rendered at each finger (mN).",
                  Axis{"Time", "s", false},
                  Axis{"Force", "uN / mN", false},
                  {{"slave contact [uN]", r.trace.t_s, scaled(r.trace.contact_force_N, 1e6), false},
                   {"finger [mN]", r.trace.t_s, scaled(r.trace.finger_force_N, 1e3), false}}});
}

void manual_section(Report& rep, const tw::ManualModeResult& hold, const tw::ManualModeResult& plain,
                    const tw::ManualModeParams& p) {
  rep.section(
      "Manual control mode (section 4.3.2.2)",
      fmt::format("The operator grasps a {:.0f} mm object, then relaxes at {:.1f} s. With the force loop the "
                  "tweezers keep {:.2f} N on it by themselves; a plain tweezers lets it go.",
                  p.object_width_m * 1e3, p.release_s, p.set_force_N));
  rep.add_result("held clamping force", hold.held_force_N, "N");
  rep.add_result("max error after release", hold.held_force_error_N, "N");
  rep.add_figure({"Manual mode: clamping force",
                  "Force on the object, with the force loop and without.",
                  Axis{"Time", "s", false},
                  Axis{"Clamping force", "N", false},
                  {{"force loop", hold.trace.t_s, hold.trace.contact_force_N, false},
                   {"plain tweezers", plain.trace.t_s, plain.trace.contact_force_N, false},
                   {"operator's finger", hold.trace.t_s, hold.trace.finger_force_N, false}}});
}

void tweezers_figures(Report& rep) {
  const tw::TweezersConfig cfg;
  identify_section(rep, tw::identify_bandwidth(cfg.model, cfg.identify));
  // Virtual cube: a stiff wall with and without the compensator, and the sweep.
  auto c = cfg.cube;
  c.stiffness_N_per_m = 16000;
  c.compensator = false;
  const auto bare = tw::simulate_virtual_cube(cfg.model, c);
  c.compensator = true;
  const auto comp = tw::simulate_virtual_cube(cfg.model, c);
  auto s = cfg.cube;
  s.compensator = false;
  const double kb = tw::max_chatter_free_stiffness(cfg.model, s, 100, 1e6, 10);
  s.compensator = true;
  const double kc = tw::max_chatter_free_stiffness(cfg.model, s, 100, 1e6, 10);
  rep.section(
      "Virtual cube without chatter (section 4.5.3)",
      fmt::format(
          "A {:.0f} mm cube between the tips rendered as a spring by a {:.0f} Hz sampled controller "
          "(ZOH) reading the lever strain gauges; lag compensator pole {:.0f} Hz, zero {:.0f} Hz. "
          "Chatter: oscillation rms above {:.0f} % of the mean force, or contact lost, in the last {:.1f} s.",
          cfg.cube.cube_width_m * 1e3, cfg.cube.control_rate_Hz, cfg.cube.lag_pole_Hz, cfg.cube.lag_zero_Hz,
          cfg.cube.chatter_rel_rms * 100, cfg.cube.hold_window_s));
  rep.add_result("max chatter-free stiffness, no compensator", kb, "N/m");
  rep.add_result("max chatter-free stiffness, lag compensator", kc, "N/m");
  rep.add_result("Colgate passivity bound 2b/T",
                 tw::colgate_stiffness_bound(cfg.model, cfg.cube.control_rate_Hz), "N/m");
  rep.add_figure(cube_figure("Virtual cube: wall force at 16 kN/m", bare, comp, 16000));
  robotic_section(rep, tw::simulate_robotic_mode(cfg.model, cfg.robotic), cfg.robotic);
  auto plain = cfg.manual;
  plain.hold = false;
  manual_section(rep, tw::simulate_manual_mode(cfg.model, cfg.manual),
                 tw::simulate_manual_mode(cfg.model, plain), cfg.manual);
}

}  // namespace mc::studies
