#pragma once
/// @file
/// What crosses from the real-time loop to the microscope camera, and what the camera produces
/// (images never enter the loop: docs/architecture.md):
///
///   loop (every tick a frame is due) --SceneSnapshot (POD)--> SPSC ring --> camera thread
///   camera thread: FrameSource -> Image -> JPEG -> CameraFrame -> sinks (console, MCAP, DDS)
///
/// A SceneSnapshot is plain data of fixed size, copied into a preallocated ring: the loop never
/// allocates, locks or waits for the camera. A FrameSource is what makes pixels: the image
/// formation of vision/ rendering the snapshot (the simulated camera), or a real camera
/// grabbing its own (devices/opencv_camera.cc), chosen by the driver registry.

#include <cstdint>
#include <string>
#include <vector>

namespace mc::devices {

/// The scene at one instant of the loop: what a renderer needs to form the image, what a real
/// camera's frame is stamped with. World frame (the telemetry's), SI units.
struct SceneSnapshot {
  double t_s = 0.0;                  ///< loop time of the instant (a frame's mid-exposure)
  std::int64_t steady_ns = 0;        ///< steady clock when the loop took it (maps loop to wall time)
  double tool_m[3] = {};             ///< the gripper's point (finger tips), measured stage position
  double tool_velocity_m_s[3] = {};  ///< its velocity (motion blur over the exposure)
  double gripper_opening_m = 0.0;    ///< distance between the finger tips
  double tool_yaw_rad = 0.0;         ///< the fingers' yaw (the rotary axis under the gripper)
  /// The fingers' common-mode bend (x, y): the tips are seen at tool_m plus this (a lateral
  /// contact force on them: force by vision's contact force).
  double finger_deflection_m[2] = {};
  /// The opening the gripper's drive puts its fingers at without a load (Gripper::free_opening_m;
  /// NaN: the drive has no model of it): force by vision's reference.
  double gripper_free_opening_m = 0.0;
  bool has_part = false;  ///< the pick-and-place's part
  double part_m[3] = {};  ///< part centre
  double part_velocity_m_s[3] = {};
  int part_phase = 0;         ///< microworld::PartPhase
  double part_yaw_rad = 0.0;  ///< the part's orientation (the rotary axis turns it)
  /// The substrate carried by the parallel positioner (devices/carried_seat.h): how far its top
  /// plate has moved (x, y) and turned about the vertical from home; the hole and the scene's
  /// other parts ride on it. Zero without a positioner.
  double seat_m[2] = {};
  double seat_yaw_rad = 0.0;
  bool has_beads = false;  ///< the optical-trap scene's beads
  double probe_bead_m[3] = {};
  double obstacle_bead_m[2] = {};
  double focus_z_m = 0.0;   ///< height of the focal plane above the substrate (focus drive)
  int objective = 0;        ///< index of the objective in the optical path (turret)
  double exposure_s = 0.0;  ///< the camera's settings for this frame
  double gain = 1.0;
};

/// An image as the sensor gives it: rows top to bottom, pixels left to right, 1 (mono) or 3
/// (RGB) channels; 8-bit samples in one byte, deeper ones (10-16 bit) in two (little-endian).
struct Image {
  int width = 0;
  int height = 0;
  int channels = 1;
  int bit_depth = 8;
  std::vector<std::uint8_t> data;  ///< height * width * channels * bytes_per_sample()

  int bytes_per_sample() const { return bit_depth > 8 ? 2 : 1; }
  std::size_t size_bytes() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
           static_cast<std::size_t>(channels) * static_cast<std::size_t>(bytes_per_sample());
  }
  /// Sizes `data` (allocates only when it grows).
  void resize(int w, int h, int c, int bits) {
    width = w, height = h, channels = c, bit_depth = bits;
    data.resize(size_bytes());
  }
};

/// A frame out of the camera: the image, its JPEG, and the state it was taken in.
struct CameraFrame {
  std::uint64_t sequence = 0;  ///< frames delivered by this camera (gaps: frames lost)
  double t_mid_s = 0.0;        ///< loop time at mid-exposure
  double exposure_s = 0.0;
  double gain = 1.0;
  int objective = 0;           ///< turret position
  std::string objective_name;  ///< e.g. "10x"
  double magnification = 1.0;
  double working_distance_m = 0.0;      ///< the objective's
  double m_per_px = 0.0;                ///< object-side pixel size: pixel pitch / magnification
  double focus_z_m = 0.0;               ///< focal plane height
  double view_center_m[2] = {};         ///< world x, y at the image's centre (the microscope's axis)
  double tool_m[3] = {};                ///< where the gripper's point was
  double gripper_opening_m = 0.0;       ///< the gripper's opening (its own sensor) at the frame
  double gripper_free_opening_m = 0.0;  ///< ... and its drive's unloaded opening (SceneSnapshot's)
  double tool_yaw_rad = 0.0;            ///< the fingers' yaw (the rotary axis) at the frame
  Image image;
  std::vector<std::uint8_t> jpeg;
  double capture_s = 0.0;  ///< time to form or grab the image (wall)
  double encode_s = 0.0;   ///< time to encode the JPEG (wall)
  /// From the loop's snapshot of the scene to the JPEG (wall; rendered frames only, else 0).
  double latency_s = 0.0;
};

}  // namespace mc::devices
