#include "klt_contour_tracker/core/sequence_run.h"

#include <chrono>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "klt_contour_tracker/core/elapsed.h"
#include "klt_contour_tracker/core/metrics.h"

namespace kct {
namespace {

/// "" when the frame's header says it can be decoded: a PNG/JPEG/BMP of the camera's size
/// within the pixel bound; else why not.
std::string check_frame_file(const std::string& path, const cv::Size& expected,
                             std::int64_t max_pixels) {
  cv::Size size;
  try {
    size = read_image_size(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  const std::int64_t pixels = std::int64_t{size.width} * size.height;
  const std::string dims = std::to_string(size.width) + "x" + std::to_string(size.height);
  if (pixels > max_pixels)
    return path + ": image is " + dims + " (" + std::to_string(pixels) +
           " pixels); allowed: at most " + std::to_string(max_pixels) + " pixels, not decoded";
  if (expected.area() > 0 && size != expected)
    return path + ": image is " + dims + " but the sequence's first frame is " +
           std::to_string(expected.width) + "x" + std::to_string(expected.height);
  return "";
}

}  // namespace

SequenceRun track_sequence_folder(const SequenceFolder& sequence, std::shared_ptr<const Mesh> mesh,
                                  const TrackerParams& params, const SequenceRunOptions& options) {
  if (sequence.poses.empty())
    throw std::runtime_error("the sequence has no pose.txt; its first line is the initial pose");
  if (sequence.image_paths.empty()) throw std::runtime_error("the sequence has no images");
  if (!(options.camera_rate_hz >= 0.0) || !std::isfinite(options.camera_rate_hz))
    throw std::invalid_argument("camera_rate_hz must be finite and >= 0 (0: every frame)");
  std::size_t frames = sequence.image_paths.size();
  if (options.max_frames > 0) frames = std::min(frames, options.max_frames);

  SequenceRun run;
  const std::string& first_path = sequence.image_paths.front();
  if (const std::string error = check_frame_file(first_path, {}, options.max_image_pixels); !error.empty())
    throw std::runtime_error("first frame unusable: " + error);
  const cv::Size size = read_image_size(first_path);
  run.camera = PinholeCamera::from_matrix(sequence.K, size.width, size.height);

  const auto startup = std::chrono::steady_clock::now();
  TrackingSession session(std::move(mesh), params, options.quality);
  session.set_camera(run.camera);
  session.set_record_hypotheses(options.record_hypotheses);
  run.startup_ms = elapsed_ms(startup);
  session.initialize(sequence.poses.front());
  Pose last = sequence.poses.front();
  run.dropped.assign(frames, 0);
  if (options.refine_truth) {
    TrackResult not_refined;
    not_refined.status = TrackStatus::kNotInitialized;
    run.truth_refined.assign(frames, not_refined);
  }
  const bool has_truth = sequence.poses.size() >= 2;
  // camera_rate_hz: when the session is next free, s (frame 0 arrives at 0).
  double free_at_s = 0.0;
  const auto arrival_s = [&](std::size_t i) { return static_cast<double>(i) / options.camera_rate_hz; };
  for (std::size_t i = 0; i < frames; ++i) {
    if (options.camera_rate_hz > 0.0 && i > 0 && i + 1 < frames && arrival_s(i + 1) <= free_at_s) {
      // A newer frame is waiting when the session frees: this one was replaced in the queue.
      run.dropped[i] = 1;
      ++run.dropped_frames;
      run.object_to_camera.push_back(last);
      continue;
    }
    double busy_ms = 0.0;  // the session's time on this frame (decoding is the camera's)
    const std::string& path = sequence.image_paths[i];
    std::string error = check_frame_file(path, size, options.max_image_pixels);
    cv::Mat image;
    if (error.empty()) {
      image = cv::imread(path, cv::IMREAD_COLOR);
      if (image.empty()) error = path + ": cannot decode the image";
    }
    SessionResult result;
    if (error.empty()) {
      const auto started = std::chrono::steady_clock::now();
      result = session.track({image, static_cast<double>(i)});
      busy_ms = elapsed_ms(started);
      if (result.frame.status == TrackStatus::kInvalidInput) error = path + ": " + result.frame.message;
      else if (options.refine_truth && has_truth && i >= 1 && i < sequence.poses.size())
        run.truth_refined[i] = session.refine_from({image, static_cast<double>(i)}, sequence.poses[i]);
    } else {
      result.frame.status = TrackStatus::kInvalidInput;
      result.frame.message = error;
      result.previous_state = result.state = session.state();
      image.release();
    }
    if (!error.empty()) {
      if (i == 0) throw std::runtime_error("first frame unusable: " + error);
      run.frame_errors.push_back(error);
    } else {
      last = result.frame.object_to_camera;
      if (i > 0) run.frame_ms.push_back(result.frame.frame_time_ms);
      if (result.frame.status == TrackStatus::kExtrapolated) ++run.extrapolated;
    }
    if (options.camera_rate_hz > 0.0)
      free_at_s = std::max(free_at_s, arrival_s(i)) + busy_ms / 1000.0;
    run.object_to_camera.push_back(last);
    if (options.on_frame) options.on_frame(i, image, result, session);
  }
  run.statistics = session.statistics();
  run.statistics.invalid_frames = static_cast<int>(run.frame_errors.size());
  return run;
}

SequenceScore score_sequence(const Mesh& mesh, const std::vector<Pose>& estimated_m,
                             const std::vector<Pose>& truth_m) {
  SequenceScore score;
  score.scored_frames = std::min(estimated_m.size(), truth_m.size());
  if (score.scored_frames < 2)
    throw std::invalid_argument(
        "cannot score: " + std::to_string(truth_m.size()) + " ground-truth pose(s) for " +
        std::to_string(estimated_m.size()) +
        " frame(s); scoring needs a ground-truth pose for at least the first 2 frames (the "
        "first is the given initial pose)");
  const std::vector<Pose> mine(estimated_m.begin(), estimated_m.begin() + score.scored_frames);
  const std::vector<Pose> truth(truth_m.begin(), truth_m.begin() + score.scored_frames);
  for (std::size_t i = 0; i < score.scored_frames; ++i)
    score.errors_m.push_back(mean_vertex_distance(mesh.vertices, mine[i], truth[i]));
  for (double d : score.errors_m) score.mean_add_m += d;
  score.mean_add_m /= static_cast<double>(score.errors_m.size());
  score.diameter_m = mesh.diameter();
  score.auc = auc_score(score.errors_m, score.diameter_m);
  score.success_5cm5deg = success_translation_rotation(mine, truth, 0.05, 5.0);
  return score;
}

}  // namespace kct
