#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "klt_contour_tracker/core/mask_correlation.h"

namespace kct {
namespace {

/// matchTemplate's TM_CCORR with the mask as a 0/1 float template: the reference.
cv::Mat reference(const cv::Mat& image, const cv::Mat& mask) {
  cv::Mat mask_float, result;
  mask.convertTo(mask_float, CV_32F, 1.0 / 255.0);
  cv::matchTemplate(image, mask_float, result, cv::TM_CCORR);
  return result;
}

cv::Mat random_image(int rows, int cols, unsigned seed) {
  cv::Mat image(rows, cols, CV_32F);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0.0, 1.0);
  return image;
}

/// Expects correlate_mask to equal the reference within `tolerance` (absolute; the sums reach a
/// few hundred, matchTemplate's DFT rounds at ~1e-7 of that).
void expect_matches_reference(const cv::Mat& image, const cv::Mat& mask, double tolerance = 1e-3) {
  const cv::Mat expected = reference(image, mask);
  const cv::Mat actual = correlate_mask(row_prefix_sums(image), MaskRuns::of(mask));
  ASSERT_EQ(actual.type(), CV_32FC1);
  ASSERT_EQ(actual.size(), expected.size());
  EXPECT_LE(cv::norm(actual, expected, cv::NORM_INF), tolerance);
}

TEST(MaskCorrelation, RunsOfAMask) {
  cv::Mat mask = cv::Mat::zeros(3, 6, CV_8UC1);
  mask.at<uchar>(0, 1) = mask.at<uchar>(0, 2) = 255;  // one run of 2
  mask.at<uchar>(1, 0) = mask.at<uchar>(1, 5) = 1;    // two runs of 1 at the row's ends
  // row 2 empty
  const MaskRuns runs = MaskRuns::of(mask);
  EXPECT_EQ(runs.size, mask.size());
  EXPECT_EQ(runs.pixels, 4u);
  ASSERT_EQ(runs.runs.size(), 3u);
  EXPECT_EQ(runs.runs[0].row, 0);
  EXPECT_EQ(runs.runs[0].begin, 1);
  EXPECT_EQ(runs.runs[0].end, 3);
  EXPECT_EQ(runs.runs[1].begin, 0);
  EXPECT_EQ(runs.runs[1].end, 1);
  EXPECT_EQ(runs.runs[2].begin, 5);
  EXPECT_EQ(runs.runs[2].end, 6);
}

TEST(MaskCorrelation, PrefixSumsOfRows) {
  const cv::Mat image = (cv::Mat_<float>(2, 3) << 1, 2, 3, -1, 0.5, 4);
  const cv::Mat prefix = row_prefix_sums(image);
  ASSERT_EQ(prefix.size(), cv::Size(4, 2));
  EXPECT_DOUBLE_EQ(prefix.at<double>(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(prefix.at<double>(0, 3), 6.0);
  EXPECT_DOUBLE_EQ(prefix.at<double>(1, 2), -0.5);
}

TEST(MaskCorrelation, SilhouetteAndRingMatchMatchTemplate) {
  // A turned ellipse and the ring around it, as ObjectSearch correlates them, over a window
  // 6 x 6 placements larger (a fine search) and 160 x 120 larger (a whole coarse frame).
  cv::Mat silhouette = cv::Mat::zeros(79, 79, CV_8UC1);
  cv::ellipse(silhouette, {39, 39}, {28, 18}, 20.0, 0.0, 360.0, 255, cv::FILLED);
  cv::Mat dilated;
  cv::dilate(silhouette, dilated, cv::getStructuringElement(cv::MORPH_ELLIPSE, {17, 17}));
  const cv::Mat ring = dilated & ~silhouette;
  for (const cv::Size placements : {cv::Size(6, 6), cv::Size(160, 120)}) {
    const cv::Mat image = random_image(placements.height + 78, placements.width + 78, 7);
    expect_matches_reference(image, silhouette);
    expect_matches_reference(image, ring);
  }
}

TEST(MaskCorrelation, EdgeCases) {
  const cv::Mat image = random_image(20, 30, 3);
  // A single pixel at the mask's corner, a full mask, a mask the image's own size, a mask with
  // empty rows and columns.
  cv::Mat corner = cv::Mat::zeros(5, 4, CV_8UC1);
  corner.at<uchar>(4, 3) = 255;
  expect_matches_reference(image, corner);
  expect_matches_reference(image, cv::Mat(7, 9, CV_8UC1, cv::Scalar(255)));
  cv::Mat whole = cv::Mat::zeros(20, 30, CV_8UC1);
  cv::circle(whole, {15, 10}, 8, 255, cv::FILLED);
  expect_matches_reference(image, whole);
  cv::Mat sparse = cv::Mat::zeros(9, 9, CV_8UC1);
  sparse.at<uchar>(0, 0) = sparse.at<uchar>(8, 8) = sparse.at<uchar>(4, 2) = 255;
  expect_matches_reference(image, sparse);
  // An all-zero mask correlates to zero everywhere.
  const cv::Mat zeros =
      correlate_mask(row_prefix_sums(image), MaskRuns::of(cv::Mat::zeros(4, 4, CV_8UC1)));
  EXPECT_EQ(cv::countNonZero(zeros), 0);
  EXPECT_EQ(zeros.size(), cv::Size(27, 17));
}

TEST(MaskCorrelation, RejectsWrongInput) {
  const cv::Mat image = random_image(10, 10, 1);
  const cv::Mat prefix = row_prefix_sums(image);
  EXPECT_THROW(MaskRuns::of(cv::Mat::zeros(3, 3, CV_32F)), std::invalid_argument);
  EXPECT_THROW(row_prefix_sums(cv::Mat::zeros(3, 3, CV_8UC1)), std::invalid_argument);
  EXPECT_THROW(correlate_mask(prefix, MaskRuns::of(cv::Mat::zeros(11, 3, CV_8UC1))),
               std::invalid_argument);
  EXPECT_THROW(correlate_mask(prefix, MaskRuns()), std::invalid_argument);
  EXPECT_THROW(correlate_mask(image, MaskRuns::of(cv::Mat::zeros(3, 3, CV_8UC1))),
               std::invalid_argument);
}

}  // namespace
}  // namespace kct
