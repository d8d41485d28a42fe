// The OpenCV camera driver of a build without OpenCV (CMake's MC_WITH_OPENCV off): the driver is
// not there, and says so. CMake compiles this file or opencv_camera.cc, never both.
#include "microcobot/core/error.h"
#include "microcobot/devices/opencv_camera.h"

namespace mc::devices {

bool opencv_camera_available() { return false; }

std::unique_ptr<FrameSource> make_opencv_camera(const std::string&) {
  throw InvalidParams("devices.camera.driver",
                      "'opencv': this build has no OpenCV (install libopencv-videoio-dev, then cmake "
                      "-DMC_WITH_OPENCV=ON; make test does both)");
}

}  // namespace mc::devices
