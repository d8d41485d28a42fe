// microcobot.vision: the microscope camera (issue #27): render() a frame of a scene as an H x W
// numpy array (uint8 for 8-bit frames, else uint16), camera_model() the optics figures. The same
// library calls as `microcobot vision render|model` (vision/, platform/camera_scene).

#include <optional>

#include "common.h"
#include "microcobot/platform/camera_scene.h"
#include "microcobot/vision/renderer.h"

namespace mc::py {
namespace {

using namespace pybind11::literals;

py::dict camera_model(const std::string& objective) {
  const vision::ObjectiveParams o = vision::objective_by_name(objective);
  const vision::OpticsFigures f = vision::optics_figures(o, vision::SensorParams{});
  py::dict d;
  d["objective"] = o.name;
  d["magnification"] = f.magnification;
  d["numerical_aperture"] = f.numerical_aperture;
  d["wavelength_m"] = o.wavelength_m;
  d["working_distance_m"] = o.working_distance_m;
  d["resolution_m"] = f.resolution_m;
  d["dof_m"] = f.dof_m;
  d["dof_wave_m"] = f.dof_wave_m;
  d["dof_geometric_m"] = f.dof_geometric_m;
  d["um_per_px"] = f.um_per_px;
  d["field_of_view_x_m"] = f.field_of_view_x_m;
  d["field_of_view_y_m"] = f.field_of_view_y_m;
  d["psf_fwhm_m"] = f.psf_fwhm_m;
  d["airy_fwhm_m"] = f.airy_fwhm_m;
  return d;
}

py::array render(const std::string& scene, const std::string& objective, double focus_um,
                 std::optional<double> exposure_ms, std::optional<double> gain, int bit_depth,
                 const std::string& illumination, std::uint64_t seed, std::uint64_t frame,
                 std::optional<std::array<double, 3>> tool_um) {
  const platform::PlatformConfig config = platform::scene_config(scene);
  vision::CameraParams cam;
  cam.objective = vision::objective_by_name(objective);
  cam.sensor.bit_depth = bit_depth;
  if (exposure_ms) cam.sensor.exposure_s = *exposure_ms * 1e-3;
  if (gain) cam.sensor.gain = *gain;
  cam.illumination.mode = illumination;
  platform::CameraScenePose pose = platform::initial_pose(config);
  if (tool_um)
    pose.tool_x_m = (*tool_um)[0] * 1e-6, pose.tool_y_m = (*tool_um)[1] * 1e-6,
    pose.tool_z_m = (*tool_um)[2] * 1e-6;
  cam.view_center_x_m = pose.part_x_m;
  cam.view_center_y_m = pose.part_y_m;
  if (!std::isfinite(focus_um)) throw InvalidInput("focus_um: must be finite");
  vision::SceneSnapshot snapshot;
  platform::fill_camera_scene(config, pose, snapshot);
  vision::Renderer renderer(cam);  // validates: ValueError naming the field
  vision::CameraControls controls = renderer.default_controls();
  controls.focus_z_m = focus_um * 1e-6;
  vision::Frame f;
  {
    py::gil_scoped_release release;
    renderer.render(snapshot, controls, seed, frame, f);
  }
  const std::vector<py::ssize_t> shape{f.height, f.width};
  if (f.bit_depth <= 8) {
    py::array_t<std::uint8_t> out(shape);
    auto* d = out.mutable_data();
    for (std::size_t i = 0; i < f.pixels.size(); ++i) d[i] = static_cast<std::uint8_t>(f.pixels[i]);
    return out;
  }
  py::array_t<std::uint16_t> out(shape);
  std::copy(f.pixels.begin(), f.pixels.end(), out.mutable_data());
  return out;
}

}  // namespace

void bind_vision(py::module_& m) {
  m.def("camera_model", &camera_model, "objective"_a = "20x",
        "The optics figures of an objective on the default sensor (SI units): resolution_m (0.61 "
        "lambda/NA), dof_m (lambda n/NA^2 + n e/(M NA)), um_per_px, field_of_view_x_m/_y_m, psf_fwhm_m.");
  m.def(
      "render", &render, "scene"_a = "pick-place", "objective"_a = "20x", "focus_um"_a = 0.0,
      "exposure_ms"_a = py::none(), "gain"_a = py::none(), "bit_depth"_a = 12, "illumination"_a = "reflected",
      "seed"_a = 1, "frame"_a = 0, "tool_um"_a = py::none(),
      "One camera frame of a scene (pick-place, pin-in-hole, optical-trap or a YAML file) seen from the top, "
      "centred on the part: an H x W array, uint8 for 8-bit frames, else uint16. Deterministic in (seed, "
      "frame).");
}

}  // namespace mc::py
