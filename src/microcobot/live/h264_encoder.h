#pragma once
/// @file
/// The camera's frames as H.264 for the recordings (`serve --record-video h264`, docs/console.md
/// "Recordings"): Debian's libavcodec driving libx264 (ITU-T H.264, Annex B byte stream).
///
/// Each access unit comes out as its own Annex B packet, so that one message of a recording
/// decodes to exactly one image, as Foxglove's CompressedVideo asks: no B-frames (pictures come
/// out in the order they went in, none needs a later one); a keyframe (an IDR picture, preceded
/// by its SPS and PPS) at least every `keyframe_interval_s` of the frames' own time, whatever the
/// camera's rate or the frames it skipped, so that a viewer seeking anywhere decodes within that
/// interval. To know that, a frame is encoded when the next one arrives (or at flush()): it is a
/// keyframe when the next would come more than the interval after the last keyframe.
///
/// Grey 8-bit samples are the luma of full-range 4:2:0 (Y = sample, Cb = Cr = 128: a decoder
/// gives back the grey levels), RGB is converted by BT.601's full-range matrix (JFIF). Odd widths
/// or heights lose their last column or row (4:2:0 needs even sizes).
///
/// Threads: one encoder, one thread (the recording's writer: live/session_recording.h); it
/// allocates and is never on the loop's path. libavcodec's headers stay in h264_encoder.cc.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "microcobot/devices/camera_frame.h"

namespace mc::live {

/// libx264's settings for the microscope's frames (defaults and their source: docs/parameters.md).
struct H264Params {
  /// x264's speed preset: "ultrafast" ... "veryslow" (faster: more bytes for the same quality).
  std::string preset = "veryfast";
  /// x264's tuning: "" (none), "zerolatency", "psnr", "ssim", "film", "grain", "stillimage" or
  /// "fastdecode".
  std::string tune = "zerolatency";
  /// Constant rate factor, [0, 51]: lower is better quality and more bytes.
  double crf = 23.0;
  /// The longest time between two keyframes, s.
  double keyframe_interval_s = 2.0;
  /// libx264's threads (1: the encoder takes one core at most, beside the loop's).
  int threads = 1;

  template <class V>
  void visit(V& v) {
    v("preset", preset);
    v("tune", tune);
    v("crf", crf);
    v("keyframe_interval_s", keyframe_interval_s);
    v("threads", threads);
  }
  void validate() const;
};

/// 8-bit samples to encode: rows top first, 1 (grey) or 3 (RGB) channels, `width * channels`
/// bytes a row.
struct VideoImage {
  int width = 0;
  int height = 0;
  int channels = 1;
  std::span<const std::uint8_t> data;
};

/// The camera's image as the encoder takes it, into `out` (replaced): 8-bit samples, the top 8
/// bits of a deeper sensor's (as the JPEG frames, core/jpeg.h). Returns its view over `out`.
/// Throws mc::InvalidInput for channels other than 1 or 3 or sizes that do not match.
VideoImage to_video_image(const devices::Image& image, std::string& out);

/// One access unit out of the encoder.
struct H264Packet {
  std::span<const std::uint8_t> annexb;  ///< start codes, then the NAL units of one picture
  double t_s = 0.0;                      ///< the time the frame was given with
  std::uint64_t tag = 0;                 ///< what the caller gave with it (e.g. its log time)
  bool keyframe = false;                 ///< an IDR picture with its SPS and PPS
};

class H264Encoder {
 public:
  using Sink = std::function<void(const H264Packet&)>;

  /// `frame_rate_Hz`: the camera's nominal rate (the stream's time base). Throws mc::InvalidParams
  /// for bad settings and mc::ComputationFailed when libavcodec has no libx264 encoder.
  H264Encoder(H264Params params, double frame_rate_Hz);
  ~H264Encoder();
  H264Encoder(const H264Encoder&) = delete;
  H264Encoder& operator=(const H264Encoder&) = delete;

  const H264Params& params() const { return params_; }

  /// Takes `image` (copied), taken at `t_s` (non-decreasing), encodes the frame before it and
  /// hands `sink` what comes out (with "zerolatency", that frame's packet; else the packets of
  /// earlier frames as x264's lookahead lets them go; always in input order). A frame of another
  /// size than the one before ends the stream and starts another at a keyframe. Throws
  /// mc::InvalidInput for a malformed image and mc::ComputationFailed when libavcodec fails.
  void encode(const VideoImage& image, double t_s, std::uint64_t tag, const Sink& sink);
  /// Encodes the frame still held and hands `sink` every packet still in the encoder (end of the
  /// recording); the next frame starts a new stream.
  void flush(const Sink& sink);

  std::uint64_t frames_in() const { return frames_in_; }
  std::uint64_t packets_out() const { return packets_out_; }

 private:
  struct Codec;
  void open(int width, int height);
  void encode_held(std::optional<double> next_t_s, const Sink& sink);
  void end_stream(const Sink& sink);
  void drain(const Sink& sink);

  H264Params params_;
  double frame_rate_Hz_;
  std::unique_ptr<Codec> codec_;
  bool keyframe_given_ = false;
  double last_keyframe_t_s_ = 0.0;
  // The frame taken last, encoded when the next arrives.
  bool held_ = false;
  std::vector<std::uint8_t> held_samples_;
  int held_width_ = 0, held_height_ = 0, held_channels_ = 1;
  double held_t_s_ = 0.0;
  std::uint64_t held_tag_ = 0;
  std::uint64_t frames_in_ = 0, packets_out_ = 0;
};

}  // namespace mc::live
