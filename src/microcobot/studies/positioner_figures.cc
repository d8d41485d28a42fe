#include "microcobot/studies/positioner_figures.h"

#include <cmath>
#include <utility>

#include <fmt/format.h>

namespace mc::studies {
namespace {

namespace mm = mc::motion;

constexpr double kDeg = M_PI / 180.0;

// A pose coordinate in the figure's units: translations in mm, rotations in deg.
double display_scale(int axis) { return axis < 3 ? 1e3 : 1.0 / kDeg; }
const char* display_unit(int axis) { return axis < 3 ? "mm" : "deg"; }

// The slice over `a` and `b` (0..5) spanning +-half_a and +-half_b (SI) about `base`.
mm::SliceSpec slice_about(const mm::SmarPodPose& base, int a, int b, double half_a, double half_b, int n) {
  mm::SliceSpec s;
  s.base = base;
  s.axis_a = a;
  s.axis_b = b;
  const auto at = base.as_array();
  s.lo_a = at[static_cast<std::size_t>(a)] - half_a;
  s.hi_a = at[static_cast<std::size_t>(a)] + half_a;
  s.lo_b = at[static_cast<std::size_t>(b)] - half_b;
  s.hi_b = at[static_cast<std::size_t>(b)] + half_b;
  s.n_a = s.n_b = n;
  return s;
}

int reachable_points(const CsvTable& slice) {
  int n = 0;
  for (double code : slice.column("reach")) n += static_cast<int>(code) == 0 ? 1 : 0;
  return n;
}

}  // namespace

report::Figure workspace_slice_figure(const CsvTable& slice, const mm::SliceSpec& s, std::string title,
                                      std::string caption) {
  const auto axis_label = [](int axis) {
    return report::Axis{mm::pose_coordinate_name(axis), display_unit(axis)};
  };
  report::Figure fig{std::move(title), std::move(caption), axis_label(s.axis_a), axis_label(s.axis_b), {}};
  const auto& ca = slice.column(static_cast<std::size_t>(s.axis_a));
  const auto& cb = slice.column(static_cast<std::size_t>(s.axis_b));
  const auto& reach = slice.column("reach");
  for (int code = 0; code <= static_cast<int>(mm::Reach::kJointLimit); ++code) {
    report::Series ser{mm::to_string(static_cast<mm::Reach>(code)), {}, {}, true};
    for (std::size_t row = 0; row < slice.rows(); ++row) {
      if (static_cast<int>(reach[row]) != code) continue;
      ser.x.push_back(ca[row] * display_scale(s.axis_a));
      ser.y.push_back(cb[row] * display_scale(s.axis_b));
    }
    if (!ser.x.empty()) fig.series.push_back(std::move(ser));
  }
  return fig;
}

void positioner_figures(report::Report& r) {
  const mm::ParallelKinematics k;  // the 110.45-size geometry (docs/concepts/parallel-positioner.md)
  const mm::SmarPodPose home;
  r.section("Parallel positioner: workspace (thesis §2.3, Fig. 2.4)",
            "The 6-DOF parallel stick-slip positioner of the SmarPod 110.45 class (three legs, each "
            "two linear positioners in the base plane; docs/concepts/parallel-positioner.md), its "
            "default geometry, the pivot at the platform's centre. A pose is reachable when every leg "
            "closes, the conditioning is above its floor, every positioner is within its stroke and "
            "every passive joint within its limit; a refused pose is marked by the first of these it "
            "fails. The same slices: microcobot positioner workspace --slice x,y and --slice rx,ry "
            "--out DIR.");

  const mm::SliceSpec xy = slice_about(home, 0, 1, 8e-3, 8e-3, 41);
  const CsvTable t_xy = mm::workspace_slice(k, xy);
  const mm::SliceSpec rxry = slice_about(home, 3, 4, 15 * kDeg, 15 * kDeg, 41);
  const CsvTable t_rxry = mm::workspace_slice(k, rxry);
  r.add_result("reachable points, x-y slice (41 x 41, +-8 mm)", reachable_points(t_xy), "");
  r.add_result("reachable points, rx-ry slice (41 x 41, +-15 deg)", reachable_points(t_rxry), "");

  // Each rotation's travel at home and 4 mm off it in x: the ranges narrow off centre.
  const mm::SmarPodPose off{4e-3, 0.0, 0.0, 0.0, 0.0, 0.0};
  for (const auto& [name, at] : {std::pair{"home", home}, std::pair{"x = 4 mm", off}}) {
    for (int axis = 0; axis < 3; ++axis) {
      const mm::RotationRange range = mm::rotation_range(k, at, axis, {});
      const char* n = mm::pose_coordinate_name(3 + axis);
      r.add_result(fmt::format("{} travel at {}: min ({})", n, name, mm::to_string(range.min_reason)),
                   range.min_rad / kDeg, "deg");
      r.add_result(fmt::format("{} travel at {}: max ({})", n, name, mm::to_string(range.max_reason)),
                   range.max_rad / kDeg, "deg");
    }
  }
  r.add_figure(workspace_slice_figure(t_xy, xy, "Reach over x and y at the home height",
                                      "41 x 41 poses, the rotations 0; each refused pose marked by the "
                                      "first check it fails."));
  r.add_figure(workspace_slice_figure(t_rxry, rxry, "Reach over rx and ry at the home position",
                                      "41 x 41 poses about the pivot at the platform's centre, rz 0."));
}

}  // namespace mc::studies
