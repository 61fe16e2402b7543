#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/object_search.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

/// A red-ish untextured box over a blue-ish background; colours learned at `learned_at`, the
/// frame showing the box at `shown_at`.
class ObjectSearchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto mesh = std::make_shared<Mesh>(test::make_box(0.08, 0.06, 0.05, /*textured=*/false));
    mesh->base_color = cv::Vec3b(40, 60, 200);
    mesh_ = mesh;
    renderer_ = std::make_unique<Renderer>(mesh_);
    background_ = cv::Mat(camera_.size(), CV_8UC3, cv::Scalar(200, 120, 40));
  }
  cv::Mat frame_at(const Pose& pose) const {
    return test::render_frame(*renderer_, camera_, pose, background_, 3.0);
  }
  /// Distance between the object centres of two poses, metres.
  double centre_distance(const Pose& a, const Pose& b) const {
    const Eigen::Vector3d c = mesh_->bounding_box_center();
    return (a * c - b * c).norm();
  }

  std::shared_ptr<const Mesh> mesh_;
  std::unique_ptr<Renderer> renderer_;
  const PinholeCamera camera_ = test::make_camera();
  cv::Mat background_;
};

TEST_F(ObjectSearchTest, NotReadyBeforeLearning) {
  ObjectSearch search(mesh_);
  const Pose truth = test::make_pose(0.4);
  EXPECT_FALSE(search.ready());
  EXPECT_TRUE(search.search(frame_at(truth), truth, camera_).empty());
  EXPECT_EQ(search.score(frame_at(truth), truth, camera_).contrast, 0.0);
}

TEST_F(ObjectSearchTest, ContrastIsHighAtTheObjectAndLowBesideIt) {
  ObjectSearch search(mesh_);
  const Pose truth = test::make_pose(0.4);
  const cv::Mat frame = frame_at(truth);
  ASSERT_TRUE(search.learn(frame, truth, camera_));
  const SearchCandidate at_truth = search.score(frame, truth, camera_);
  EXPECT_GT(at_truth.contrast, 0.8);  // two clean colours: posteriors near 0.99 and 0.01
  EXPECT_NEAR(at_truth.visible_fraction, 1.0, 1e-9);
  // Moved sideways by more than the object's size: the silhouette sees only background.
  const Pose beside = test::move(truth, 0, Eigen::Vector3d::UnitZ(), {0.15, 0.0, 0.0});
  EXPECT_LT(search.score(frame, beside, camera_).contrast, 0.1);
}

TEST_F(ObjectSearchTest, VisibleFractionCountsTheSilhouetteOutsideTheImage) {
  ObjectSearch search(mesh_);
  const Pose truth = test::make_pose(0.4);
  ASSERT_TRUE(search.learn(frame_at(truth), truth, camera_));
  // Centre moved to the image's left border: about half of the silhouette is outside.
  Pose at_border = truth;
  const double depth = (truth * mesh_->bounding_box_center()).z();
  at_border.translation().x() += (-0.5 - camera_.cx()) * depth / camera_.fx() -
                                 (truth * mesh_->bounding_box_center()).x();
  const SearchCandidate scored = search.score(frame_at(at_border), at_border, camera_);
  EXPECT_GT(scored.visible_fraction, 0.3);
  EXPECT_LT(scored.visible_fraction, 0.7);
  // Entirely outside.
  const Pose outside = test::move(truth, 0, Eigen::Vector3d::UnitZ(), {1.0, 0.0, 0.0});
  EXPECT_EQ(search.score(frame_at(truth), outside, camera_).visible_fraction, 0.0);
}

TEST_F(ObjectSearchTest, VisibleFractionOfAnObjectLargerThanTheImage) {
  ObjectSearch search(mesh_);
  const Pose truth = test::make_pose(0.4);
  ASSERT_TRUE(search.learn(frame_at(truth), truth, camera_));
  // 6 cm from the camera the box's silhouette is wider than the image. Reference: the share
  // of a full-resolution render on a canvas three images wide that falls in the image.
  const Pose close = test::make_pose(0.06);
  const int pad_x = camera_.width(), pad_y = camera_.height();
  const PinholeCamera canvas_camera(camera_.fx(), camera_.fy(), camera_.cx() + pad_x,
                                    camera_.cy() + pad_y, 3 * pad_x, 3 * pad_y);
  RenderOptions options;
  options.draw_color = false;
  const cv::Mat canvas = renderer_->render(close, canvas_camera, options).mask();
  const double expected = cv::countNonZero(canvas(cv::Rect(pad_x, pad_y, pad_x, pad_y))) /
                          static_cast<double>(cv::countNonZero(canvas));
  ASSERT_LT(expected, 0.9);
  // Scored at half resolution: within 0.02 of the full-resolution share.
  EXPECT_NEAR(search.score(frame_at(close), close, camera_).visible_fraction, expected, 0.02);
  // The box reaching behind the camera: scored on the clipped render, no exception.
  Pose straddling = truth;
  straddling.translation().z() = 0.0;
  const SearchCandidate behind = search.score(frame_at(truth), straddling, camera_);
  EXPECT_GE(behind.visible_fraction, 0.0);
  EXPECT_LE(behind.visible_fraction, 1.0);
}

TEST_F(ObjectSearchTest, FindsTheObjectFarFromTheReferencePose) {
  ObjectSearch search(mesh_);
  const Pose learned_at = test::make_pose(0.4);
  ASSERT_TRUE(search.learn(frame_at(learned_at), learned_at, camera_));
  // The object is now 12 cm to the side, 6 cm lower and 8 cm farther, rotated by 10 deg: far
  // outside any local refinement's reach from the reference.
  const Pose shown_at =
      test::move(learned_at, 10, Eigen::Vector3d(0.3, 1.0, 0.2), {0.12, 0.06, 0.08});
  const std::vector<SearchCandidate> found = search.search(frame_at(shown_at), learned_at, camera_);
  ASSERT_FALSE(found.empty());
  EXPECT_GT(found.front().contrast, 0.6);
  for (std::size_t i = 1; i < found.size(); ++i)
    EXPECT_GE(found[i - 1].contrast, found[i].contrast);  // best first
  // The placement puts the centre within 15 % of the object's distance error and 1.5 cm
  // sideways (the depth is searched in steps of about 15-20 %).
  const Eigen::Vector3d c = mesh_->bounding_box_center();
  const Eigen::Vector3d found_centre = found.front().object_to_camera * c;
  const Eigen::Vector3d true_centre = shown_at * c;
  EXPECT_LT(std::abs(found_centre.z() - true_centre.z()), 0.15 * true_centre.z());
  const Eigen::Vector2d found_px = camera_.project(found_centre);
  const Eigen::Vector2d true_px = camera_.project(true_centre);
  EXPECT_LT((found_px - true_px).norm(), 8.0);
  // The rotation is the reference's (the refinement's job).
  EXPECT_TRUE(found.front().object_to_camera.linear().isApprox(learned_at.linear(), 1e-12));
}

TEST_F(ObjectSearchTest, ResultsDoNotDependOnTheThreadCount) {
  ObjectSearchSettings two_threads;
  two_threads.threads = 2;
  ObjectSearch one(mesh_), two(mesh_, two_threads);
  const Pose learned_at = test::make_pose(0.4);
  ASSERT_TRUE(one.learn(frame_at(learned_at), learned_at, camera_));
  ASSERT_TRUE(two.learn(frame_at(learned_at), learned_at, camera_));
  const Pose shown_at =
      test::move(learned_at, 10, Eigen::Vector3d(0.3, 1.0, 0.2), {0.12, 0.06, 0.08});
  const cv::Mat frame = frame_at(shown_at);
  const std::vector<SearchCandidate> found_one = one.search(frame, learned_at, camera_);
  const std::vector<SearchCandidate> found_two = two.search(frame, learned_at, camera_);
  ASSERT_EQ(found_one.size(), one.settings().depth_scales.size());  // every depth places it
  ASSERT_EQ(found_two.size(), found_one.size());
  std::vector<Pose> poses{shown_at, learned_at};
  for (std::size_t i = 0; i < found_one.size(); ++i) {
    EXPECT_EQ(found_two[i].contrast, found_one[i].contrast);
    EXPECT_EQ(found_two[i].visible_fraction, found_one[i].visible_fraction);
    EXPECT_TRUE(found_two[i].object_to_camera.isApprox(found_one[i].object_to_camera, 0.0));
    poses.push_back(found_one[i].object_to_camera);
  }
  const std::vector<SearchCandidate> scored_one = one.score(frame, poses, camera_);
  const std::vector<SearchCandidate> scored_two = two.score(frame, poses, camera_);
  ASSERT_EQ(scored_two.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(scored_two[i].contrast, scored_one[i].contrast);
    EXPECT_EQ(scored_two[i].visible_fraction, scored_one[i].visible_fraction);
    EXPECT_TRUE(scored_two[i].object_to_camera.isApprox(poses[i], 0.0));
  }
  EXPECT_GT(scored_two[0].contrast, 0.8);  // at the object
  // Changing the thread count keeps the learned colours.
  two.set_threads(1);
  EXPECT_EQ(two.settings().threads, 1);
  EXPECT_EQ(two.score(frame, shown_at, camera_).contrast, scored_one[0].contrast);
  EXPECT_THROW(two.set_threads(0), std::invalid_argument);
}

TEST_F(ObjectSearchTest, FindsAnObjectEnteringTheImage) {
  ObjectSearch search(mesh_);
  const Pose learned_at = test::make_pose(0.4);
  ASSERT_TRUE(search.learn(frame_at(learned_at), learned_at, camera_));
  // Centre 20 px inside the left border: a bit over half of the box is in the image.
  Pose entering = learned_at;
  const Eigen::Vector3d c = learned_at * mesh_->bounding_box_center();
  entering.translation().x() += (20.0 - camera_.cx()) * c.z() / camera_.fx() - c.x();
  const std::vector<SearchCandidate> found = search.search(frame_at(entering), learned_at, camera_);
  ASSERT_FALSE(found.empty());
  const Eigen::Vector2d found_px =
      camera_.project(found.front().object_to_camera * mesh_->bounding_box_center());
  const Eigen::Vector2d true_px = camera_.project(entering * mesh_->bounding_box_center());
  EXPECT_LT((found_px - true_px).norm(), 8.0);
  EXPECT_LT(found.front().visible_fraction, 0.9);
}

TEST_F(ObjectSearchTest, AReachKeepsTheSearchNearTheReference) {
  ObjectSearch search(mesh_);
  const Pose learned_at = test::make_pose(0.4);
  ASSERT_TRUE(search.learn(frame_at(learned_at), learned_at, camera_));
  // Two copies of the object: one 2 cm beside the reference with a background-coloured bar
  // across its middle (a weaker match), a twin 15 cm away, whole (the better match).
  const Pose near = test::move(learned_at, 0, Eigen::Vector3d::UnitZ(), {0.02, 0.0, 0.0});
  const Pose twin = test::move(learned_at, 0, Eigen::Vector3d::UnitZ(), {-0.15, 0.0, 0.0});
  cv::Mat frame = frame_at(twin);
  const cv::Mat near_frame = frame_at(near);
  cv::Mat near_mask = renderer_->render(near, camera_).mask();
  near_frame.copyTo(frame, near_mask);
  const Eigen::Vector3d c = mesh_->bounding_box_center();
  const Eigen::Vector2d near_px = camera_.project(near * c), twin_px = camera_.project(twin * c);
  cv::rectangle(frame, cv::Point2d(near_px.x() - 80, near_px.y() - 8),
                cv::Point2d(near_px.x() + 80, near_px.y() + 8), cv::Scalar(200, 120, 40), cv::FILLED);
  const auto found_px = [&](double reach_px) {
    const std::vector<SearchCandidate> found = search.search(frame, learned_at, camera_, reach_px);
    EXPECT_FALSE(found.empty());
    return found.empty() ? Eigen::Vector2d(-1e9, -1e9)
                         : Eigen::Vector2d(camera_.project(found.front().object_to_camera * c));
  };
  // The whole frame: the twin wins; within 60 px of the reference's centre: the near copy
  // (its placement may slide along the bar: 25 px, where the twin is 250 px away).
  EXPECT_LT((found_px(0.0) - twin_px).norm(), 8.0);
  const Eigen::Vector2d reference_px = camera_.project(learned_at * c);
  ASSERT_GT((twin_px - reference_px).norm(), 150.0);  // the twin is out of reach
  EXPECT_LT((found_px(60.0) - near_px).norm(), 25.0);
  for (const SearchCandidate& candidate : search.search(frame, learned_at, camera_, 60.0))
    EXPECT_LE((camera_.project(candidate.object_to_camera * c) - reference_px).norm(), 60.0 + 2.0);
}

TEST_F(ObjectSearchTest, AReachAtTheImageBorderFindsWhatTheWholeFrameFinds) {
  // The search within a reach correlates only the window the reach covers: at the border, with
  // the reference's centre outside the image, it must find the placement the whole frame finds.
  ObjectSearch search(mesh_);
  const Pose learned_at = test::make_pose(0.4);
  ASSERT_TRUE(search.learn(frame_at(learned_at), learned_at, camera_));
  const Eigen::Vector3d c = mesh_->bounding_box_center();
  const auto centred_at_x = [&](double x_px) {
    Pose pose = learned_at;
    const Eigen::Vector3d centre = learned_at * c;
    pose.translation().x() += (x_px - camera_.cx()) * centre.z() / camera_.fx() - centre.x();
    return pose;
  };
  const cv::Mat frame = frame_at(centred_at_x(20.0));  // a bit over half the box in the image
  const Pose reference = centred_at_x(-15.0);          // its centre 15 px left of the image
  const std::vector<SearchCandidate> whole = search.search(frame, reference, camera_);
  const std::vector<SearchCandidate> near = search.search(frame, reference, camera_, 80.0);
  ASSERT_FALSE(whole.empty());
  ASSERT_FALSE(near.empty());
  const Eigen::Vector2d whole_px = camera_.project(whole.front().object_to_camera * c);
  const Eigen::Vector2d near_px = camera_.project(near.front().object_to_camera * c);
  EXPECT_LT((near_px - whole_px).norm(), 1e-6);
  EXPECT_NEAR(near.front().contrast, whole.front().contrast, 1e-5);
  EXPECT_NEAR(near.front().visible_fraction, whole.front().visible_fraction, 1e-9);
  EXPECT_LT(std::abs(near_px.x() - 20.0), 8.0);
  // A reach that covers no pixel of the image: nothing, and no exception.
  EXPECT_TRUE(search.search(frame, centred_at_x(-200.0), camera_, 60.0).empty());
}

TEST_F(ObjectSearchTest, CoarseToFineFindsWhatTheWorkingSizeFinds) {
  // The coarse level only chooses where to look at the working size: on a moved object, one
  // entering the image and a scene with a weaker twin, both searches give the same placements.
  ObjectSearchSettings working_only;
  working_only.coarse_to_fine = false;
  ObjectSearch coarse(mesh_), fine(mesh_, working_only);
  ASSERT_TRUE(coarse.settings().coarse_to_fine);
  const Pose learned_at = test::make_pose(0.4);
  ASSERT_TRUE(coarse.learn(frame_at(learned_at), learned_at, camera_));
  ASSERT_TRUE(fine.learn(frame_at(learned_at), learned_at, camera_));
  const Eigen::Vector3d c = mesh_->bounding_box_center();
  Pose entering = learned_at;
  const Eigen::Vector3d centre = learned_at * c;
  entering.translation().x() += (20.0 - camera_.cx()) * centre.z() / camera_.fx() - centre.x();
  cv::Mat twins = frame_at(test::move(learned_at, 0, Eigen::Vector3d::UnitZ(), {-0.15, 0.0, 0.0}));
  const Pose weaker = test::move(learned_at, 20, Eigen::Vector3d::UnitY(), {0.1, 0.02, 0.0});
  frame_at(weaker).copyTo(twins, renderer_->render(weaker, camera_).mask());
  const std::vector<cv::Mat> frames{
      frame_at(test::move(learned_at, 10, Eigen::Vector3d(0.3, 1.0, 0.2), {0.12, 0.06, 0.08})),
      frame_at(entering), twins};
  for (std::size_t f = 0; f < frames.size(); ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const std::vector<SearchCandidate> a = coarse.search(frames[f], learned_at, camera_);
    const std::vector<SearchCandidate> b = fine.search(frames[f], learned_at, camera_);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_FALSE(a.empty());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_LT((camera_.project(a[i].object_to_camera * c) - camera_.project(b[i].object_to_camera * c)).norm(),
                1e-6);
      EXPECT_NEAR(a[i].contrast, b[i].contrast, 1e-6);
      EXPECT_NEAR(a[i].visible_fraction, b[i].visible_fraction, 1e-6);
    }
  }
}

TEST_F(ObjectSearchTest, GreyFramesStoredAsColourAreRecognized) {
  const cv::Mat colour = frame_at(test::make_pose(0.4));
  EXPECT_FALSE(ObjectSearch::looks_grey(colour));
  cv::Mat grey, grey_bgr;
  cv::cvtColor(colour, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(grey, grey_bgr, cv::COLOR_GRAY2BGR);
  EXPECT_TRUE(ObjectSearch::looks_grey(grey_bgr));
}

TEST(SilhouetteRing, IsTheDiscDilationMinusTheMask) {
  // Against OpenCV's dilation by the same disc: shapes touching the borders, a single pixel,
  // thin lines and noise, rings of 1 to 25 px.
  cv::RNG rng(7);
  for (int trial = 0; trial < 12; ++trial) {
    cv::Mat mask(37 + 11 * trial, 53 + 7 * trial, CV_8UC1, cv::Scalar(0));
    cv::ellipse(mask, cv::Point(rng.uniform(0, mask.cols), rng.uniform(0, mask.rows)),
                cv::Size(rng.uniform(1, 30), rng.uniform(1, 20)), rng.uniform(0.0, 180.0), 0, 360,
                cv::Scalar(255), cv::FILLED);
    cv::line(mask, cv::Point(0, rng.uniform(0, mask.rows)),
             cv::Point(mask.cols - 1, rng.uniform(0, mask.rows)), cv::Scalar(255), 1);
    mask.at<uchar>(rng.uniform(0, mask.rows), rng.uniform(0, mask.cols)) = 255;
    if (trial % 3 == 0) {
      cv::Mat noise(mask.size(), CV_8UC1);
      rng.fill(noise, cv::RNG::UNIFORM, 0, 100);
      mask.setTo(255, noise < 2);
    }
    for (const int ring_px : {1, 2, 3, 5, 8, 13, 25}) {
      cv::Mat dilated;
      cv::dilate(mask, dilated,
                 cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * ring_px + 1, 2 * ring_px + 1}));
      const cv::Mat expected = dilated & ~mask;
      const cv::Mat ring = silhouette_ring(mask, ring_px);
      ASSERT_EQ(ring.size(), mask.size());
      ASSERT_EQ(ring.type(), CV_8UC1);
      EXPECT_EQ(cv::countNonZero(ring != expected), 0) << "trial " << trial << ", ring " << ring_px;
      EXPECT_GT(cv::countNonZero(ring), 0);
    }
  }
  // Empty mask: empty ring. Bad input: an exception.
  EXPECT_EQ(cv::countNonZero(silhouette_ring(cv::Mat::zeros(20, 30, CV_8UC1), 4)), 0);
  EXPECT_THROW(silhouette_ring(cv::Mat::zeros(20, 30, CV_32F), 4), std::invalid_argument);
  EXPECT_THROW(silhouette_ring(cv::Mat::zeros(20, 30, CV_8UC1), 0), std::invalid_argument);
}

TEST(ObjectSearchSettings, RejectsBadValues) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.08, 0.06, 0.05));
  ObjectSearchSettings settings;
  settings.depth_scales.clear();
  EXPECT_THROW(ObjectSearch(mesh, settings), std::invalid_argument);
  settings = {};
  settings.min_visible_fraction = 0.0;
  EXPECT_THROW(ObjectSearch(mesh, settings), std::invalid_argument);
  settings = {};
  settings.learning_rate = 2.0;
  EXPECT_THROW(ObjectSearch(mesh, settings), std::invalid_argument);
  settings = {};
  settings.threads = 0;
  EXPECT_THROW(ObjectSearch(mesh, settings), std::invalid_argument);
  EXPECT_THROW(ObjectSearch(nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace kct
