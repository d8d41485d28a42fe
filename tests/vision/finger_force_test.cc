// Force by vision: two fingers rendered at a known deflection read back as
// k x deflection; bad input (empty ROI, NaN stiffness, too few unloaded openings, no unloaded
// pose) refused in one line. The benchmark over 1-20 mN is tests/studies/force_by_vision_test.cc.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/imaging/renderer.h"
#include "microcobot/vision/finger_force.h"
#include "tracking_scenes.h"

namespace mc::vision {
namespace finger_force_test {

// Two 40 um fingers whose tips' inner edges are `opening` apart, centred on the view.
struct Fingers {
  imaging::Renderer renderer{testing::small_camera()};
  imaging::Frame frame;
  std::uint64_t index = 0;
  void render(double opening_m) {
    imaging::SceneSnapshot s;
    s.substrate.texture_seed = 5;
    for (int side : {-1, 1}) {
      imaging::Finger f;
      f.tip_x_m = side * 0.5 * (opening_m + f.width_m);
      f.tip_y_m = -20e-6;
      f.length_m = 1e-3;
      s.fingers.push_back(f);
    }
    renderer.render(s, renderer.default_controls(), 3, index++, frame);
  }
  imaging::PixelRoi roi(double x0_m, double x1_m) const {
    const double u0 = renderer.u_of_x(x0_m), u1 = renderer.u_of_x(x1_m);
    const double v0 = renderer.v_of_y(-20e-6 + 30e-6), v1 = renderer.v_of_y(-20e-6 - 12e-6);
    return imaging::PixelRoi{static_cast<int>(std::lround(u0)), static_cast<int>(std::lround(v0)),
                             static_cast<int>(std::lround(u1 - u0)), static_cast<int>(std::lround(v1 - v0))};
  }
};

TEST(FingerForce, ReadsTheDeflectionTimesTheStiffness) {
  Fingers f;
  FingerForceParams p;
  p.finger_stiffness_N_m = 80.0;
  FingerForce force(p);
  const double o0 = 60e-6;
  f.render(o0);
  force.set_templates(f.frame, f.roi(-0.5 * o0 - 20e-6 - 32e-6, -0.5 * o0 - 20e-6),
                      f.roi(0.5 * o0 + 20e-6, 0.5 * o0 + 20e-6 + 32e-6));
  for (double o : {60e-6, 54e-6, 48e-6, 42e-6}) {
    if (o != o0) f.render(o);
    force.add_unloaded(f.frame, o);
  }
  force.fit_unloaded();
  EXPECT_LT(force.unloaded_residual_px(), 0.05);
  // A 40 um part squeezed by a command of 16 um: each tip 12 um out of its unloaded place.
  f.render(40e-6);
  const FingerForceEstimate e = force.measure(f.frame, 16e-6);
  ASSERT_TRUE(e.found);
  EXPECT_NEAR(e.deflection_left_m, 12e-6, 0.05e-6);
  EXPECT_NEAR(e.deflection_right_m, 12e-6, 0.05e-6);
  EXPECT_NEAR(e.grip_force_N, 80.0 * 12e-6, 0.02 * 80.0 * 12e-6);
  // Nothing squeezed: no force.
  f.render(36e-6);
  EXPECT_NEAR(force.measure(f.frame, 36e-6).grip_force_N, 0.0, 80.0 * 0.05e-6);
}

TEST(FingerForce, BadInputIsRefusedInOneLine) {
  FingerForceParams p;
  p.finger_stiffness_N_m = std::numeric_limits<double>::quiet_NaN();
  try {
    FingerForce bad(p);
    FAIL() << "a NaN stiffness was accepted";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("finger_stiffness_N_m"), std::string::npos) << e.what();
  }
  Fingers f;
  f.render(60e-6);
  FingerForce force;
  try {
    force.set_templates(f.frame, imaging::PixelRoi{10, 10, 0, 0}, f.roi(50e-6, 82e-6));
    FAIL() << "an empty ROI was accepted";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("left finger"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(force.set_templates(f.frame, f.roi(-82e-6, -50e-6), imaging::PixelRoi{300, 10, 64, 64}),
               InvalidInput);
  force.set_templates(f.frame, f.roi(-82e-6, -50e-6), f.roi(50e-6, 82e-6));
  EXPECT_THROW(force.measure(f.frame, 50e-6), InvalidInput);  // no unloaded pose
  force.add_unloaded(f.frame, 60e-6);
  EXPECT_THROW(force.fit_unloaded(), InvalidInput);  // one opening
  EXPECT_THROW(force.add_unloaded(f.frame, std::numeric_limits<double>::quiet_NaN()), InvalidInput);
}

}  // namespace finger_force_test
}  // namespace mc::vision
