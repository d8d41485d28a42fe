#include "microcobot/live/h264_encoder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libavutil/rational.h>
}

#include "microcobot/core/error.h"

namespace mc::live {
namespace {

constexpr std::array<std::string_view, 10> kPresets = {"ultrafast", "superfast", "veryfast", "faster",
                                                       "fast",      "medium",    "slow",     "slower",
                                                       "veryslow",  "placebo"};
constexpr std::array<std::string_view, 8> kTunes = {"",     "zerolatency", "psnr",       "ssim",
                                                    "film", "grain",       "stillimage", "fastdecode"};

std::string av_error(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

// JFIF's full-range BT.601: Y, Cb, Cr of an 8-bit RGB sample, rounded and clamped.
std::uint8_t clamp_byte(double v) { return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

}  // namespace

void H264Params::validate() const {
  require(std::find(kPresets.begin(), kPresets.end(), preset) != kPresets.end(), "preset",
          "must be one of ultrafast, superfast, veryfast, faster, fast, medium, slow, slower, veryslow, "
          "placebo");
  require(std::find(kTunes.begin(), kTunes.end(), tune) != kTunes.end(), "tune",
          "must be empty or one of zerolatency, psnr, ssim, film, grain, stillimage, fastdecode");
  require_in_range(crf, 0.0, 51.0, "crf");
  require(std::isfinite(keyframe_interval_s) && keyframe_interval_s > 0.0 && keyframe_interval_s <= 60.0,
          "keyframe_interval_s", "must be within (0, 60] s", keyframe_interval_s);
  require(threads >= 1 && threads <= 16, "threads", "must be within [1, 16]", threads);
}

VideoImage to_video_image(const devices::Image& image, std::string& out) {
  if (image.channels != 1 && image.channels != 3)
    throw InvalidInput("video: " + std::to_string(image.channels) + " channels (1 grey or 3 RGB)");
  if (image.width <= 0 || image.height <= 0 || image.data.size() != image.size_bytes())
    throw InvalidInput("video: " + std::to_string(image.data.size()) + " bytes for a " +
                       std::to_string(image.width) + "x" + std::to_string(image.height) + " image");
  const std::size_t samples = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) *
                              static_cast<std::size_t>(image.channels);
  out.resize(samples);
  auto* dst = reinterpret_cast<std::uint8_t*>(out.data());
  const std::uint8_t* src = image.data.data();
  if (image.bytes_per_sample() == 1) {
    std::memcpy(dst, src, samples);
  } else {
    const int shift = std::max(0, image.bit_depth - 8);
    for (std::size_t i = 0; i < samples; ++i) {
      const unsigned v =
          (static_cast<unsigned>(src[2 * i]) | (static_cast<unsigned>(src[2 * i + 1]) << 8)) >> shift;
      dst[i] = static_cast<std::uint8_t>(std::min(v, 255u));
    }
  }
  return VideoImage{image.width, image.height, image.channels, std::span<const std::uint8_t>(dst, samples)};
}

struct H264Encoder::Codec {
  AVCodecContext* context = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  int width = 0, height = 0;  // the frames' (the stream's: even)
  std::int64_t next_pts = 0;
  struct Pending {
    std::int64_t pts;
    double t_s;
    std::uint64_t tag;
  };
  std::deque<Pending> pending;  // frames in, their packets not yet out
  ~Codec() {
    avcodec_free_context(&context);
    av_frame_free(&frame);
    av_packet_free(&packet);
  }
};

H264Encoder::H264Encoder(H264Params params, double frame_rate_Hz)
    : params_(std::move(params)), frame_rate_Hz_(frame_rate_Hz) {
  params_.validate();
  require(std::isfinite(frame_rate_Hz) && frame_rate_Hz > 0.0 && frame_rate_Hz <= 1000.0, "frame_rate_Hz",
          "must be within (0, 1000] Hz", frame_rate_Hz);
  // libavcodec logs to stderr; its errors come back as return codes here, and x264's summary at
  // the end of each stream is not wanted on serve's stderr.
  static std::once_flag quiet;
  std::call_once(quiet, [] { av_log_set_level(AV_LOG_ERROR); });
  if (avcodec_find_encoder_by_name("libx264") == nullptr)
    throw ComputationFailed(
        "h264: this libavcodec has no libx264 encoder (Debian's libavcodec59 has it: "
        "scripts/install-deps.sh)");
}

H264Encoder::~H264Encoder() = default;

void H264Encoder::open(int width, int height) {
  auto c = std::make_unique<Codec>();
  const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
  c->context = avcodec_alloc_context3(codec);
  c->frame = av_frame_alloc();
  c->packet = av_packet_alloc();
  if (!c->context || !c->frame || !c->packet) throw ComputationFailed("h264: out of memory");
  AVCodecContext* x = c->context;
  x->width = width;
  x->height = height;
  x->pix_fmt = AV_PIX_FMT_YUV420P;
  x->color_range = AVCOL_RANGE_JPEG;  // the grey levels as they are: 0 black, 255 white
  x->colorspace = AVCOL_SPC_SMPTE170M;
  x->framerate = av_d2q(frame_rate_Hz_, 100000);
  x->time_base = av_inv_q(x->framerate);
  x->gop_size =
      std::max(1, static_cast<int>(std::floor(params_.keyframe_interval_s * frame_rate_Hz_ + 1e-9)));
  x->max_b_frames = 0;
  x->thread_count = params_.threads;
  av_opt_set(x->priv_data, "preset", params_.preset.c_str(), 0);
  if (!params_.tune.empty()) av_opt_set(x->priv_data, "tune", params_.tune.c_str(), 0);
  av_opt_set_double(x->priv_data, "crf", params_.crf, 0);
  av_opt_set_int(x->priv_data, "forced-idr", 1, 0);  // a forced keyframe is an IDR picture
  if (const int rc = avcodec_open2(x, codec, nullptr); rc < 0)
    throw ComputationFailed("h264: libx264 refused " + std::to_string(width) + "x" + std::to_string(height) +
                            " at " + std::to_string(frame_rate_Hz_) + " Hz: " + av_error(rc));
  c->frame->format = AV_PIX_FMT_YUV420P;
  c->frame->width = width;
  c->frame->height = height;
  c->frame->color_range = AVCOL_RANGE_JPEG;
  if (const int rc = av_frame_get_buffer(c->frame, 0); rc < 0)
    throw ComputationFailed("h264: no frame buffer: " + av_error(rc));
  c->width = width;
  c->height = height;
  codec_ = std::move(c);
  keyframe_given_ = false;
}

void H264Encoder::encode(const VideoImage& image, double t_s, std::uint64_t tag, const Sink& sink) {
  if (image.channels != 1 && image.channels != 3)
    throw InvalidInput("h264: " + std::to_string(image.channels) + " channels (1 grey or 3 RGB)");
  if (image.width < 2 || image.height < 2 ||
      image.data.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) *
                               static_cast<std::size_t>(image.channels))
    throw InvalidInput("h264: " + std::to_string(image.data.size()) + " bytes for a " +
                       std::to_string(image.width) + "x" + std::to_string(image.height) + " image of " +
                       std::to_string(image.channels) + " channel(s)");
  if (held_) encode_held(t_s, sink);
  held_samples_.assign(image.data.begin(), image.data.end());
  held_width_ = image.width;
  held_height_ = image.height;
  held_channels_ = image.channels;
  held_t_s_ = t_s;
  held_tag_ = tag;
  held_ = true;
}

void H264Encoder::flush(const Sink& sink) {
  if (held_) encode_held(std::nullopt, sink);
  end_stream(sink);
}

void H264Encoder::end_stream(const Sink& sink) {
  if (!codec_) return;
  if (const int rc = avcodec_send_frame(codec_->context, nullptr); rc < 0 && rc != AVERROR_EOF)
    throw ComputationFailed("h264: flushing failed: " + av_error(rc));
  drain(sink);
  codec_.reset();  // the next frame starts a new stream
}

void H264Encoder::encode_held(std::optional<double> next_t_s, const Sink& sink) {
  held_ = false;
  const int w = held_width_ & ~1, h = held_height_ & ~1;
  if (!codec_ || codec_->width != w || codec_->height != h) {
    end_stream(sink);
    open(w, h);
  }
  Codec& c = *codec_;
  AVFrame* f = c.frame;
  if (const int rc = av_frame_make_writable(f); rc < 0)
    throw ComputationFailed("h264: frame not writable: " + av_error(rc));
  const std::uint8_t* samples = held_samples_.data();
  const std::size_t stride = static_cast<std::size_t>(held_width_) * static_cast<std::size_t>(held_channels_);
  if (held_channels_ == 1) {
    for (int y = 0; y < h; ++y)
      std::memcpy(f->data[0] + static_cast<std::ptrdiff_t>(y) * f->linesize[0],
                  samples + static_cast<std::size_t>(y) * stride, static_cast<std::size_t>(w));
    for (int y = 0; y < h / 2; ++y) {
      std::memset(f->data[1] + static_cast<std::ptrdiff_t>(y) * f->linesize[1], 128,
                  static_cast<std::size_t>(w / 2));
      std::memset(f->data[2] + static_cast<std::ptrdiff_t>(y) * f->linesize[2], 128,
                  static_cast<std::size_t>(w / 2));
    }
  } else {
    // Full-range BT.601 (JFIF): Y = 0.299 R + 0.587 G + 0.114 B; Cb, Cr of each 2x2 block's mean.
    for (int y = 0; y < h; y += 2) {
      for (int x = 0; x < w; x += 2) {
        double r = 0, g = 0, b = 0;
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const std::uint8_t* p =
                samples + static_cast<std::size_t>(y + dy) * stride + 3 * static_cast<std::size_t>(x + dx);
            f->data[0][static_cast<std::ptrdiff_t>(y + dy) * f->linesize[0] + x + dx] =
                clamp_byte(0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]);
            r += p[0], g += p[1], b += p[2];
          }
        r *= 0.25, g *= 0.25, b *= 0.25;
        f->data[1][static_cast<std::ptrdiff_t>(y / 2) * f->linesize[1] + x / 2] =
            clamp_byte(128.0 - 0.168736 * r - 0.331264 * g + 0.5 * b);
        f->data[2][static_cast<std::ptrdiff_t>(y / 2) * f->linesize[2] + x / 2] =
            clamp_byte(128.0 + 0.5 * r - 0.418688 * g - 0.081312 * b);
      }
    }
  }
  // By the frames' own time, not their count (a camera that skips frames would stretch a count):
  // this frame is a keyframe when the next one would come more than an interval after the last
  // keyframe, so that no two keyframes are further apart than the interval (unless one gap between
  // frames is longer).
  const double interval = params_.keyframe_interval_s;
  const bool key = !keyframe_given_ || held_t_s_ - last_keyframe_t_s_ > interval ||
                   (next_t_s && *next_t_s - last_keyframe_t_s_ > interval + 1e-9);
  if (key) {
    keyframe_given_ = true;
    last_keyframe_t_s_ = held_t_s_;
  }
  f->pict_type = key ? AV_PICTURE_TYPE_I : AV_PICTURE_TYPE_NONE;
  f->pts = c.next_pts++;
  c.pending.push_back({f->pts, held_t_s_, held_tag_});
  if (const int rc = avcodec_send_frame(c.context, f); rc < 0)
    throw ComputationFailed("h264: encoding frame " + std::to_string(frames_in_) +
                            " failed: " + av_error(rc));
  ++frames_in_;
  drain(sink);
}

void H264Encoder::drain(const Sink& sink) {
  Codec& c = *codec_;
  while (true) {
    const int rc = avcodec_receive_packet(c.context, c.packet);
    if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
    if (rc < 0) throw ComputationFailed("h264: no packet out: " + av_error(rc));
    // Without B-frames packets leave in the order frames came: the pending front is this one's
    // (frames x264 dropped, none at a constant rate factor, are skipped by their pts).
    while (!c.pending.empty() && c.pending.front().pts < c.packet->pts) c.pending.pop_front();
    H264Packet p;
    p.annexb = std::span<const std::uint8_t>(c.packet->data, static_cast<std::size_t>(c.packet->size));
    p.keyframe = (c.packet->flags & AV_PKT_FLAG_KEY) != 0;
    if (!c.pending.empty() && c.pending.front().pts == c.packet->pts) {
      p.t_s = c.pending.front().t_s;
      p.tag = c.pending.front().tag;
      c.pending.pop_front();
    }
    if (p.keyframe) last_keyframe_t_s_ = std::max(last_keyframe_t_s_, p.t_s);  // x264's own (a scene cut)
    ++packets_out_;
    try {
      sink(p);
    } catch (...) {
      av_packet_unref(c.packet);
      throw;
    }
    av_packet_unref(c.packet);
  }
}

}  // namespace mc::live
