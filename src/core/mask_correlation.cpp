#include "klt_contour_tracker/core/mask_correlation.h"

#include <stdexcept>

namespace kct {

MaskRuns MaskRuns::of(const cv::Mat& mask) {
  if (mask.type() != CV_8UC1) throw std::invalid_argument("MaskRuns::of: the mask must be CV_8UC1");
  MaskRuns result;
  result.size = mask.size();
  for (int r = 0; r < mask.rows; ++r) {
    const uchar* m = mask.ptr<uchar>(r);
    for (int c = 0; c < mask.cols;) {
      if (!m[c]) {
        ++c;
        continue;
      }
      const int begin = c;
      while (c < mask.cols && m[c]) ++c;
      result.runs.push_back({r, begin, c});
      result.pixels += static_cast<std::size_t>(c - begin);
    }
  }
  return result;
}

cv::Mat row_prefix_sums(const cv::Mat& image) {
  if (image.type() != CV_32FC1)
    throw std::invalid_argument("row_prefix_sums: the image must be CV_32FC1");
  cv::Mat prefix(image.rows, image.cols + 1, CV_64FC1);
  for (int r = 0; r < image.rows; ++r) {
    const float* in = image.ptr<float>(r);
    double* out = prefix.ptr<double>(r);
    double sum = 0.0;
    out[0] = 0.0;
    for (int c = 0; c < image.cols; ++c) out[c + 1] = sum += in[c];
  }
  return prefix;
}

cv::Mat correlate_mask(const cv::Mat& prefix, const MaskRuns& mask) {
  if (prefix.type() != CV_64FC1)
    throw std::invalid_argument("correlate_mask: prefix must be row_prefix_sums' CV_64FC1");
  const int image_cols = prefix.cols - 1;
  if (mask.size.width <= 0 || mask.size.height <= 0 || mask.size.width > image_cols ||
      mask.size.height > prefix.rows)
    throw std::invalid_argument("correlate_mask: the mask must be non-empty and fit in the image");
  const int rows = prefix.rows - mask.size.height + 1, cols = image_cols - mask.size.width + 1;
  cv::Mat sums(rows, cols, CV_64FC1, cv::Scalar(0.0));
  for (const MaskRuns::Run& run : mask.runs)
    for (int r = 0; r < rows; ++r) {
      const double* p = prefix.ptr<double>(r + run.row);
      double* out = sums.ptr<double>(r);
      // The run over placements c .. c + cols - 1: prefix(c + end) - prefix(c + begin).
      const double* last = p + run.end;
      const double* first = p + run.begin;
      for (int c = 0; c < cols; ++c) out[c] += last[c] - first[c];
    }
  cv::Mat result;
  sums.convertTo(result, CV_32FC1);
  return result;
}

}  // namespace kct
