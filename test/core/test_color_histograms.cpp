#include <gtest/gtest.h>

#include <numeric>
#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/color_histograms.h"

namespace kct {
namespace {

const cv::Vec3b kRed(30, 40, 220), kBlue(220, 60, 30), kGreen(40, 200, 40);

/// A red disc of radius 60 px on a blue 320x240 image, and its mask.
void red_disc(cv::Mat& image, cv::Mat& mask, const cv::Vec3b& background = kBlue) {
  image.create(240, 320, CV_8UC3);
  image.setTo(cv::Scalar(background[0], background[1], background[2]));
  mask = cv::Mat::zeros(240, 320, CV_8UC1);
  cv::circle(mask, {160, 120}, 60, 255, cv::FILLED);
  image.setTo(cv::Scalar(kRed[0], kRed[1], kRed[2]), mask);
}

TEST(ColorHistograms, SeparatesObjectAndBackgroundColours) {
  cv::Mat image, mask;
  red_disc(image, mask);
  ColorHistograms histograms;
  EXPECT_FALSE(histograms.ready());
  EXPECT_FLOAT_EQ(histograms.posterior(kRed), 0.5f);
  ASSERT_TRUE(histograms.learn(image, mask, 8, 0.2));
  EXPECT_TRUE(histograms.ready());
  EXPECT_NEAR(std::accumulate(histograms.foreground().begin(), histograms.foreground().end(), 0.0),
              1.0, 1e-4);
  EXPECT_NEAR(std::accumulate(histograms.background().begin(), histograms.background().end(), 0.0),
              1.0, 1e-4);
  EXPECT_GT(histograms.posterior(kRed), 0.98f);
  EXPECT_LT(histograms.posterior(kBlue), 0.02f);
  EXPECT_FLOAT_EQ(histograms.posterior(kGreen), 0.5f);  // never seen: no information
  // Colours in the same bin (16 levels per channel) share the posterior.
  EXPECT_FLOAT_EQ(histograms.posterior(cv::Vec3b(31, 41, 221)), histograms.posterior(kRed));
}

TEST(ColorHistograms, BlendsWithTheLearningRate) {
  cv::Mat image, mask;
  red_disc(image, mask);
  ColorHistograms histograms;
  ASSERT_TRUE(histograms.learn(image, mask, 8, 0.2));
  // The background turns green: after one update blue still counts as background (weight 0.8)
  // and green has weight 0.2 there; after many updates the old blue fades out.
  red_disc(image, mask, kGreen);
  ASSERT_TRUE(histograms.learn(image, mask, 8, 0.2));
  const int blue = ColorHistograms::bin(kBlue), green = ColorHistograms::bin(kGreen);
  EXPECT_NEAR(histograms.background()[blue], 0.8, 1e-5);
  EXPECT_NEAR(histograms.background()[green], 0.2, 1e-5);
  EXPECT_LT(histograms.posterior(kGreen), 0.02f);
  for (int i = 0; i < 40; ++i) ASSERT_TRUE(histograms.learn(image, mask, 8, 0.2));
  EXPECT_LT(histograms.background()[blue], 1e-3);
  histograms.clear();
  EXPECT_FALSE(histograms.ready());
  EXPECT_FLOAT_EQ(histograms.posterior(kGreen), 0.5f);
}

TEST(ColorHistograms, SameColourBothSidesGivesNoInformation) {
  cv::Mat image, mask;
  red_disc(image, mask, kRed);  // the background has the object's colour
  ColorHistograms histograms;
  ASSERT_TRUE(histograms.learn(image, mask, 8, 1.0));
  EXPECT_NEAR(histograms.posterior(kRed), 0.5f, 1e-6);
}

TEST(ColorHistograms, ObjectCutByTheImageBorder) {
  // The disc half outside the image (the bands are computed in a region around the object):
  // the outline's colours are still learned.
  cv::Mat image(240, 320, CV_8UC3, cv::Scalar(kBlue[0], kBlue[1], kBlue[2]));
  cv::Mat mask = cv::Mat::zeros(240, 320, CV_8UC1);
  cv::circle(mask, {0, 120}, 60, 255, cv::FILLED);
  image.setTo(cv::Scalar(kRed[0], kRed[1], kRed[2]), mask);
  ColorHistograms histograms;
  ASSERT_TRUE(histograms.learn(image, mask, 8, 1.0));
  EXPECT_GT(histograms.posterior(kRed), 0.98f);
  EXPECT_LT(histograms.posterior(kBlue), 0.02f);
}

TEST(ColorHistograms, TooFewPixelsAndBadInput) {
  cv::Mat image, mask;
  red_disc(image, mask);
  ColorHistograms histograms;
  EXPECT_FALSE(histograms.learn(image, cv::Mat::zeros(image.size(), CV_8UC1), 8, 0.2));
  EXPECT_FALSE(histograms.ready());
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  EXPECT_THROW(histograms.learn(grey, mask, 8, 0.2), std::invalid_argument);
  EXPECT_THROW(histograms.learn(image, mask(cv::Rect(0, 0, 10, 10)), 8, 0.2),
               std::invalid_argument);
  EXPECT_THROW(histograms.learn(image, mask, 0, 0.2), std::invalid_argument);
  EXPECT_THROW(histograms.learn(image, mask, 8, 0.0), std::invalid_argument);
  EXPECT_THROW(histograms.learn(image, mask, 8, 1.5), std::invalid_argument);
}

}  // namespace
}  // namespace kct
