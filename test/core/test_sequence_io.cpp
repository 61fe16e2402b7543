#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "klt_contour_tracker/core/sequence_io.h"

namespace {

class SequenceIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("kct_test_sequence_io_" +
            std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  void write_text(const std::string& name, const std::string& text) const {
    std::ofstream(file(name)) << text;
  }
  /// Expects `call` to throw std::runtime_error whose message contains every `parts`.
  template <typename Call>
  void expect_error(Call call, std::initializer_list<std::string> parts) const {
    try {
      call();
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      for (const auto& part : parts)
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
            << "'" << part << "' missing in: " << e.what();
    }
  }

  std::filesystem::path dir_;
};

kct::Pose some_pose(int i) {
  kct::Pose pose = kct::Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(0.3 + 0.7 * i, Eigen::Vector3d(1, 2 - i, 0.5).normalized())
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.01 * i, -0.02, 0.4 + 0.013 * i);
  return pose;
}

}  // namespace

TEST_F(SequenceIo, WriteReadRoundTrip) {
  const cv::Matx33d K(525.5, 0, 319.25, 0, 524.75, 241.125, 0, 0, 1);
  std::vector<kct::Pose> poses;
  for (int i = 0; i < 5; ++i) poses.push_back(some_pose(i));
  kct::write_intrinsics(file("K.txt"), K);
  kct::write_pose_file(file("pose.txt"), poses);  // more poses than images is allowed
  const cv::Mat image(8, 8, CV_8UC3, cv::Scalar(1, 2, 3));
  for (int i : {2, 0, 1}) ASSERT_TRUE(cv::imwrite(file(kct::frame_file_name(i)), image));
  write_text("notes.txt", "not an image\n");

  const kct::SequenceFolder sequence = kct::read_sequence(dir_.string());
  ASSERT_EQ(sequence.image_paths.size(), 3u);
  EXPECT_EQ(sequence.image_paths[0], file("000000.png"));
  EXPECT_EQ(sequence.image_paths[1], file("000001.png"));
  EXPECT_EQ(sequence.image_paths[2], file("000002.png"));
  EXPECT_EQ(sequence.K, K);
  ASSERT_EQ(sequence.poses.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i)
    EXPECT_LT((sequence.poses[i].matrix() - poses[i].matrix()).norm(), 1e-12) << i;
  EXPECT_EQ(kct::frame_file_name(12), "000012.png");
}

TEST_F(SequenceIo, LenientFormatting) {
  // Commas, comments, blank lines, 6-decimal rotations (projected onto SO(3)).
  write_text("pose.txt",
             "# r11 r12 r13 r21 r22 r23 r31 r32 r33 tx ty tz\n\n"
             "1,0,0, 0,1,0, 0,0,1, 0.1,0.2,0.3\n"
             "0.866025 -0.5 0 0.5 0.866025 0 0 0 1 0 0 0.5\n");
  const auto poses = kct::read_pose_file(file("pose.txt"));
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_LT((poses[0].translation() - Eigen::Vector3d(0.1, 0.2, 0.3)).norm(), 1e-15);
  EXPECT_TRUE(kct::is_valid_pose(poses[1]));
  EXPECT_NEAR(poses[1].linear()(1, 0), 0.5, 1e-6);
  write_text("K.txt", "500, 0, 320,\n0, 500, 240,\n0, 0, 1\n");
  EXPECT_EQ(kct::read_intrinsics(file("K.txt"))(0, 2), 320.0);
}

TEST_F(SequenceIo, MalformedPoseLineThrowsNamingFileAndLine) {
  const std::string good = "1 0 0 0 1 0 0 0 1 0 0 0.5\n";
  write_text("short.txt", good + good + "1 0 0 0 1 0 0 0 1 0 0\n");
  expect_error([&] { kct::read_pose_file(file("short.txt")); }, {file("short.txt"), "line 3"});
  write_text("word.txt", good + "1 0 0 0 1 0 0 0 one 0 0 0.5\n");
  expect_error([&] { kct::read_pose_file(file("word.txt")); }, {"line 2", "one"});
  write_text("not_rotation.txt", "2 0 0 0 1 0 0 0 1 0 0 0.5\n");
  expect_error([&] { kct::read_pose_file(file("not_rotation.txt")); }, {"line 1", "rotation"});
  write_text("mirror.txt", "-1 0 0 0 1 0 0 0 1 0 0 0.5\n");
  expect_error([&] { kct::read_pose_file(file("mirror.txt")); }, {"line 1"});
  expect_error([&] { kct::read_pose_file(file("missing.txt")); }, {file("missing.txt")});
}

TEST_F(SequenceIo, MissingOrBadIntrinsicsAndEmptyFolders) {
  const cv::Mat image(4, 4, CV_8UC3, cv::Scalar::all(0));
  ASSERT_TRUE(cv::imwrite(file("000000.png"), image));
  expect_error([&] { kct::read_sequence(dir_.string()); }, {file("K.txt")});
  write_text("K.txt", "500 0 320 0 500 240 0 0\n");
  expect_error([&] { kct::read_sequence(dir_.string()); }, {file("K.txt"), "9 numbers"});
  write_text("K.txt", "0 0 320 0 500 240 0 0 1\n");
  expect_error([&] { kct::read_sequence(dir_.string()); }, {file("K.txt")});
  write_text("K.txt", "500 0 320 0 500 240 0 0 1\n");
  const auto sequence = kct::read_sequence(dir_.string());  // no pose.txt: no ground truth
  EXPECT_EQ(sequence.image_paths.size(), 1u);
  EXPECT_TRUE(sequence.poses.empty());

  std::filesystem::remove(file("000000.png"));
  expect_error([&] { kct::read_sequence(dir_.string()); }, {"no images", dir_.string()});
  expect_error([&] { kct::read_sequence(file("nope")); }, {file("nope")});
}

TEST_F(SequenceIo, ImageSizeFromTheHeaderOfPngJpegAndBmp) {
  const cv::Mat image(37, 61, CV_8UC3, cv::Scalar(10, 200, 30));
  for (const std::string name : {"a.png", "b.jpg", "c.bmp"}) {
    ASSERT_TRUE(cv::imwrite(file(name), image)) << name;
    const cv::Size size = kct::read_image_size(file(name));
    EXPECT_EQ(size, cv::Size(61, 37)) << name;
  }
  const cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(7));
  ASSERT_TRUE(cv::imwrite(file("grey.jpg"), grey));
  EXPECT_EQ(kct::read_image_size(file("grey.jpg")), cv::Size(640, 480));
  write_text("text.png", "not an image");
  expect_error([&] { kct::read_image_size(file("text.png")); }, {"text.png", "not a PNG, JPEG or BMP"});
  write_text("short.png", "\x89PNG");
  expect_error([&] { kct::read_image_size(file("short.png")); }, {"short.png", "truncated"});
  expect_error([&] { kct::read_image_size(file("missing.png")); }, {"missing.png", "cannot open"});
}

TEST_F(SequenceIo, PosesAreConvertedFromModelUnitsOnReadAndBackOnWrite) {
  kct::Pose pose = kct::Pose::Identity();
  pose.translation() = Eigen::Vector3d(0.01, 0.02, 0.5);
  write_text("K.txt", "500 0 320\n0 500 240\n0 0 1\n");
  cv::imwrite(file("000000.png"), cv::Mat(4, 4, CV_8UC1, cv::Scalar(0)));
  kct::write_pose_file(file("pose.txt"), {pose}, kct::ModelUnits(0.001));
  EXPECT_NEAR(kct::read_pose_file(file("pose.txt"))[0].translation().z(), 500.0, 1e-9);
  const kct::SequenceFolder in_mm = kct::read_sequence(dir_.string(), kct::ModelUnits(0.001));
  EXPECT_NEAR((in_mm.poses[0].translation() - pose.translation()).norm(), 0.0, 1e-15);
  // Read as metres, the same file puts the object 500 m away: the unit is the caller's to give.
  EXPECT_NEAR(kct::read_sequence(dir_.string()).poses[0].translation().z(), 500.0, 1e-9);
}
