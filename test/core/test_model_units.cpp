// ModelUnits: the one conversion between model units and metres.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "klt_contour_tracker/core/model_units.h"

namespace kct {
namespace {

Pose a_pose() {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(12.5, -30.0, 450.0);  // millimetres
  return pose;
}

TEST(ModelUnits, MillimetresScaleTranslationsNotRotations) {
  const ModelUnits mm(0.001);
  const Pose in_mm = a_pose();
  const Pose in_m = mm.to_metres(in_mm);
  EXPECT_NEAR((in_m.translation() - Eigen::Vector3d(0.0125, -0.03, 0.45)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((in_m.linear() - in_mm.linear()).norm(), 0.0, 0.0);
  // Round trip to 1 ulp-level rounding.
  EXPECT_NEAR((mm.from_metres(in_m).translation() - in_mm.translation()).norm(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(mm.to_metres(250.0), 0.25);
  EXPECT_DOUBLE_EQ(mm.from_metres(0.25), 250.0);
  const auto many = mm.to_metres(std::vector<Pose>{in_mm, in_mm});
  ASSERT_EQ(many.size(), 2u);
  EXPECT_NEAR(many[1].translation().z(), 0.45, 1e-15);
  EXPECT_FALSE(mm.is_metres());
  EXPECT_TRUE(ModelUnits().is_metres());
  EXPECT_NEAR((ModelUnits().to_metres(in_mm).translation() - in_mm.translation()).norm(), 0.0, 0.0);
}

TEST(ModelUnits, RejectsScalesOutsideTheRangeNamingIt) {
  for (double bad : {0.0, -0.001, 1e-9, 1e300, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    try {
      ModelUnits units(bad);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("model scale"), std::string::npos) << what;
      EXPECT_NE(what.find("allowed"), std::string::npos) << what;
    }
  }
  EXPECT_NO_THROW(ModelUnits{ModelUnits::kMinScale});
  EXPECT_NO_THROW(ModelUnits{ModelUnits::kMaxScale});
}

}  // namespace
}  // namespace kct
