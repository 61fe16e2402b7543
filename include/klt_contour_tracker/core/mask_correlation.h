#pragma once
/// \file mask_correlation.h
/// Correlation of a float image with a binary mask, for ObjectSearch's contrast maps: at every
/// placement of the mask inside the image, the sum of the image under the mask's pixels (what
/// cv::matchTemplate's TM_CCORR gives with the mask as a 0/1 float template).
///
/// Ours rather than cv::matchTemplate's, because the template is a mask: its rows are a few runs
/// of pixels, and the sum over a run is the difference of two prefix sums of the image's row.
/// That costs (placements x runs) instead of matchTemplate's DFT of the image and of the template
/// on every call. A lost frame's colour search correlates two masks (silhouette and ring) at 5
/// depths over the whole frame and again at 3 peaks each, where matchTemplate was most of the
/// search (perf, hard2/castle/occlusion: 17 % of all samples). Measured on this machine
/// (silhouette of radius 28 px over 160x120 placements / radius 56 over 6x6): 3.1 -> 1.0 ms and
/// 1.1 -> 0.06 ms for both masks. Sums are accumulated in double and rounded to float once;
/// matchTemplate's DFT differs from them by about 1e-7 of the sum (the tracker's poses on the
/// 240 dev-loop runs came out identical).

#include <opencv2/core.hpp>
#include <vector>

namespace kct {

/// A binary mask as its horizontal runs of set pixels.
struct MaskRuns {
  struct Run {
    int row = 0;    ///< mask row
    int begin = 0;  ///< first set column
    int end = 0;    ///< one past the last set column
  };
  cv::Size size;  ///< the mask's size, px
  std::vector<Run> runs;
  std::size_t pixels = 0;  ///< set pixels

  /// The runs of a CV_8UC1 mask (non-zero = set). Throws std::invalid_argument for another type.
  static MaskRuns of(const cv::Mat& mask);
};

/// Row prefix sums of a CV_32FC1 image: CV_64FC1, rows x (cols + 1), element (r, c) the sum of
/// the image's row r over columns 0 .. c - 1. Throws std::invalid_argument for another type.
cv::Mat row_prefix_sums(const cv::Mat& image);

/// For every placement of `mask` inside the image whose row_prefix_sums are `prefix`, the sum of
/// the image's pixels under the mask's set pixels: CV_32FC1 of (image rows - mask rows + 1) x
/// (image cols - mask cols + 1), element (r, c) for the mask's top-left at image pixel (c, r).
/// Throws std::invalid_argument when the mask is empty-sized or larger than the image, or
/// `prefix` is not CV_64FC1.
cv::Mat correlate_mask(const cv::Mat& prefix, const MaskRuns& mask);

}  // namespace kct
