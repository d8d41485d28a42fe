#pragma once
/// @file
/// The force-by-vision benchmark (`microcobot vision force`): the gripper
/// closes on a part, its fingers' tips are tracked, and vision::FingerForce's estimate is judged
/// against the simulation's grip force (microworld/piezo_gripper.h: F = k (w - o) / 2 for a part
/// of width w and a free opening o < w).
///
/// What the image shows is the simulation's: the fingers are drawn at the actual opening (the
/// part's width while it is squeezed: each tip deflected by (w - o) / 2 = F / k from where the
/// bender would be), the part between them, the tips in focus at the part's mid-height. One
/// scene: the unloaded pose measured at four openings 15-60 um wider than the part, the fingers
/// closed onto it in steps (the trackers follow), then `loaded_frames` frames at the command o
/// (sensor noise only differs): the estimates' mean against the truth is the bias, their spread
/// the noise, set beside the tips' own tracking noise in the same frames.

#include <cstdint>
#include <string>
#include <vector>

#include "microcobot/vision/finger_force.h"

namespace mc::studies {

struct ForceSceneParams {
  std::string objective = "10x";
  double finger_stiffness_N_m = 50.0;
  double part_width_m = 300e-6;
  double force_N = 5e-3;  ///< the grip wanted: the free opening is w - 2 F / k
  double part_x_m = 0.0, part_y_m = 0.0;
  std::uint64_t texture_seed = 1, seed = 1;
  int width_px = 0, height_px = 0;  ///< 0: the default sensor's
  int loaded_frames = 8;
  vision::TrackerParams tracker;

  void validate() const;
};

struct ForceSceneResult {
  double true_force_N = 0.0;
  double mean_force_N = 0.0;      ///< mean of the frames' estimates
  double force_noise_N = 0.0;     ///< their standard deviation
  double tracking_noise_m = 0.0;  ///< rms of the two tips' standard deviations [m]
  double unloaded_residual_px = 0.0;
  double true_deflection_m = 0.0;  ///< per finger, F / k
  std::vector<double> estimates_N;
  std::string loaded_png;  ///< a loaded frame with the tips marked
};

/// Throws InvalidParams (a force the gripper cannot reach: o outside [min, max] opening),
/// InvalidInput (a template outside the frame), ComputationFailed (a tip lost).
ForceSceneResult run_force_scene(const ForceSceneParams& params);

}  // namespace mc::studies
