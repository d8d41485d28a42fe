#pragma once
/// @file
/// What the camera sees, as plain data: the microworld from the top, in stage metres (x, y in
/// the substrate's plane, z up, 0 on the substrate's surface). A producer (the platform's
/// camera_scene adapter, a test) fills it; the Renderer reads it. Copyable, no platform types;
/// its vectors keep their capacity when refilled, so a camera thread reuses one snapshot.

#include <cstdint>
#include <vector>

namespace mc::imaging {

/// The substrate: a flat surface at z = 0 with a seeded procedural texture (value noise in
/// octaves, fixed to the stage: the same seed shows the same surface).
struct Substrate {
  double reflectance = 0.45;       ///< mean (or transmittance in transmitted light)
  double texture_contrast = 0.15;  ///< rms of the texture relative to the mean
  double texture_grain_m = 2e-6;   ///< finest feature of the texture
  int texture_octaves = 4;         ///< octaves from the grain up (each twice as coarse, amplitude x 1.4)
  std::uint64_t texture_seed = 1;
};

/// An axis-aligned box seen from the top (a part, a pin) or a disc (a round part): its top face.
struct Part {
  double x_m = 0.0, y_m = 0.0;            ///< centre
  double z_top_m = 0.0;                   ///< height of the top face
  double size_x_m = 0.0, size_y_m = 0.0;  ///< box sides; a disc when `disc` (diameter size_x_m)
  bool disc = false;
  double reflectance = 0.8;           ///< top face (brass); in transmitted light parts are opaque
  double vx_m_s = 0.0, vy_m_s = 0.0;  ///< velocity during the exposure (motion blur)
  double angle_rad = 0.0;             ///< a box turned about its centre, counter-clockwise seen from the top
};

/// A hole (a bore into the substrate): dark, its rim at the substrate's surface.
struct Hole {
  double x_m = 0.0, y_m = 0.0;
  double size_x_m = 0.0, size_y_m = 0.0;  ///< square or rectangular opening; disc when `disc`
  bool disc = false;
  double depth_m = 0.0;
  double bottom_reflectance = 0.03;  ///< what comes back out of the bore
  double angle_rad = 0.0;            ///< a box turned about its centre, counter-clockwise seen from the top
};

/// A sphere (a bead) resting or floating: in reflected light a specular highlight where its
/// surface sends light back into the objective's cone and a darker rim; in transmitted light a
/// dark ring around a bright centre (a ball lens).
struct Bead {
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;  ///< centre
  double radius_m = 1e-6;
  double reflectance = 0.9;
  double vx_m_s = 0.0, vy_m_s = 0.0;
};

/// A gripper finger seen from the top: a bar from its tip along +y (away from the part), with
/// a dark outline (its bevelled edges send the light out of the objective). The tip is at
/// z_tip_m; the bar rises by `rise` per metre along its length (an inclined bender).
struct Finger {
  double tip_x_m = 0.0, tip_y_m = 0.0, z_tip_m = 0.0;  ///< centre of the tip's end
  double width_m = 40e-6;                              ///< along x
  double length_m = 2e-3;                              ///< along +y
  double rise = 0.0;                                   ///< dz/dy along the bar
  double reflectance = 0.6;
  double outline_m = 4e-6;  ///< width of the dark edge
  /// The finger turned counter-clockwise (seen from the top) by angle_rad about the pivot: the
  /// gripper's rotary axis through the tool point.
  double angle_rad = 0.0;
  double pivot_x_m = 0.0, pivot_y_m = 0.0;
  double vx_m_s = 0.0, vy_m_s = 0.0;
};

struct SceneSnapshot {
  double t_s = 0.0;  ///< the loop time the snapshot was taken at
  Substrate substrate;
  std::vector<Part> parts;  ///< parts and pins
  std::vector<Hole> holes;
  std::vector<Bead> beads;
  std::vector<Finger> fingers;

  /// Empties the object lists, keeping their capacity.
  void clear_objects() {
    parts.clear();
    holes.clear();
    beads.clear();
    fingers.clear();
  }
};

}  // namespace mc::imaging
