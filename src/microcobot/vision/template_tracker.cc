#include "microcobot/vision/template_tracker.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>

#include "microcobot/core/error.h"

namespace mc::vision {

namespace {

// Pixels of margin around the coarse match that ECC may move within.
constexpr int kFineMargin = 4;
// A refinement further than this from the coarse match is a divergence, not a correction [px].
constexpr double kMaxRefinement = 2.0;

cv::Mat view16(const imaging::Frame& f) {
  // matchTemplate/ECC read; the frame's buffer is not written.
  return cv::Mat(f.height, f.width, CV_16U, const_cast<std::uint16_t*>(f.pixels.data()));
}

// `area` of the frame as float, low-passed by a Gaussian of `ksize` computed with the frame's own
// pixels around it (not a replicated border: where a bar crosses the template's edge, a blur
// padded differently in the template and in the window biased the alignment by 0.14 px), and
// high-passed (minus its Gaussian of sigma `highpass_px`) when that is > 0.
void blurred(const cv::Mat& full, const cv::Rect& area, int ksize, double highpass_px, cv::Mat& scratch,
             cv::Mat& out) {
  const int pad = ksize / 2 + 1 + static_cast<int>(std::ceil(3.0 * highpass_px));
  const cv::Rect grown = cv::Rect(area.x - pad, area.y - pad, area.width + 2 * pad, area.height + 2 * pad) &
                         cv::Rect(0, 0, full.cols, full.rows);
  full(grown).convertTo(scratch, CV_32F);
  if (ksize > 1) cv::GaussianBlur(scratch, scratch, cv::Size(ksize, ksize), 0.0, 0.0, cv::BORDER_REPLICATE);
  if (highpass_px > 0.0) {
    cv::Mat low;
    cv::GaussianBlur(scratch, low, cv::Size(0, 0), highpass_px, highpass_px, cv::BORDER_REPLICATE);
    scratch -= low;
  }
  scratch(cv::Rect(area.tl() - grown.tl(), area.size())).copyTo(out);
}

std::string roi_text(const imaging::PixelRoi& r) {
  return "ROI x " + std::to_string(r.x) + ", y " + std::to_string(r.y) + ", " + std::to_string(r.width) +
         "x" + std::to_string(r.height);
}

}  // namespace

void TrackerParams::validate() const {
  require(search_margin_px >= 2 && search_margin_px <= 4096, "search_margin_px", "must be within [2, 4096]",
          search_margin_px);
  require(lost_below > -1.0 && lost_below < 1.0, "lost_below", "must be within (-1, 1)", lost_below);
  require(min_contrast_ratio > 0.0 && min_contrast_ratio <= 1.0, "min_contrast_ratio",
          "must be within (0, 1]", min_contrast_ratio);
  require(ecc_iterations >= 1 && ecc_iterations <= 1000, "ecc_iterations", "must be within [1, 1000]",
          ecc_iterations);
  require(ecc_epsilon > 0.0 && ecc_epsilon < 1.0, "ecc_epsilon", "must be within (0, 1)", ecc_epsilon);
  require(ecc_blur_px >= 1 && ecc_blur_px <= 31 && ecc_blur_px % 2 == 1, "ecc_blur_px",
          "must be odd, within [1, 31]", ecc_blur_px);
  require(std::isfinite(ecc_highpass_px) && ecc_highpass_px >= 0.0 && ecc_highpass_px <= 64.0,
          "ecc_highpass_px", "must be within [0, 64] px", ecc_highpass_px);
}

struct TemplateTracker::Images {
  cv::Mat templ;             // float
  cv::Mat templ_smooth;      // low-passed with its surroundings, for ECC
  cv::Mat templ_half;        // 2x-decimated, for the whole-frame search
  cv::Mat templ_turned;      // turned by the last angle, for the coarse search (scratch)
  cv::Mat window, response;  // scratch
  double templ_stddev = 0.0;
  int frame_width = 0, frame_height = 0;
};

TemplateTracker::TemplateTracker(const TrackerParams& params) : params_(params) { params_.validate(); }
TemplateTracker::~TemplateTracker() = default;
TemplateTracker::TemplateTracker(TemplateTracker&&) noexcept = default;
TemplateTracker& TemplateTracker::operator=(TemplateTracker&&) noexcept = default;

bool TemplateTracker::has_template() const { return images_ != nullptr; }

void TemplateTracker::set_template(const imaging::Frame& frame, const imaging::PixelRoi& roi) {
  if (roi.width < 8 || roi.height < 8)
    throw InvalidInput(roi_text(roi) + ": a template needs at least 8x8 pixels");
  if (roi.x < 0 || roi.y < 0 || roi.x + roi.width > frame.width || roi.y + roi.height > frame.height)
    throw InvalidInput(roi_text(roi) + ": not inside the " + std::to_string(frame.width) + "x" +
                       std::to_string(frame.height) + " frame");
  auto images = std::make_unique<Images>();
  view16(frame)(cv::Rect(roi.x, roi.y, roi.width, roi.height)).convertTo(images->templ, CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(images->templ, mean, stddev);
  if (!(stddev[0] > 0.5))  // under half a grey level: noise, no feature
    throw InvalidInput(roi_text(roi) + ": the patch has no contrast to track (rms " +
                       std::to_string(stddev[0]) + " grey levels)");
  images->templ_stddev = stddev[0];
  cv::pyrDown(images->templ, images->templ_half);
  {
    cv::Mat scratch;
    blurred(view16(frame), cv::Rect(roi.x, roi.y, roi.width, roi.height), params_.ecc_blur_px,
            params_.ecc_highpass_px, scratch, images->templ_smooth);
  }
  images->frame_width = frame.width;
  images->frame_height = frame.height;
  images_ = std::move(images);
  templ_width_ = roi.width;
  templ_height_ = roi.height;
  last_ = {};
  last_.u_px = roi.x + 0.5 * (roi.width - 1);
  last_.v_px = roi.y + 0.5 * (roi.height - 1);
  last_.confidence = 1.0;
  last_.found = true;
  du_ = dv_ = 0.0;
  lost_ = false;
}

TrackEstimate TemplateTracker::track(const imaging::Frame& frame) {
  const double u = last_.u_px + du_, v = last_.v_px + dv_;
  return track_around(frame, u, v, u, v, lost_);
}

bool TemplateTracker::fits(double u_px, double v_px, int width_px, int height_px) const noexcept {
  if (!images_ || !std::isfinite(u_px) || !std::isfinite(v_px)) return false;
  // Continuous pixel coordinates: the template's centre is (width - 1) / 2 from its left column.
  const double left = u_px - 0.5 * (templ_width_ - 1), top = v_px - 0.5 * (templ_height_ - 1);
  return left >= -0.5 && top >= -0.5 && left + templ_width_ <= width_px + 0.5 &&
         top + templ_height_ <= height_px + 0.5;
}

TrackEstimate TemplateTracker::track_near(const imaging::Frame& frame, double u_px, double v_px) {
  if (!std::isfinite(u_px) || !std::isfinite(v_px))
    throw InvalidInput("template tracker: the predicted position (" + std::to_string(u_px) + ", " +
                       std::to_string(v_px) + ") px is not finite");
  return track_around(frame, u_px, v_px, u_px, v_px, false);
}

TrackEstimate TemplateTracker::track_along(const imaging::Frame& frame, double u0_px, double v0_px,
                                           double u1_px, double v1_px) {
  if (!std::isfinite(u0_px) || !std::isfinite(v0_px) || !std::isfinite(u1_px) || !std::isfinite(v1_px))
    throw InvalidInput("template tracker: a predicted position is not finite");
  return track_around(frame, u0_px, v0_px, u1_px, v1_px, false);
}

TrackEstimate TemplateTracker::track_around(const imaging::Frame& frame, double pu0, double pv0, double pu1,
                                            double pv1, bool whole) {
  if (!images_) throw InvalidInput("template tracker: no template (set_template first)");
  Images& im = *images_;
  if (frame.width != im.frame_width || frame.height != im.frame_height)
    throw InvalidInput("template tracker: a " + std::to_string(frame.width) + "x" +
                       std::to_string(frame.height) + " frame, the template came from " +
                       std::to_string(im.frame_width) + "x" + std::to_string(im.frame_height));
  const cv::Mat full = view16(frame);
  const int tw = im.templ.cols, th = im.templ.rows;
  const double cx = 0.5 * (tw - 1), cy = 0.5 * (th - 1);
  const cv::Rect bounds(0, 0, frame.width, frame.height);

  // 1. Coarse: the integer-pixel top-left corner of the best match.
  cv::Point corner;
  double peak = -1.0;
  // A turned target is searched with the template turned by its last angle (a template matched
  // unturned slid 2 px off the corner of a part turned 3.6 degrees).
  const double turn = params_.rotation ? last_.angle_rad : 0.0;
  const cv::Mat* coarse_templ = &im.templ;
  if (turn != 0.0) {
    // Image axes (rows down): the turn seen counter-clockwise is cv's positive angle.
    const cv::Mat m = cv::getRotationMatrix2D(cv::Point2f(static_cast<float>(cx), static_cast<float>(cy)),
                                              turn * 180.0 / M_PI, 1.0);
    cv::warpAffine(im.templ, im.templ_turned, m, im.templ.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    coarse_templ = &im.templ_turned;
  }
  const auto search = [&](const cv::Rect& area) {
    full(area).convertTo(im.window, CV_32F);
    cv::matchTemplate(im.window, *coarse_templ, im.response, cv::TM_CCOEFF_NORMED);
    cv::Point at;
    cv::minMaxLoc(im.response, nullptr, &peak, nullptr, &at);
    corner = area.tl() + at;
  };
  const int m = params_.search_margin_px;
  const double far = 1e6;  // a prediction outside any frame
  const auto around = [&](double pu, double pv) {
    return cv::Rect(static_cast<int>(std::lround(std::clamp(pu - cx, -far, far))) - m,
                    static_cast<int>(std::lround(std::clamp(pv - cy, -far, far))) - m, tw + 2 * m,
                    th + 2 * m);
  };
  const cv::Rect predicted = around(pu0, pv0) | around(pu1, pv1);
  const cv::Rect window = predicted & bounds;
  if (!whole && window.width >= tw && window.height >= th) search(window);
  // Correlation is blind to contrast: a faint patch of texture shaped like the target correlates
  // well. A match must also carry the template's contrast.
  const auto is_match = [&] {
    if (peak < params_.lost_below) return false;
    const cv::Rect at(corner.x, corner.y, tw, th);
    if ((at & bounds) != at) return false;
    cv::Scalar mean, stddev;
    cv::meanStdDev(full(at), mean, stddev);
    const double ratio = stddev[0] / im.templ_stddev;
    return ratio >= params_.min_contrast_ratio && ratio <= 1.0 / params_.min_contrast_ratio;
  };
  const bool searched_whole = !is_match();
  if (searched_whole) {
    // Lost (or predicted out of the frame): the whole frame, decimated 2x, then the
    // full-resolution peak within a pixel or two of it.
    cv::Mat half;
    full.convertTo(im.window, CV_32F);
    cv::pyrDown(im.window, half);
    if (half.cols >= im.templ_half.cols && half.rows >= im.templ_half.rows) {
      cv::matchTemplate(half, im.templ_half, im.response, cv::TM_CCOEFF_NORMED);
      cv::Point at;
      cv::minMaxLoc(im.response, nullptr, &peak, nullptr, &at);
      const cv::Rect near(2 * at.x - 3, 2 * at.y - 3, tw + 6, th + 6);
      const cv::Rect area = near & bounds;
      if (area.width >= tw && area.height >= th) search(area);
    }
  }
  TrackEstimate e = last_;
  e.reacquired = false;
  if (searched_whole && !is_match()) {
    e.found = false;
    e.confidence = peak;
    lost_ = true;
    last_ = e;
    return e;
  }

  // 2. Fine: ECC from the coarse match, on a window a few pixels larger than the template (and
  // than its turned corners).
  const int fine_margin =
      kFineMargin + static_cast<int>(std::ceil(0.5 * std::hypot(tw, th) * std::abs(std::sin(turn))));
  const cv::Rect fine_area =
      cv::Rect(corner.x - fine_margin, corner.y - fine_margin, tw + 2 * fine_margin, th + 2 * fine_margin) &
      bounds;
  blurred(full, fine_area, params_.ecc_blur_px, params_.ecc_highpass_px, im.response, im.window);
  const double a0 = -turn;  // image axes: rows go down
  cv::Mat warp = (cv::Mat_<float>(2, 3) << std::cos(a0), -std::sin(a0), corner.x - fine_area.x, std::sin(a0),
                  std::cos(a0), corner.y - fine_area.y);
  // Rotation about the template's centre: shift the translation so the centre stays put.
  warp.at<float>(0, 2) += static_cast<float>(cx - (std::cos(a0) * cx - std::sin(a0) * cy));
  warp.at<float>(1, 2) += static_cast<float>(cy - (std::sin(a0) * cx + std::cos(a0) * cy));
  double u = corner.x + cx, v = corner.y + cy, angle = last_.angle_rad, rho = peak;
  try {
    rho = cv::findTransformECC(im.templ_smooth, im.window, warp,
                               params_.rotation ? cv::MOTION_EUCLIDEAN : cv::MOTION_TRANSLATION,
                               cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                                                params_.ecc_iterations, params_.ecc_epsilon),
                               cv::noArray(), 1);  // both already low-passed
    const auto w = [&](int r, int c) { return static_cast<double>(warp.at<float>(r, c)); };
    const double fu = fine_area.x + w(0, 0) * cx + w(0, 1) * cy + w(0, 2);
    const double fv = fine_area.y + w(1, 0) * cx + w(1, 1) * cy + w(1, 2);
    if (std::hypot(fu - u, fv - v) <= kMaxRefinement) {
      u = fu, v = fv;
      angle = -std::atan2(w(1, 0), w(0, 0));
    }
  } catch (const cv::Exception&) {
    // ECC did not converge (a flat or saturated window): the coarse match stands.
  }
  e.u_px = u;
  e.v_px = v;
  e.angle_rad = params_.rotation ? angle : 0.0;
  e.confidence = rho;
  e.found = true;
  e.reacquired = searched_whole && lost_;
  du_ = lost_ ? 0.0 : u - last_.u_px;
  dv_ = lost_ ? 0.0 : v - last_.v_px;
  lost_ = false;
  last_ = e;
  return e;
}

}  // namespace mc::vision
