#pragma once
/// @file
/// Image formation (docs/concepts/vision.md, "Image formation"): a scene snapshot seen from the
/// top through the objective onto the sensor.
///
///  1. Radiance: each object's top face (reflectance, or transmittance in transmitted light)
///     rasterised with its exact area coverage of each pixel (pixel integration); beads shaded
///     by the part of their surface that sends light back into the objective's cone; motion
///     blur as the mean of the object's coverage along its path over the exposure.
///  2. Defocus: each object blurred by the Gaussian PSF of its distance to the focal plane
///     (optics.h, DefocusPsf); objects composited from the lowest up, each over what lies below
///     it through its own blurred coverage ("over" of blurred layers). Objects whose blurs are
///     within 15 % of each other are blurred together; wide blurs are computed on a coarser grid.
///  3. Sensor: expected photo-electrons = radiance x illumination x exposure, then shot noise,
///     dark signal, read noise, gain and quantisation (sensor_model.h).
///
/// One Renderer per camera: its buffers are allocated on the first frame and reused; the
/// substrate's texture and its blurred image are cached (per focus). render() is deterministic
/// in (snapshot, controls, seed, frame index). Not thread-safe: one camera thread owns it.

#include <cstdint>
#include <vector>

#include "microcobot/imaging/camera_params.h"
#include "microcobot/imaging/gaussian_blur.h"
#include "microcobot/imaging/optics.h"
#include "microcobot/imaging/scene_snapshot.h"
#include "microcobot/imaging/sensor_model.h"

namespace mc::imaging {

namespace detail {
enum class LayerKind { kHole, kPart, kBead, kFinger };
/// One object (a finger: one segment) at its height, with its blur.
struct Layer {
  LayerKind kind;
  std::size_t index;
  int segment;
  double z_m;
  double sigma_px;
  bool analytic;  ///< a bead smaller than a pixel: its blurred image is drawn exactly
  /// A whole finger (segment -1): its segments blurred one by one, laid over the scene at once.
  bool whole_finger() const noexcept { return kind == LayerKind::kFinger && segment < 0; }
};
}  // namespace detail

/// What the camera's controls are set to for a frame.
struct CameraControls {
  double focus_z_m = 0.0;  ///< height of the focal plane above the substrate
  double exposure_s = 10e-3;
  double gain = 1.0;
};

class Renderer {
 public:
  /// Validates `camera` (throws InvalidParams naming the field).
  explicit Renderer(const CameraParams& camera);

  const CameraParams& camera() const { return camera_; }
  const OpticsFigures& figures() const { return figures_; }
  const DefocusPsf& psf() const { return psf_; }
  /// The sensor's own exposure and gain, focus on the substrate.
  CameraControls default_controls() const;

  /// The optical image: expected photo-electrons per pixel (before the dark signal and noise),
  /// row-major, `width x height`. Valid until the next call.
  const std::vector<float>& render_expected(const SceneSnapshot& scene, const CameraControls& controls);
  /// A full frame: render_expected() then the sensor's read-out with noise from (seed, frame_index).
  void render(const SceneSnapshot& scene, const CameraControls& controls, std::uint64_t seed,
              std::uint64_t frame_index, Frame& out);

  /// Stage point -> continuous pixel coordinates (column u, row v; pixel (i, j) spans
  /// [j - 1/2, j + 1/2] x [i - 1/2, i + 1/2]); rows go down, stage y up.
  double u_of_x(double x_m) const { return (x_m - camera_.view_center_x_m) / pixel_m_ + 0.5 * (width_ - 1); }
  double v_of_y(double y_m) const { return 0.5 * (height_ - 1) - (y_m - camera_.view_center_y_m) / pixel_m_; }

 private:
  using Layer = detail::Layer;
  void render_substrate(const Substrate& s, double sigma_px);
  void draw_point_bead(const Bead& bead, double sigma_px, double exposure_s);
  /// Lays layers [begin, end), one blur, over the image; or, `to_finger`, adds them to the
  /// finger's canvas (coverage and premultiplied radiance summed: a finger's segments partition it).
  void composite_group(const SceneSnapshot& scene, const std::vector<Layer>& layers, std::size_t begin,
                       std::size_t end, double exposure_s, bool to_finger = false);
  /// Finger `index`: each segment at its own blur, summed on the canvas, then over the image.
  void composite_finger(const SceneSnapshot& scene, std::size_t index, double focus_z_m, double exposure_s);

  CameraParams camera_;
  OpticsFigures figures_;
  DefocusPsf psf_;
  SensorModel sensor_;
  int width_, height_;
  double pixel_m_;

  std::vector<float> image_;      ///< radiance, then photo-electrons
  std::vector<float> texture_;    ///< the substrate's radiance, unblurred (with a margin)
  std::vector<float> substrate_;  ///< the substrate blurred at substrate_sigma_px_
  bool texture_valid_ = false;
  Substrate texture_of_{};
  double substrate_sigma_px_ = -1.0;
  std::vector<float> cover_, premult_;          ///< a layer group's coverage and premultiplied radiance
  std::vector<float> obj_cover_, obj_premult_;  ///< one object's, averaged over its motion
  std::vector<float> row_cover_, row_premult_;  ///< a coarse group's rows blended for one image row
  std::vector<int> col_x0_;                     ///< a coarse group's cell column left of each pixel
  std::vector<float> col_tx_;                   ///< and the weight of the one right of it
  std::vector<Layer> layers_;
  std::vector<Layer> finger_layers_;                  ///< one finger's segments
  std::vector<float> finger_cover_, finger_premult_;  ///< a finger's canvas (zero between fingers)
  int canvas_i0_ = 0, canvas_i1_ = -1, canvas_j0_ = 0,
      canvas_j1_ = -1;  ///< the canvas's touched rows, columns
  BlurScratch scratch_;
};

}  // namespace mc::imaging
