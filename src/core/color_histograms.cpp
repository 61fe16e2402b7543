#include "klt_contour_tracker/core/color_histograms.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace kct {
namespace {

constexpr int kMinBandPixels = 50;
constexpr float kMinPosterior = 0.01f;
// Added to both histograms' bins before the posterior: a colour seen a few times on one side
// only does not become certain.
constexpr float kBinPrior = 1e-4f;

/// Normalized histogram of the BGR pixels of `image` where `mask` is non-zero; false when
/// fewer than kMinBandPixels.
bool band_histogram(const cv::Mat& image, const cv::Mat& mask, std::vector<float>& histogram) {
  std::vector<float> counts(ColorHistograms::kBins, 0.0f);
  int total = 0;
  for (int r = 0; r < image.rows; ++r) {
    const cv::Vec3b* pixels = image.ptr<cv::Vec3b>(r);
    const uchar* m = mask.ptr<uchar>(r);
    for (int c = 0; c < image.cols; ++c)
      if (m[c]) {
        counts[ColorHistograms::bin(pixels[c])] += 1.0f;
        ++total;
      }
  }
  if (total < kMinBandPixels) return false;
  for (float& v : counts) v /= static_cast<float>(total);
  histogram.swap(counts);
  return true;
}

}  // namespace

void ColorHistograms::clear() {
  ready_ = false;
  std::fill(foreground_.begin(), foreground_.end(), 0.0f);
  std::fill(background_.begin(), background_.end(), 0.0f);
  std::fill(posterior_.begin(), posterior_.end(), 0.5f);
}

bool ColorHistograms::learn(const cv::Mat& bgr, const cv::Mat& mask, int band_px,
                            double learning_rate) {
  if (bgr.type() != CV_8UC3)
    throw std::invalid_argument("ColorHistograms::learn: bgr must be CV_8UC3");
  if (mask.type() != CV_8UC1 || mask.size() != bgr.size())
    throw std::invalid_argument("ColorHistograms::learn: mask must be CV_8UC1 of the image's size");
  if (band_px < 1)
    throw std::invalid_argument("ColorHistograms::learn: band_px must be >= 1, got " +
                                std::to_string(band_px));
  if (!(learning_rate > 0.0 && learning_rate <= 1.0))
    throw std::invalid_argument("ColorHistograms::learn: learning_rate must be in (0, 1], got " +
                                std::to_string(learning_rate));
  // Bands along the outline only, computed with OpenCV's morphology inside the object's
  // bounding box grown by the band (the rest of the frame cannot be in a band).
  const cv::Rect frame_rect(0, 0, bgr.cols, bgr.rows);
  const cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return false;
  const cv::Rect roi =
      cv::Rect(box.x - band_px - 1, box.y - band_px - 1, box.width + 2 * band_px + 2,
               box.height + 2 * band_px + 2) &
      frame_rect;
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * band_px + 1, 2 * band_px + 1});
  cv::Mat object = mask(roi) != 0, eroded, dilated;
  cv::erode(object, eroded, kernel, {-1, -1}, 1, cv::BORDER_REPLICATE);
  cv::dilate(object, dilated, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  const cv::Mat inner = object & ~eroded;
  const cv::Mat outer = dilated & ~object;
  std::vector<float> fg, bg;
  if (!band_histogram(bgr(roi), inner, fg) || !band_histogram(bgr(roi), outer, bg)) return false;
  if (!ready_) {
    foreground_ = fg;
    background_ = bg;
  } else {
    const float a = static_cast<float>(learning_rate);
    for (int i = 0; i < kBins; ++i) {
      foreground_[i] = (1.0f - a) * foreground_[i] + a * fg[i];
      background_[i] = (1.0f - a) * background_[i] + a * bg[i];
    }
  }
  ready_ = true;
  update_posterior();
  return true;
}

void ColorHistograms::update_posterior() {
  for (int i = 0; i < kBins; ++i) {
    const float f = foreground_[i] + kBinPrior, b = background_[i] + kBinPrior;
    posterior_[i] = std::clamp(f / (f + b), kMinPosterior, 1.0f - kMinPosterior);
  }
}

}  // namespace kct
