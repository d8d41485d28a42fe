#include "microcobot/live/camera_messages.h"

#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

namespace mc::live {
namespace {

constexpr std::string_view kHeaderDeps =
    "================================================================================\n"
    "MSG: std_msgs/Header\n"
    "builtin_interfaces/Time stamp\n"
    "string frame_id\n"
    "================================================================================\n"
    "MSG: builtin_interfaces/Time\n"
    "int32 sec\n"
    "uint32 nanosec\n";

/// Little-endian CDR into a string; alignment counts from after the encapsulation header.
class CdrWriter {
 public:
  explicit CdrWriter(std::string& out) : out_(out) {
    out_.clear();
    out_.append("\x00\x01\x00\x00", 4);
  }
  void align(std::size_t n) {
    while ((out_.size() - 4) % n != 0) out_.push_back('\0');
  }
  template <class T>
  void put(T v) {
    align(sizeof(T));
    char bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));  // x86-64 and ARM64 are little-endian, as the header says
    out_.append(bytes, sizeof(T));
  }
  void string(std::string_view s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size() + 1));
    out_.append(s);
    out_.push_back('\0');
  }
  void bytes(const std::uint8_t* data, std::size_t n) {
    put<std::uint32_t>(static_cast<std::uint32_t>(n));
    out_.append(reinterpret_cast<const char*>(data), n);
  }
  void header(RosTime stamp) {
    put<std::int32_t>(stamp.sec);
    put<std::uint32_t>(stamp.nanosec);
    string(kCameraFrameId);
  }

 private:
  std::string& out_;
};

// RFC 4648 base64 (with padding), appended to `out`.
void append_base64(std::span<const std::uint8_t> in, std::string& out) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::size_t i = 0;
  for (; i + 3 <= in.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{in[i]} << 16) | (std::uint32_t{in[i + 1]} << 8) | in[i + 2];
    const char quad[4] = {kDigits[v >> 18], kDigits[(v >> 12) & 63], kDigits[(v >> 6) & 63], kDigits[v & 63]};
    out.append(quad, 4);
  }
  if (const std::size_t rest = in.size() - i; rest > 0) {
    const std::uint32_t v = (std::uint32_t{in[i]} << 16) | (rest == 2 ? std::uint32_t{in[i + 1]} << 8 : 0u);
    const char quad[4] = {kDigits[v >> 18], kDigits[(v >> 12) & 63], rest == 2 ? kDigits[(v >> 6) & 63] : '=',
                          '='};
    out.append(quad, 4);
  }
}

}  // namespace

std::string_view compressed_image_schema() {
  static const std::string s =
      std::string("std_msgs/Header header\nstring format\nuint8[] data\n") + std::string(kHeaderDeps);
  return s;
}

std::string_view camera_info_schema() {
  static const std::string s =
      std::string(
          "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\nfloat64[] d\n"
          "float64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\nuint32 binning_y\n"
          "sensor_msgs/RegionOfInterest roi\n") +
      std::string(kHeaderDeps) +
      "================================================================================\n"
      "MSG: sensor_msgs/RegionOfInterest\n"
      "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n";
  return s;
}

RosTime ros_time(double t_s) {
  if (!std::isfinite(t_s) || t_s < 0) return {};
  const double sec = std::floor(t_s);
  auto ns = static_cast<std::int64_t>(std::llround((t_s - sec) * 1e9));
  auto s = static_cast<std::int64_t>(sec);
  if (ns >= 1000000000) ++s, ns -= 1000000000;
  return {static_cast<std::int32_t>(std::min<std::int64_t>(s, 2147483647)), static_cast<std::uint32_t>(ns)};
}

void encode_compressed_image(std::span<const std::uint8_t> jpeg, RosTime stamp, std::string& out) {
  out.reserve(jpeg.size() + 64);
  CdrWriter w(out);
  w.header(stamp);
  w.string("jpeg");
  w.bytes(jpeg.data(), jpeg.size());
}

void encode_compressed_image(const devices::CameraFrame& frame, RosTime stamp, std::string& out) {
  encode_compressed_image(std::span<const std::uint8_t>(frame.jpeg), stamp, out);
}

void encode_camera_info(const devices::CameraFrame& frame, RosTime stamp, std::string& out) {
  CdrWriter w(out);
  w.header(stamp);
  const auto width = static_cast<std::uint32_t>(frame.image.width);
  const auto height = static_cast<std::uint32_t>(frame.image.height);
  w.put<std::uint32_t>(height);
  w.put<std::uint32_t>(width);
  w.string("plumb_bob");
  w.put<std::uint32_t>(5);  // d: k1 k2 t1 t2 k3, all zero
  for (int i = 0; i < 5; ++i) w.put<double>(0.0);
  const double f = frame.m_per_px > 0 ? frame.working_distance_m / frame.m_per_px : 0.0;
  const double cx = 0.5 * (static_cast<double>(width) - 1.0), cy = 0.5 * (static_cast<double>(height) - 1.0);
  for (double k : {f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0}) w.put<double>(k);
  for (double r : {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}) w.put<double>(r);
  for (double p : {f, 0.0, cx, 0.0, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0}) w.put<double>(p);
  w.put<std::uint32_t>(1);  // binning
  w.put<std::uint32_t>(1);
  for (int i = 0; i < 4; ++i) w.put<std::uint32_t>(0);  // roi: the whole image
  w.put<std::uint8_t>(0);
}

std::string compressed_video_schema() {
  const nlohmann::json integer = {{"type", "integer"}, {"minimum", 0}};
  return nlohmann::json{
      {"title", "foxglove.CompressedVideo"},
      {"description", "A single frame of a compressed video bitstream"},
      {"type", "object"},
      {"properties",
       {{"timestamp",
         {{"type", "object"},
          {"title", "time"},
          {"properties",
           {{"sec", integer}, {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}}},
          {"description", "Timestamp of video frame"}}},
        {"frame_id", {{"type", "string"}, {"description", "Frame of reference for the video."}}},
        {"data",
         {{"type", "string"},
          {"contentEncoding", "base64"},
          {"description", "Compressed video frame data: the NAL units of one picture, Annex B"}}},
        {"format", {{"type", "string"}, {"description", "Video format: h264"}}}}}}
      .dump();
}

void encode_compressed_video(std::span<const std::uint8_t> annexb, RosTime stamp, std::string& out) {
  out.clear();
  out.reserve(annexb.size() / 3 * 4 + 160);
  out += "{\"timestamp\":{\"sec\":";
  out += std::to_string(stamp.sec);
  out += ",\"nsec\":";
  out += std::to_string(stamp.nanosec);
  out += "},\"frame_id\":\"";
  out += kCameraFrameId;
  out += "\",\"data\":\"";
  append_base64(annexb, out);
  out += "\",\"format\":\"h264\"}";
}

std::string camera_state_schema() {
  const nlohmann::json number = {{"type", "number"}}, text = {{"type", "string"}};
  const nlohmann::json pair = {{"type", "array"}, {"items", number}, {"minItems", 2}, {"maxItems", 2}};
  return nlohmann::json{
      {"type", "object"},
      {"properties",
       {{"t_s", number},
        {"sequence", number},
        {"width", number},
        {"height", number},
        {"objective", number},
        {"objective_name", text},
        {"magnification", number},
        {"m_per_px", number},
        {"view_center_m", pair},
        {"focus_z_m", number},
        {"exposure_s", number},
        {"gain", number},
        {"frame_rate_Hz", number},
        {"jpeg_bytes", number},
        {"capture_ms", number},
        {"encode_ms", number},
        {"latency_ms", number},
        {"dropped", number},
        {"calibration",
         {{"type", {"object", "null"}},
          {"properties",
           {{"px_per_m", {{"type", "array"}, {"items", pair}, {"minItems", 2}, {"maxItems", 2}}},
            {"offset_px", pair},
            {"residual_rms_px", number}}}}},
        {"grip_vision",
         {{"type", {"object", "null"}},
          {"properties",
           {{"grip_force_N", {{"type", {"number", "null"}}}},
            {"gap_m", {{"type", {"number", "null"}}}},
            {"state", text}}}}}}}}
      .dump();
}

std::string camera_state_json(const devices::CameraFrame& f, double frame_rate_Hz, std::uint64_t dropped,
                              const vision::StageCalibration* calibration,
                              const perception::VisionGripStatus* grip) {
  nlohmann::json cal = nullptr;
  if (calibration)
    cal = {{"px_per_m", calibration->px_per_m},
           {"offset_px", calibration->offset_px},
           {"residual_rms_px", calibration->residual_rms_px}};
  nlohmann::json grip_json = nullptr;
  if (grip) {
    const auto number_or_null = [](double v) {
      return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
    };
    grip_json = {{"grip_force_N", number_or_null(grip->grip_force_N)},
                 {"gap_m", number_or_null(grip->gap_m)},
                 {"contact_force_N", number_or_null(grip->contact_force_N)},
                 {"state", grip->state}};
  }
  return nlohmann::json{{"t_s", f.t_mid_s},
                        {"sequence", f.sequence},
                        {"width", f.image.width},
                        {"height", f.image.height},
                        {"objective", f.objective},
                        {"objective_name", f.objective_name},
                        {"magnification", f.magnification},
                        {"m_per_px", f.m_per_px},
                        {"view_center_m", {f.view_center_m[0], f.view_center_m[1]}},
                        {"focus_z_m", f.focus_z_m},
                        {"exposure_s", f.exposure_s},
                        {"gain", f.gain},
                        {"frame_rate_Hz", frame_rate_Hz},
                        {"jpeg_bytes", f.jpeg.size()},
                        {"capture_ms", 1e3 * f.capture_s},
                        {"encode_ms", 1e3 * f.encode_s},
                        {"latency_ms", 1e3 * f.latency_s},
                        {"dropped", dropped},
                        {"calibration", cal},
                        {"grip_vision", grip_json}}
      .dump();
}

}  // namespace mc::live
