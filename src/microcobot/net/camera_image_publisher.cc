#include "microcobot/net/camera_image_publisher.h"

#include "microcobot/live/camera_messages.h"
#include "ros2_messages.h"

namespace mc::net {

namespace {

// As ROS 2's sensor-data profile: best effort, volatile, keep last 1.
QosPtr sensor_data_qos() {
  QosPtr qos(dds_create_qos());
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 1);
  return qos;
}

}  // namespace

CameraImagePublisher::CameraImagePublisher(int domain_id, const NetworkConfig& network)
    : participant_(domain_id, network),
      writer_(participant_.handle(), sensor_msgs_msg_dds__CompressedImage__desc, kCameraImageDdsName,
              sensor_data_qos().get(), "camera images") {
  // The publication-matched status is read by wanted(); it need not wake anyone.
  check_dds(dds_set_status_mask(writer_.writer(), DDS_PUBLICATION_MATCHED_STATUS),
            "camera images: status mask");
}

bool CameraImagePublisher::wanted() const {
  dds_publication_matched_status_t status{};
  if (dds_get_publication_matched_status(writer_.writer(), &status) < 0) return false;
  return status.current_count > 0;
}

bool CameraImagePublisher::publish(const devices::CameraFrame& frame, double t_s) {
  if (frame.jpeg.empty()) return true;
  const live::RosTime stamp = live::ros_time(t_s);
  sensor_msgs_msg_dds__CompressedImage_ m{};
  m.header_.stamp_.sec_ = stamp.sec;
  m.header_.stamp_.nanosec_ = stamp.nanosec;
  // The generated type holds non-const pointers; dds_write only reads them.
  m.header_.frame_id_ = const_cast<char*>(live::kCameraFrameId.data());
  m.format_ = const_cast<char*>("jpeg");
  m.data_._buffer = const_cast<std::uint8_t*>(frame.jpeg.data());
  m.data_._length = static_cast<std::uint32_t>(frame.jpeg.size());
  m.data_._maximum = m.data_._length;
  m.data_._release = false;
  return writer_.write(&m);
}

}  // namespace mc::net
