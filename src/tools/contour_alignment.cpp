/// \file contour_alignment.cpp
/// Scores poses on footage WITHOUT ground truth (the benchmark's real section): how well the
/// model's projected outline lies on image edges, and how long the track holds. This is NOT
/// the AUC of the paper's metric and not comparable with it.
///
///   contour_alignment --sequence DIR --model MESH --poses FILE [--model-scale S]
///                     [--tolerance-px 2] [--per-frame FILE] [--summary-json FILE]
///
/// Per frame: the model is rendered at the pose (silhouette, Renderer); its outline pixels
/// inside the image (3 px margin) are the samples; the frame's edges are Canny's (grey image,
/// Gaussian sigma 1 px, hysteresis thresholds 40 / 100 grey levels). alignment = fraction of
/// outline samples within --tolerance-px of an edge pixel (0..1). chance = fraction of all
/// image pixels within the same distance of an edge: what a randomly placed outline would
/// score. held_frames = frames before the first 5 consecutive frames whose alignment is below
/// max(chance, 0.5 x the first frame's alignment) (the first pose is the given initial pose;
/// a frame with no outline in the image counts as below).
#include <algorithm>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/renderer.h"
#include "klt_contour_tracker/core/sequence_io.h"
#include "tool_args.h"

namespace {

const char* kUsage =
    "usage: contour_alignment --sequence DIR --model MESH --poses FILE [--model-scale S]\n"
    "                         [--tolerance-px 2] [--per-frame FILE] [--summary-json FILE]\n";

struct FrameScore {
  double alignment = 0.0;  ///< fraction of outline samples near an edge, 0..1
  double chance = 0.0;     ///< fraction of image pixels near an edge
  int samples = 0;
};

FrameScore score_frame(const cv::Mat& image, const kct::Renderer& renderer, const kct::Pose& pose,
                       const kct::PinholeCamera& camera, double tolerance_px) {
  cv::Mat grey, edges, distance;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::GaussianBlur(grey, grey, cv::Size(0, 0), 1.0);
  cv::Canny(grey, edges, 40, 100);
  cv::distanceTransform(255 - edges, distance, cv::DIST_L2, 3);
  FrameScore score;
  score.chance = cv::countNonZero(distance <= tolerance_px) / static_cast<double>(distance.total());
  kct::RenderOptions depth_only;
  depth_only.draw_color = false;
  const cv::Mat mask = renderer.render(pose, camera, depth_only).mask();
  std::vector<std::vector<cv::Point>> outlines;
  cv::findContours(mask, outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  int near = 0;
  for (const auto& outline : outlines)
    for (const cv::Point& p : outline) {
      if (p.x < 3 || p.y < 3 || p.x >= image.cols - 3 || p.y >= image.rows - 3) continue;
      ++score.samples;
      if (distance.at<float>(p) <= tolerance_px) ++near;
    }
  score.alignment = score.samples ? static_cast<double>(near) / score.samples : 0.0;
  return score;
}

}  // namespace

int main(int argc, char** argv) {
  std::string sequence_dir, model, poses_path, per_frame, summary_json;
  double model_scale = 1.0, tolerance_px = 2.0;
  try {
    using kct_tools::store;
    if (!kct_tools::parse_tool_options(argc, argv,
                                       {{"--sequence", store(sequence_dir)},
                                        {"--model", store(model)},
                                        {"--poses", store(poses_path)},
                                        {"--model-scale", store(model_scale)},
                                        {"--tolerance-px", store(tolerance_px)},
                                        {"--per-frame", store(per_frame)},
                                        {"--summary-json", store(summary_json)}})) {
      std::cout << kUsage;
      return 0;
    }
    if (sequence_dir.empty() || model.empty() || poses_path.empty())
      throw std::invalid_argument("--sequence, --model and --poses are required");
    if (!(tolerance_px > 0.0 && tolerance_px < 50.0))
      throw std::invalid_argument("--tolerance-px must be in (0, 50)");
  } catch (const std::exception& e) {
    std::cerr << "contour_alignment: " << e.what() << "\n" << kUsage;
    return 2;
  }
  try {
    const kct::SequenceFolder sequence = kct::read_sequence(sequence_dir);
    std::vector<kct::Pose> poses = kct::read_pose_file(poses_path);
    // Poses are in model units (as track_sequence writes them): scale the translations to metres.
    for (auto& pose : poses) pose.translation() *= model_scale;
    auto mesh = std::make_shared<const kct::Mesh>(kct::load_mesh(model, model_scale));
    const kct::Renderer renderer(mesh);
    const size_t frames = std::min(poses.size(), sequence.image_paths.size());
    if (frames == 0) throw std::runtime_error("no frames with a pose");
    std::vector<FrameScore> scores;
    for (size_t i = 0; i < frames; ++i) {
      const cv::Mat image = cv::imread(sequence.image_paths[i], cv::IMREAD_COLOR);
      if (image.empty()) throw std::runtime_error(sequence.image_paths[i] + ": cannot read image");
      const kct::PinholeCamera camera = kct::PinholeCamera::from_matrix(sequence.K, image.cols, image.rows);
      scores.push_back(score_frame(image, renderer, poses[i], camera, tolerance_px));
    }
    double mean_alignment = 0.0, mean_chance = 0.0;
    for (const auto& s : scores) mean_alignment += s.alignment, mean_chance += s.chance;
    mean_alignment /= frames;
    mean_chance /= frames;
    const double threshold = std::max(mean_chance, 0.5 * scores.front().alignment);
    size_t held = frames;
    for (size_t i = 0, run = 0; i < frames; ++i) {
      run = scores[i].alignment < threshold ? run + 1 : 0;
      if (run == 5) {
        held = i - 4;
        break;
      }
    }
    if (!per_frame.empty()) {
      std::ofstream out(per_frame);
      out << "# frame alignment chance outline_samples\n";
      for (size_t i = 0; i < frames; ++i)
        out << i << " " << scores[i].alignment << " " << scores[i].chance << " " << scores[i].samples << "\n";
      if (!out) throw std::runtime_error(per_frame + ": cannot write");
    }
    std::printf("frames            %zu\n", frames);
    std::printf("alignment         %.4f  (fraction of outline samples within %.1f px of a Canny edge)\n",
                mean_alignment, tolerance_px);
    std::printf("chance            %.4f  (fraction of image pixels within %.1f px of an edge)\n",
                mean_chance, tolerance_px);
    std::printf("first_frame       %.4f\n", scores.front().alignment);
    std::printf("held_frames       %zu\n", held);
    if (!summary_json.empty()) {
      std::ofstream out(summary_json);
      out << std::setprecision(6) << "{\n  \"frames\": " << frames << ",\n  \"alignment\": " << mean_alignment
          << ",\n  \"chance\": " << mean_chance << ",\n  \"first_frame_alignment\": " << scores.front().alignment
          << ",\n  \"held_frames\": " << held << ",\n  \"tolerance_px\": " << tolerance_px << "\n}\n";
      if (!out) throw std::runtime_error(summary_json + ": cannot write");
    }
  } catch (const std::exception& e) {
    std::cerr << "contour_alignment: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
