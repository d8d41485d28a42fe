#include "microcobot/net/remote_camera.h"

#include <cstring>
#include <span>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/core/jpeg.h"
#include "microcobot/net/camera_image_publisher.h"
#include "ros2_messages.h"

namespace mc::net {

namespace {
constexpr std::uint32_t kImagesPerTake = 4;
}  // namespace

RemoteCameraSource::RemoteCameraSource(int domain_id, const NetworkConfig& network)
    : domain_id_(domain_id), network_(network) {}

RemoteCameraSource::~RemoteCameraSource() { close(); }

void RemoteCameraSource::open(const devices::CameraDeviceParams& params) {
  params_ = params;
  participant_ = std::make_unique<Participant>(domain_id_, network_);
  // The image publisher's QoS (ROS 2's sensor-data profile): best effort, volatile, keep last 1.
  topic_ = check_dds(dds_create_topic(participant_->handle(), &sensor_msgs_msg_dds__CompressedImage__desc,
                                      std::string(kCameraImageDdsName).c_str(), nullptr, nullptr),
                     "the slave's camera: cannot create the image topic");
}

void RemoteCameraSource::close() {
  stop_reading();
  participant_.reset();  // deletes the topic with it
  topic_ = 0;
}

void RemoteCameraSource::start_reading() {
  if (reader_ > 0) return;
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  reader_ = dds_create_reader(participant_->handle(), topic_, qos, nullptr);
  dds_delete_qos(qos);
  check_dds(reader_, "the slave's camera: cannot create the image reader");
  waitset_ = check_dds(dds_create_waitset(participant_->handle()), "the slave's camera: waitset");
  const dds_entity_t cond =
      check_dds(dds_create_readcondition(reader_, DDS_ANY_STATE), "the slave's camera: read condition");
  check_dds(dds_waitset_attach(waitset_, cond, reader_), "the slave's camera: waitset");
}

void RemoteCameraSource::stop_reading() {
  if (waitset_ > 0) dds_delete(waitset_);
  if (reader_ > 0) dds_delete(reader_);  // and its read condition
  waitset_ = reader_ = 0;
}

void RemoteCameraSource::idle() { stop_reading(); }

bool RemoteCameraSource::capture(const devices::SceneSnapshot&, devices::Image& out) {
  start_reading();
  dds_waitset_wait(waitset_, nullptr, 0, DDS_MSECS(100));
  void* samples[kImagesPerTake] = {};
  dds_sample_info_t infos[kImagesPerTake];
  const dds_return_t n = dds_take(reader_, samples, infos, kImagesPerTake, kImagesPerTake);
  if (n <= 0) return false;
  // The newest valid image; older ones (the thread fell behind) are dropped undecoded.
  int newest = -1;
  for (dds_return_t k = 0; k < n; ++k)
    if (infos[k].valid_data) newest = static_cast<int>(k);
  JpegImage decoded;
  std::string error;
  if (newest >= 0) {
    const auto& m = *static_cast<const sensor_msgs_msg_dds__CompressedImage_*>(samples[newest]);
    try {
      decoded = decode_jpeg(std::span<const std::uint8_t>(m.data_._buffer, m.data_._length), 1);
      jpeg_.assign(m.data_._buffer, m.data_._buffer + m.data_._length);
    } catch (const Error& e) {
      error = e.what();
    }
  }
  dds_return_loan(reader_, samples, n);
  if (!error.empty()) throw InvalidInput("the slave's camera sent a frame that does not decode: " + error);
  if (newest < 0) return false;
  const imaging::SensorParams& sensor = params_.sensor;
  if (decoded.width != sensor.width_px || decoded.height != sensor.height_px)
    throw InvalidInput("the slave's camera sends " + std::to_string(decoded.width) + " x " +
                       std::to_string(decoded.height) + " px frames; this configuration's camera.sensor is " +
                       std::to_string(sensor.width_px) + " x " + std::to_string(sensor.height_px) +
                       " (give both ends the same camera)");
  const int bits = sensor.bit_depth;
  out.resize(decoded.width, decoded.height, 1, bits);
  if (bits <= 8) {
    std::memcpy(out.data.data(), decoded.pixels.data(), decoded.pixels.size());
  } else {
    // Deeper sensors: the 8-bit JPEG samples scaled to the sensor's range, little-endian.
    for (std::size_t i = 0; i < decoded.pixels.size(); ++i) {
      const auto v = static_cast<std::uint16_t>(decoded.pixels[i] << (bits - 8));
      out.data[2 * i] = static_cast<std::uint8_t>(v & 0xff);
      out.data[2 * i + 1] = static_cast<std::uint8_t>(v >> 8);
    }
  }
  return true;
}

}  // namespace mc::net
