// track_sequence: tracks a sequence folder (BCOT / RBOT-style: images, K.txt, pose.txt) offline
// and scores it with the paper's metric (Sec. 4.1). Needs no ROS master.
//
//   track_sequence --sequence DIR --model MESH [--model-scale S] [--preset NAME]
//                  [--param NAME=VALUE ...] [--output FILE] [--summary-json FILE]
//                  [--max-frames N] [--errors FILE] [--debug-dir DIR [--debug-every N]] [--quiet]
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/debug_drawing.h"
#include "klt_contour_tracker/core/metrics.h"
#include "klt_contour_tracker/core/sequence_io.h"
#include "klt_contour_tracker/core/tracker.h"

namespace {

void usage(const char* error) {
  if (error) std::cerr << "track_sequence: " << error << "\n";
  std::cerr << "usage: track_sequence --sequence DIR --model MESH [--model-scale S] [--preset NAME]\n"
               "                      [--param NAME=VALUE ...] [--output FILE] [--summary-json FILE]\n"
               "                      [--max-frames N] [--errors FILE] [--debug-dir DIR [--debug-every N]]\n"
               "                      [--quiet]\n"
               "  The visibility table is cached in $XDG_CACHE_HOME (~/.cache)/klt_contour_tracker/visibility\n"
               "  (--param visibility_cache_dir=DIR to change, =\"\" for none).\n"
               "  --errors FILE writes the per-frame error delta_i (Sec. 4.1, model units), one a line.\n"
               "  --debug-dir DIR writes the tracking overlay (contour, keypoints, axes, status) of every\n"
               "  N-th frame (default 1) as DIR/<frame>.png.\n"
               "  DIR holds images (sorted by name), K.txt and pose.txt (first line = initial pose;\n"
               "  the rest, when present, is the ground truth used for scoring).\n"
               "  presets: ";
  for (const auto& name : kct::preset_names()) std::cerr << name << " ";
  std::cerr << "\n";
  std::exit(2);
}

struct Options {
  std::string sequence, model, preset = "paper", output, summary_json, errors, debug_dir;
  int debug_every = 1;
  double model_scale = 1.0;
  int max_frames = -1;
  bool quiet = false;
  std::vector<std::pair<std::string, std::string>> overrides;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage((arg + " needs a value").c_str());
      return argv[++i];
    };
    try {
      if (arg == "--sequence") o.sequence = value();
      else if (arg == "--model") o.model = value();
      else if (arg == "--model-scale") o.model_scale = std::stod(value());
      else if (arg == "--preset") o.preset = value();
      else if (arg == "--output") o.output = value();
      else if (arg == "--summary-json") o.summary_json = value();
      else if (arg == "--errors") o.errors = value();
      else if (arg == "--max-frames") o.max_frames = std::stoi(value());
      else if (arg == "--quiet") o.quiet = true;
      else if (arg == "--debug-dir") o.debug_dir = value();
      else if (arg == "--debug-every") o.debug_every = std::max(1, std::stoi(value()));
      else if (arg == "--param") {
        const std::string kv = value();
        const auto eq = kv.find('=');
        if (eq == std::string::npos) usage("--param takes NAME=VALUE");
        o.overrides.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
      } else if (arg == "-h" || arg == "--help") usage(nullptr);
      else usage(("unknown argument " + arg).c_str());
    } catch (const std::logic_error&) {
      usage(("bad number for " + arg).c_str());
    }
  }
  if (o.sequence.empty() || o.model.empty()) usage("--sequence and --model are required");
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  try {
    kct::TrackerParams params = kct::make_preset(options.preset);
    // The visibility table is cached per model: a second run on the same model starts at once.
    if (const char* home = std::getenv("HOME"); home && *home) {
      const char* xdg = std::getenv("XDG_CACHE_HOME");
      params.visibility_cache_dir = (xdg && *xdg ? std::string(xdg) : std::string(home) + "/.cache") +
                                    "/klt_contour_tracker/visibility";
    }
    for (const auto& [name, value] : options.overrides) kct::set_param(params, name, value);
    params.validate();

    const kct::SequenceFolder sequence = kct::read_sequence(options.sequence);
    if (sequence.poses.empty())
      throw std::runtime_error(options.sequence + "/pose.txt: missing; its first line is the initial pose");
    auto mesh = std::make_shared<kct::Mesh>(kct::load_mesh(options.model, options.model_scale));
    size_t frames = sequence.image_paths.size();
    if (options.max_frames > 0) frames = std::min(frames, static_cast<size_t>(options.max_frames));

    const cv::Mat first = cv::imread(sequence.image_paths.front(), cv::IMREAD_COLOR);
    if (first.empty()) throw std::runtime_error(sequence.image_paths.front() + ": cannot read image");
    const kct::PinholeCamera camera = kct::PinholeCamera::from_matrix(sequence.K, first.cols, first.rows);
    kct::Tracker tracker(mesh, camera, params);
    tracker.initialize(sequence.poses.front());

    if (!options.debug_dir.empty()) std::filesystem::create_directories(options.debug_dir);
    std::vector<kct::Pose> estimated;
    std::vector<double> frame_ms;
    int extrapolated = 0;
    for (size_t i = 0; i < frames; ++i) {
      const cv::Mat image = cv::imread(sequence.image_paths[i], cv::IMREAD_COLOR);
      if (image.empty()) throw std::runtime_error(sequence.image_paths[i] + ": cannot read image");
      const kct::TrackResult result = tracker.track({image, static_cast<double>(i)});
      if (result.status == kct::TrackStatus::kInvalidInput)
        throw std::runtime_error(sequence.image_paths[i] + ": " + result.message);
      estimated.push_back(result.object_to_camera);
      if (i > 0) frame_ms.push_back(result.frame_time_ms);
      if (result.status == kct::TrackStatus::kExtrapolated) ++extrapolated;
      if (!options.debug_dir.empty() && i % options.debug_every == 0) {
        const std::string path = options.debug_dir + "/" + kct::frame_file_name(static_cast<int>(i));
        if (!cv::imwrite(path, kct::draw_tracking_overlay(image, result, tracker.camera(), *mesh,
                                                         tracker.contour_extractor())))
          throw std::runtime_error(path + ": cannot write");
      }
      if (!options.quiet) {
        std::cerr << "\r[" << (i + 1) << "/" << frames << "] " << std::setw(12) << kct::to_string(result.status)
                  << "  " << std::fixed << std::setprecision(1) << result.frame_time_ms << " ms" << std::flush;
      }
    }
    if (!options.quiet) std::cerr << "\n";
    if (!options.output.empty()) kct::write_pose_file(options.output, estimated);

    // Score the frames that have ground truth (pose.txt may hold more lines than images).
    const size_t scored = std::min(frames, sequence.poses.size());
    std::ostringstream json;
    json << std::setprecision(6) << "{\n  \"sequence\": \"" << options.sequence << "\",\n  \"preset\": \""
         << options.preset << "\",\n  \"frames\": " << frames << ",\n  \"faces\": " << mesh->faces.size()
         << ",\n  \"vertices\": " << mesh->vertices.size() << ",\n  \"width\": " << camera.width()
         << ",\n  \"height\": " << camera.height() << ",\n  \"extrapolated_frames\": " << extrapolated
         << ",\n  \"median_ms\": " << kct::median(frame_ms);
    std::printf("frames            %zu\n", frames);
    std::printf("extrapolated      %d\n", extrapolated);
    std::printf("median_ms         %.2f\n", kct::median(frame_ms));
    if (scored > 1) {
      std::vector<double> deltas;
      const std::vector<kct::Pose> truth(sequence.poses.begin(), sequence.poses.begin() + scored);
      const std::vector<kct::Pose> mine(estimated.begin(), estimated.begin() + scored);
      for (size_t i = 0; i < scored; ++i)
        deltas.push_back(kct::mean_vertex_distance(mesh->vertices, mine[i], truth[i]));
      if (!options.errors.empty()) {
        std::ofstream out(options.errors);
        out << std::setprecision(9);
        for (double d : deltas) out << d << "\n";
        if (!out) throw std::runtime_error(options.errors + ": cannot write");
      }
      double mean_add = 0;
      for (double d : deltas) mean_add += d;
      mean_add /= deltas.size();
      const double auc = kct::auc_score(deltas, mesh->diameter());
      const double success = kct::success_translation_rotation(mine, truth, 0.05, 5.0);
      std::printf("auc               %.3f  (of 20; k in [0, 0.2], diameter %.4f m)\n", auc, mesh->diameter());
      std::printf("success_5cm5deg   %.4f\n", success);
      std::printf("mean_add_mm       %.3f\n", 1000.0 * mean_add);
      json << ",\n  \"scored_frames\": " << scored << ",\n  \"auc\": " << auc
           << ",\n  \"success_5cm5deg\": " << success << ",\n  \"mean_add_mm\": " << 1000.0 * mean_add
           << ",\n  \"diameter_m\": " << mesh->diameter();
    }
    json << "\n}\n";
    if (!options.summary_json.empty()) {
      std::ofstream out(options.summary_json);
      out << json.str();
      if (!out) throw std::runtime_error(options.summary_json + ": cannot write");
    }
  } catch (const std::exception& e) {
    std::cerr << "track_sequence: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
