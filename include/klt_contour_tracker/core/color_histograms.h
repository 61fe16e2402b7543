#pragma once
/// \file color_histograms.h
/// Foreground / background colour statistics of the tracked object (ours, beyond the paper; the
/// model of SRT3D, Stoiber et al. 2020/2022): two normalized RGB histograms learned at trusted
/// poses from pixels just inside and just outside the object's silhouette, and the per-pixel
/// posterior P(foreground | colour) they give.

#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace kct {

/// Normalized foreground and background colour histograms (16 x 16 x 16 BGR bins, as SRT3D).
class ColorHistograms {
 public:
  static constexpr int kBinsPerChannel = 16;
  static constexpr int kBins = kBinsPerChannel * kBinsPerChannel * kBinsPerChannel;

  /// Learns from a BGR frame (CV_8UC3) and a silhouette mask (CV_8UC1, non-zero on the object)
  /// of the same size: foreground = mask pixels within `band_px` of the silhouette's border,
  /// background = non-mask pixels within `band_px` of it (only the colours next to the outline
  /// matter to the cue). The first call sets the histograms; later ones blend:
  /// h = (1 - learning_rate) h + learning_rate h_new, learning_rate in (0, 1]. Returns false
  /// (model unchanged) when either band has fewer than 50 pixels. Throws std::invalid_argument
  /// for a wrong image type or size, band_px < 1 or a learning rate outside (0, 1].
  bool learn(const cv::Mat& bgr, const cv::Mat& mask, int band_px, double learning_rate);

  /// True once learn() succeeded.
  bool ready() const { return ready_; }
  /// Forgets the model.
  void clear();

  /// Bin of a BGR colour.
  static int bin(const cv::Vec3b& bgr) {
    constexpr int shift = 4;  // 256 / kBinsPerChannel = 16 = 2^4
    return ((bgr[0] >> shift) * kBinsPerChannel + (bgr[1] >> shift)) * kBinsPerChannel +
           (bgr[2] >> shift);
  }
  /// P(foreground | colour) = h_f / (h_f + h_b) with equal priors, clamped to
  /// [0.01, 0.99] (never certain: a colour unseen on either side gives 0.5).
  float posterior(const cv::Vec3b& bgr) const { return posterior_[bin(bgr)]; }

  /// Normalized histograms (sum 1 each once ready), for tests and diagnostics.
  const std::vector<float>& foreground() const { return foreground_; }
  const std::vector<float>& background() const { return background_; }

 private:
  void update_posterior();

  bool ready_ = false;
  std::vector<float> foreground_ = std::vector<float>(kBins, 0.0f);
  std::vector<float> background_ = std::vector<float>(kBins, 0.0f);
  std::vector<float> posterior_ = std::vector<float>(kBins, 0.5f);
};

}  // namespace kct
