#pragma once
/// @file
/// The figures of the TéléTweez tweezers (thesis ch. 4): the bandwidth identification, the virtual
/// cube with and without the lag compensator, the robotic and manual modes, and the full report's
/// part on the default configuration.

#include <string>

#include "microcobot/report/report.h"
#include "microcobot/tweezers/config.h"

namespace mc::studies {

/// The identified FRF against the model's, with the mode, antiresonance and flat-band edge
/// (section 4.5.2, Fig. 4.25).
void identify_section(report::Report& rep, const tweezers::BandwidthIdentResult& r);
/// The rendered wall force at stiffness `k`, without and with the lag compensator.
report::Figure cube_figure(const std::string& title, const tweezers::VirtualCubeResult& bare,
                           const tweezers::VirtualCubeResult& comp, double k);
/// The robotic mode (section 4.3.2.1): openings and forces.
void robotic_section(report::Report& rep, const tweezers::RoboticModeResult& r,
                     const tweezers::RoboticModeParams& p);
/// The manual mode (section 4.3.2.2): the clamping force with the force loop and without.
void manual_section(report::Report& rep, const tweezers::ManualModeResult& hold,
                    const tweezers::ManualModeResult& plain, const tweezers::ManualModeParams& p);

/// The tweezers' part of the full report, on the default configuration.
void tweezers_figures(report::Report& rep);

}  // namespace mc::studies
