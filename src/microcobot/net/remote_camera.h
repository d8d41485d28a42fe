#pragma once
/// @file
/// The slave's microscope as the master process's camera over the network (`serve
/// --role master`): a frame source that reads the slave's images on DDS
/// (camera_image_publisher.h: /microcobot/slave/camera/image_raw/compressed, JPEG) and decodes
/// them, so that the master's console, its recordings and its vision see what the slave's camera
/// sees, not a drawing of the master's own model (which has no part: the microworld is the
/// slave's).
///
/// It grabs at the slave's pace (renders_scene() false): each capture waits up to 100 ms for the
/// next image and decodes the newest one; frames are stamped in the master's loop time on their
/// arrival (minus half the exposure), so the network's delay is part of their age. Their JPEG is
/// passed on as the slave encoded it (decoded once for the console's preview and vision). The reader
/// exists only while somebody looks at the master's frames (idle() deletes it): the slave forms
/// frames only while a reader is matched. The master's focus and objective reach the slave by the
/// microscope's topics (microscope_link.h); its exposure and gain stay the slave's.
///
/// The master's configuration must have the slave's sensor size: a frame of another size faults
/// the camera (and so every device: an operator who cannot see must not drive), naming both.

#include <cstdint>
#include <memory>
#include <vector>

#include <dds/dds.h>

#include "microcobot/devices/camera_device.h"
#include "microcobot/net/participant.h"

namespace mc::net {

class RemoteCameraSource final : public devices::FrameSource {
 public:
  RemoteCameraSource(int domain_id, const NetworkConfig& network);
  ~RemoteCameraSource() override;

  /// Joins the domain (throws InvalidParams / ComputationFailed as Participant does).
  void open(const devices::CameraDeviceParams& params) override;
  void close() override;
  bool renders_scene() const override { return false; }
  /// Throws mc::InvalidInput when a frame does not decode or is not the configured size.
  bool capture(const devices::SceneSnapshot& scene, devices::Image& out) override;
  void idle() override;
  /// The slave's JPEG of the last frame captured, sent on unchanged.
  const std::vector<std::uint8_t>* captured_jpeg() const override { return &jpeg_; }

 private:
  void start_reading();
  void stop_reading();

  int domain_id_;
  NetworkConfig network_;
  devices::CameraDeviceParams params_;
  std::unique_ptr<Participant> participant_;
  dds_entity_t topic_ = 0, reader_ = 0, waitset_ = 0;
  std::vector<std::uint8_t> jpeg_;  // the last frame's, as the slave encoded it
};

}  // namespace mc::net
