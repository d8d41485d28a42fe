// `microcobot vision ...`: the microscope camera's image formation: `model` prints an
// objective's optics figures, `render` makes one camera frame of a scene (PNG + the camera state).

#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/params.h"
#include "microcobot/imaging/png_file.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/imaging/tiff_file.h"
#include "microcobot/platform/camera_scene.h"
#include "vision_processing_commands.h"

namespace vision_commands {
namespace {

namespace vs = mc::vision;
namespace pf = mc::platform;
using mc::cli::CommonOptions;

nlohmann::json figures_json(const mc::imaging::ObjectiveParams& o, const mc::imaging::OpticsFigures& f) {
  return {{"objective", o.name},
          {"magnification", f.magnification},
          {"numerical_aperture", f.numerical_aperture},
          {"wavelength_m", o.wavelength_m},
          {"immersion_index", o.immersion_index},
          {"working_distance_m", o.working_distance_m},
          {"resolution_m", f.resolution_m},
          {"dof_m", f.dof_m},
          {"dof_wave_m", f.dof_wave_m},
          {"dof_geometric_m", f.dof_geometric_m},
          {"um_per_px", f.um_per_px},
          {"field_of_view_x_m", f.field_of_view_x_m},
          {"field_of_view_y_m", f.field_of_view_y_m},
          {"psf_sigma_m", f.psf_sigma_m},
          {"psf_fwhm_m", f.psf_fwhm_m},
          {"airy_fwhm_m", f.airy_fwhm_m}};
}

// The objective named by --objective (exit 2 naming the flag and the value).
mc::imaging::ObjectiveParams objective_flag(const std::string& name) {
  try {
    return mc::imaging::objective_by_name(name);
  } catch (const mc::UsageError& e) {
    throw mc::UsageError(std::string("--objective: ") + e.what());
  }
}

// ---- model ------------------------------------------------------------------------------
struct ModelOptions {
  CommonOptions common;
  std::string objective = "20x";
};

void run_model(const ModelOptions& o) {
  const mc::imaging::ObjectiveParams obj = objective_flag(o.objective);
  const mc::imaging::SensorParams sensor;
  const mc::imaging::OpticsFigures f = mc::imaging::optics_figures(obj, sensor);
  mc::cli::emit(o.common, figures_json(obj, f),
                fmt::format("objective {} (M {:g}, NA {:g}, WD {:g} mm, lambda {:g} nm)\n"
                            "resolution 0.61 lambda/NA   {:.3f} um\n"
                            "depth of field              {:.2f} um ({:.2f} wave + {:.2f} geometric)\n"
                            "scale                       {:.4f} um/px\n"
                            "field of view               {:.1f} x {:.1f} um\n"
                            "PSF FWHM (model, Airy)      {:.3f} um, {:.3f} um",
                            obj.name, obj.magnification, obj.numerical_aperture, obj.working_distance_m * 1e3,
                            obj.wavelength_m * 1e9, f.resolution_m * 1e6, f.dof_m * 1e6, f.dof_wave_m * 1e6,
                            f.dof_geometric_m * 1e6, f.um_per_px, f.field_of_view_x_m * 1e6,
                            f.field_of_view_y_m * 1e6, f.psf_fwhm_m * 1e6, f.airy_fwhm_m * 1e6));
}

// ---- render -----------------------------------------------------------------------------
struct RenderOptions {
  CommonOptions common;
  std::string scene = "pick-place";
  std::string objective = "20x";
  double focus_um = 0.0;
  std::optional<double> exposure_ms, gain, view_x_um, view_y_um, tool_x_um, tool_y_um, tool_z_um;
  int bit_depth = 12;
  std::string illumination = "reflected";
  std::uint64_t seed = 1;
  std::uint64_t frame = 0;
  std::string format = "png";
};

void run_render(const RenderOptions& o) {
  if (!o.common.out)
    throw mc::UsageError("--out: required (the directory the frame and its camera state go to)");
  const pf::PlatformConfig config = pf::scene_config(o.scene);
  mc::imaging::CameraParams cam;
  cam.objective = objective_flag(o.objective);
  cam.sensor.bit_depth = o.bit_depth;
  if (o.exposure_ms) cam.sensor.exposure_s = *o.exposure_ms * 1e-3;
  if (o.gain) cam.sensor.gain = *o.gain;
  cam.illumination.mode = o.illumination;
  pf::CameraScenePose pose = pf::initial_pose(config);
  if (o.tool_x_um) pose.tool_x_m = *o.tool_x_um * 1e-6;
  if (o.tool_y_um) pose.tool_y_m = *o.tool_y_um * 1e-6;
  if (o.tool_z_um) pose.tool_z_m = *o.tool_z_um * 1e-6;
  // The microscope looks at the part (the probe bead) unless told where.
  cam.view_center_x_m = o.view_x_um ? *o.view_x_um * 1e-6 : pose.part_x_m;
  cam.view_center_y_m = o.view_y_um ? *o.view_y_um * 1e-6 : pose.part_y_m;
  mc::cli::naming_flags({{"exposure_s", "--exposure-ms"}, {"gain", "--gain"}, {"bit_depth", "--bit-depth"}},
                        [&] { cam.validate(); });
  mc::imaging::SceneSnapshot scene;
  pf::fill_camera_scene(config, pose, scene);
  mc::imaging::Renderer renderer(cam);
  mc::imaging::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = o.focus_um * 1e-6;
  mc::imaging::Frame frame;
  renderer.render(scene, controls, o.seed, o.frame, frame);

  const mc::imaging::OpticsFigures& f = renderer.figures();
  nlohmann::json j = figures_json(cam.objective, f);
  j["scene"] = o.scene;
  j["focus_z_m"] = controls.focus_z_m;
  j["exposure_s"] = controls.exposure_s;
  j["gain"] = controls.gain;
  j["system_gain_dn_per_e"] = cam.sensor.system_gain_dn_per_e();
  j["bit_depth"] = cam.sensor.bit_depth;
  j["width_px"] = cam.sensor.width_px;
  j["height_px"] = cam.sensor.height_px;
  j["pixel_pitch_m"] = cam.sensor.pixel_pitch_m;
  j["illumination"] = cam.illumination.mode;
  j["view_center_m"] = {cam.view_center_x_m, cam.view_center_y_m};
  j["tool_m"] = {pose.tool_x_m, pose.tool_y_m, pose.tool_z_m};
  j["seed"] = o.seed;
  j["frame_index"] = o.frame;
  const std::string image_name = "frame." + o.format;
  j["image"] = image_name;
  // Everything computed before anything is written; each file staged and renamed when complete.
  // A TIFF carries the scale (pixels per cm, object side) and this JSON (ImageJ/Fiji read both).
  const std::string image = o.format == "tiff"
                                ? mc::imaging::encode_tiff(frame, f.um_per_px * 1e-6, j.dump(-1, ' ', true))
                                : mc::imaging::encode_png(frame);
  mc::ensure_writable_dir(*o.common.out);
  mc::write_file_atomic(*o.common.out / image_name, image);
  mc::write_file_atomic(*o.common.out / "camera.json", j.dump(2) + "\n");
  mc::cli::emit(
      o.common, j,
      fmt::format("{} at {}, focus {:g} um: {}x{} {}-bit frame ({:.4f} um/px, DOF {:.2f} um) in {}", o.scene,
                  cam.objective.name, o.focus_um, frame.width, frame.height, frame.bit_depth, f.um_per_px,
                  f.dof_m * 1e6, (*o.common.out / image_name).string()));
}

void add_vision(CLI::App& group) {
  group.require_subcommand(1);
  {
    auto o = std::make_shared<ModelOptions>();
    auto* cmd = group.add_subcommand(
        "model", "An objective's optics figures: resolution, depth of field, scale, field of view");
    cmd->add_option("--objective", o->objective,
                    "Objective of the turret: 2x, 5x, 10x, 20x, 50x (default 20x)");
    cmd->add_flag("--json", o->common.json, "Print a machine-readable JSON summary on stdout");
    cmd->callback([o] { run_model(*o); });
  }
  {
    auto o = std::make_shared<RenderOptions>();
    auto* cmd = group.add_subcommand(
        "render", "One camera frame of a scene: DIR/frame.png (or .tiff) and DIR/camera.json");
    cmd->add_option(
        "--scene", o->scene,
        "pick-place (default), pin-in-hole, optical-trap, or a YAML file of the microworld's keys");
    cmd->add_option("--objective", o->objective, "Objective: 2x, 5x, 10x, 20x, 50x (default 20x)");
    cmd->add_option("--focus-um", o->focus_um, "Focal plane above the substrate [um] (default 0)")
        ->check(mc::cli::Range(-20000.0, 20000.0));
    cmd->add_option("--exposure-ms", o->exposure_ms, "Exposure [ms] (default 10)")
        ->check(mc::cli::Range(1e-3, 10000.0));
    cmd->add_option("--gain", o->gain, "Analog gain; 1 maps the full well to full scale (default 1)")
        ->check(mc::cli::Range(1e-3, 1000.0));
    cmd->add_option("--bit-depth", o->bit_depth, "Bits per pixel, 8 to 16 (default 12; PNG 8- or 16-bit)")
        ->check(CLI::Range(8, 16));
    cmd->add_option("--illumination", o->illumination, "reflected (default) or transmitted brightfield")
        ->check(CLI::IsMember({"reflected", "transmitted"}));
    cmd->add_option("--view-x-um", o->view_x_um, "Stage x at the image centre [um] (default: the part)")
        ->check(mc::cli::Range(-1e5, 1e5));
    cmd->add_option("--view-y-um", o->view_y_um, "Stage y at the image centre [um] (default: the part)")
        ->check(mc::cli::Range(-1e5, 1e5));
    cmd->add_option("--tool-x-um", o->tool_x_um, "Gripper tip x [um] (default: the stage's home)")
        ->check(mc::cli::Range(-1e5, 1e5));
    cmd->add_option("--tool-y-um", o->tool_y_um, "Gripper tip y [um] (default: the stage's home)")
        ->check(mc::cli::Range(-1e5, 1e5));
    cmd->add_option("--tool-z-um", o->tool_z_um, "Gripper tip height [um] (default: the stage's home)")
        ->check(mc::cli::Range(-1e5, 1e5));
    cmd->add_option("--seed", o->seed, "Seed of the sensor noise (default 1)");
    cmd->add_option("--frame", o->frame, "Frame index (the noise of frame k of a seed; default 0)");
    cmd->add_option(
           "--format", o->format,
           "png (default) or tiff (16-bit for frames over 8 bits, with the pixel size and the camera state)")
        ->check(CLI::IsMember({"png", "tiff"}));
    mc::cli::add_output_options(*cmd, o->common);
    cmd->callback([o] { run_render(*o); });
  }
  mc::cli::add_vision_processing(group);
  mc::cli::add_vision_force(group);
  mc::cli::add_vision_servo(group);
  mc::cli::add_vision_pick_place(group);
}

const bool kRegistered = mc::cli::register_group(
    {"vision", "The microscope camera: optics, rendered frames, calibration and tracking", 45, &add_vision});

}  // namespace
}  // namespace vision_commands
