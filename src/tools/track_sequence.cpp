// track_sequence: tracks a sequence folder (BCOT / RBOT-style: images, K.txt, pose.txt) offline
// and scores it with the paper's metric (Sec. 4.1), through the same TrackingSession as the
// nodelet (loss detection and re-acquisition included). Needs no ROS master.
//
//   track_sequence --sequence DIR --model MESH [--model-scale S] [--preset NAME]
//                  [--param NAME=VALUE ...] [--output FILE] [--summary-json FILE]
//                  [--max-frames N] [--max-image-pixels N] [--errors FILE] [--score-model MESH]
//                  [--debug-dir DIR [--debug-every N]] [--trace FILE] [--hypotheses FILE]
//                  [--truth-refinement FILE]
//                  [--camera-rate HZ] [--quiet]
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
#include "klt_contour_tracker/core/model_units.h"
#include "klt_contour_tracker/core/sequence_io.h"
#include "klt_contour_tracker/core/sequence_run.h"
#include "klt_contour_tracker/core/track_quality.h"
#include "klt_contour_tracker/core/tracker.h"
#include "tool_args.h"

namespace {

void usage(const char* error) {
  if (error) std::cerr << "track_sequence: " << error << "\n";
  std::cerr << "usage: track_sequence --sequence DIR --model MESH [--model-scale S] [--preset NAME]\n"
               "                      [--param NAME=VALUE ...] [--quality NAME=VALUE ...]\n"
               "                      [--output FILE] [--summary-json FILE]\n"
               "                      [--max-frames N] [--max-image-pixels N] [--errors FILE]\n"
               "                      [--score-model MESH]\n"
               "                      [--debug-dir DIR [--debug-every N]] [--trace FILE]\n"
               "                      [--hypotheses FILE] [--truth-refinement FILE]\n"
               "                      [--camera-rate HZ] [--quiet]\n"
               "  --quality NAME=VALUE: the session's loss / recovery thresholds, as the nodelet's\n"
               "  parameters of the same names (lost_after_bad_frames, recover_after_good_frames,\n"
               "  min_quality, energy_weight, energy_level_smoothing, reacquire_search_scale).\n"
               "  --model-scale S: metres per model unit (0.001 for millimetres). It applies to\n"
               "  everything in model units: the mesh, pose.txt as read, the poses written by --output\n"
               "  (in model units, as read). Errors and ADD are reported in metres / mm regardless.\n"
               "  --max-image-pixels N: frames larger than N pixels (from the file header) are refused\n"
               "  before decoding, with a per-frame error [16777216 = 4096x4096].\n"
               "  The visibility table is cached in $XDG_CACHE_HOME (~/.cache)/klt_contour_tracker/visibility\n"
               "  (--param visibility_cache_dir=DIR to change, =\"\" for none).\n"
               "  --errors FILE writes the per-frame error delta_i (Sec. 4.1, metres), one a line.\n"
               "  --score-model MESH: the object's true shape (same units and frame as --model), used for\n"
               "  the errors and the diameter instead of --model: the tracker is given a model that is off\n"
               "  the object (a CAD model or scan with a shape error), the score is against the object.\n"
               "  --debug-dir DIR writes the tracking overlay (contour, keypoints, axes, status) of every\n"
               "  N-th frame (default 1) as DIR/<frame>.png.\n"
               "  --trace FILE writes one CSV line per frame: status, state, quality, KLT tracked / inliers,\n"
               "  energy before / after / level, colour contrast / level, searched, colour visible fraction,\n"
               "  relocalized, rotation corrected (why a track was lost or kept).\n"
               "  --hypotheses FILE writes one CSV line per hypothesis a colour search refined: the frame,\n"
               "  whether the frame re-acquires, its colour contrast and contour energy, in reach, chosen,\n"
               "  and with ground truth for the frame its error delta_i, centre distance (both in object\n"
               "  diameters) and rotation error (deg) after and before the refinement (how far the\n"
               "  re-acquisition's hypotheses reach; scripts/dev_loop.py reach sums them up).\n"
               "  --truth-refinement FILE writes, for every tracked frame after the first with ground\n"
               "  truth, the true pose refined as a re-acquisition hypothesis is (contour only, no\n"
               "  keypoints, no shift search): contour energy at the truth and after, and how far the\n"
               "  refinement moved it (error delta_i and centre distance in diameters, rotation deg,\n"
               "  depth mm, + = farther). Whether the objective holds the truth; the track is unchanged.\n"
               "  --camera-rate HZ: replay as a live camera at HZ: a frame that a newer one replaced\n"
               "  while the tracker was busy (its wall time here) is dropped, as the nodelet's one-message\n"
               "  queue drops it, and holds the last pose (scored so; no trace or debug line). Timing-\n"
               "  dependent: the score depends on this machine and its load. [0 = every frame]\n"
               "  DIR holds images (sorted by name), K.txt and pose.txt (first line = initial pose;\n"
               "  the rest, when present, is the ground truth used for scoring; with the initial pose alone\n"
               "  the run is not scored and --errors fails).\n"
               "  presets: ";
  for (const auto& name : kct::preset_names()) std::cerr << name << " ";
  std::cerr << "\n";
  std::exit(2);
}

struct Options {
  std::string sequence, model, preset = "realtime", output, summary_json, errors, debug_dir, trace,
      hypotheses, truth_refinement;
  std::string score_model;  ///< the object's true shape for scoring; empty = `model`
  int debug_every = 1;
  double model_scale = 1.0;
  int max_frames = -1;
  long long max_image_pixels = 4096LL * 4096;
  double camera_rate_hz = 0.0;  ///< --camera-rate; 0 = every frame
  bool quiet = false;
  std::vector<std::pair<std::string, std::string>> overrides;
  kct::TrackQualityParams quality;  ///< --quality NAME=VALUE, as the nodelet's parameters
};

/// NAME=VALUE split at the first '=' (--param, --quality).
std::pair<std::string, std::string> name_value(const std::string& kv) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("takes NAME=VALUE");
  return {kv.substr(0, eq), kv.substr(eq + 1)};
}

Options parse(int argc, char** argv) {
  Options o;
  using kct_tools::store;
  try {
    const bool run = kct_tools::parse_tool_options(
        argc, argv,
        {{"--sequence", store(o.sequence)},
         {"--model", store(o.model)},
         {"--model-scale", store(o.model_scale)},
         {"--preset", store(o.preset)},
         {"--output", store(o.output)},
         {"--summary-json", store(o.summary_json)},
         {"--errors", store(o.errors)},
         {"--score-model", store(o.score_model)},
         {"--max-frames", store(o.max_frames)},
         {"--max-image-pixels", store(o.max_image_pixels)},
         kct_tools::flag("--quiet", o.quiet),
         {"--debug-dir", store(o.debug_dir)},
         {"--debug-every", store(o.debug_every)},
         {"--trace", store(o.trace)},
         {"--hypotheses", store(o.hypotheses)},
         {"--truth-refinement", store(o.truth_refinement)},
         {"--camera-rate", store(o.camera_rate_hz)},
         {"--param", [&o](const std::string& kv) { o.overrides.push_back(name_value(kv)); }},
         {"--quality", [&o](const std::string& kv) {
            const auto [name, value] = name_value(kv);
            kct::set_quality_param(o.quality, name, value);
            o.quality.validate();
          }}});
    if (!run) usage(nullptr);
  } catch (const std::invalid_argument& e) {
    usage(e.what());
  }
  o.debug_every = std::max(1, o.debug_every);
  if (!(o.camera_rate_hz >= 0.0 && o.camera_rate_hz < 1e9))
    usage("--camera-rate takes a rate in Hz >= 0 (0: every frame)");
  if (o.sequence.empty() || o.model.empty()) usage("--sequence and --model are required");
  return o;
}

}  // namespace

namespace {

/// The tracker parameters: the preset, the visibility cache in $XDG_CACHE_HOME, the overrides.
kct::TrackerParams make_params(const Options& options) {
  kct::TrackerParams params = kct::make_preset(options.preset);
  // The visibility table is cached per model: a second run on the same model starts at once.
  if (const char* home = std::getenv("HOME"); home && *home) {
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    params.visibility_cache_dir = (xdg && *xdg ? std::string(xdg) : std::string(home) + "/.cache") +
                                  "/klt_contour_tracker/visibility";
  }
  for (const auto& [name, value] : options.overrides) kct::set_param(params, name, value);
  params.validate();
  return params;
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  return out + "\"";
}

std::string join(const std::vector<int>& values) {
  std::string out;
  for (int v : values) out += (out.empty() ? "" : ", ") + std::to_string(v);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  try {
    const kct::TrackerParams params = make_params(options);
    // Units: the mesh and pose.txt are in model units; everything inside is metres. The one
    // conversion happens at the I/O boundary (read_sequence, write_pose_file, load_mesh).
    const kct::ModelUnits units(options.model_scale);
    const kct::SequenceFolder sequence = kct::read_sequence(options.sequence, units);
    if (sequence.poses.empty())
      throw std::runtime_error(options.sequence + "/pose.txt: missing; its first line is the initial pose");
    auto mesh = std::make_shared<kct::Mesh>(kct::load_mesh(options.model, units.metres_per_unit()));
    // Scored against the object's true shape when it is not the model the tracker is given.
    const auto score_mesh = options.score_model.empty()
                                ? mesh
                                : std::make_shared<kct::Mesh>(kct::load_mesh(options.score_model,
                                                                             units.metres_per_unit()));

    if (!options.debug_dir.empty()) std::filesystem::create_directories(options.debug_dir);
    kct::SequenceRunOptions run_options;
    run_options.max_frames = options.max_frames > 0 ? static_cast<size_t>(options.max_frames) : 0;
    run_options.max_image_pixels = options.max_image_pixels;
    run_options.quality = options.quality;
    run_options.camera_rate_hz = options.camera_rate_hz;
    run_options.record_hypotheses = !options.hypotheses.empty();
    run_options.refine_truth = !options.truth_refinement.empty();
    size_t frames = sequence.image_paths.size();
    if (options.max_frames > 0) frames = std::min(frames, static_cast<size_t>(options.max_frames));
    // Per-stage times of the tracked frames (not the first), for the benchmark's stage table.
    const std::vector<std::pair<const char*, double kct::StageTimes::*>> stages = {
        {"klt", &kct::StageTimes::klt_ms},
        {"pnp", &kct::StageTimes::pnp_ms},
        {"keypoint_detection", &kct::StageTimes::keypoint_detection_ms},
        {"image", &kct::StageTimes::image_ms},
        {"contour_extraction", &kct::StageTimes::contour_extraction_ms},
        {"energy", &kct::StageTimes::energy_ms},
        {"optimizer", &kct::StageTimes::optimizer_ms}};
    std::vector<std::vector<double>> stage_ms(stages.size());
    std::ofstream trace;
    if (!options.trace.empty()) {
      trace.open(options.trace);
      if (!trace) throw std::runtime_error(options.trace + ": cannot write");
      trace << "frame,status,state,quality,good,klt_tracked,klt_inliers,energy_before,energy_after,"
               "energy_level,color_contrast,color_level,searched,color_visible,relocalized,rotation_corrected,texture_corrected,texture_correlation,frame_ms\n";
    }
    std::ofstream hypotheses;
    if (!options.hypotheses.empty()) {
      hypotheses.open(options.hypotheses);
      if (!hypotheses) throw std::runtime_error(options.hypotheses + ": cannot write");
      hypotheses << "frame,reacquiring,index,contrast,energy,in_reach,chosen,error_diameters,"
                    "centre_diameters,rotation_deg,start_error_diameters,start_centre_diameters,"
                    "start_rotation_deg,surface_correlation\n";
    }
    const double score_diameter_m = score_mesh->diameter();
    // A pose against a true one: error delta_i and centre distance (object diameters, against
    // the scored shape) and rotation (deg), as "e,c,r" (--hypotheses, --truth-refinement).
    const Eigen::Vector3d center = mesh->bounding_box_center();  // the tracker's centre_object
    const auto pose_errors = [&](const kct::Pose& pose, const kct::Pose& t) {
      return cv::format("%.4f,%.4f,%.2f",
                        kct::mean_vertex_distance(score_mesh->vertices, pose, t) / score_diameter_m,
                        ((pose * center) - (t * center)).norm() / score_diameter_m,
                        kct::rotation_error_deg(pose, t));
    };
    run_options.on_frame = [&](size_t i, const cv::Mat& image, const kct::SessionResult& result,
                               const kct::TrackingSession& session) {
      if (hypotheses.is_open()) {
        // Against the frame's ground truth (pose.txt's line i), when there is one.
        const bool truth = sequence.poses.size() >= 2 && i < sequence.poses.size();
        const auto errors = [&](const kct::Pose& pose) {
          return truth ? pose_errors(pose, sequence.poses[i]) : std::string(",,");
        };
        for (size_t k = 0; k < result.hypotheses.size(); ++k) {
          const kct::HypothesisRecord& h = result.hypotheses[k];
          hypotheses << i << ',' << (h.reacquiring ? 1 : 0) << ',' << k << ','
                     << cv::format("%.4f,%.4g,%d,%d,", h.contrast, h.energy, h.in_reach ? 1 : 0,
                                   h.chosen ? 1 : 0)
                     << errors(h.object_to_camera) << ',' << errors(h.start_object_to_camera) << ','
                     << cv::format("%.3f", h.surface_correlation) << '\n';
        }
      }
      if (i > 0 && result.frame.status != kct::TrackStatus::kInvalidInput)
        for (size_t k = 0; k < stages.size(); ++k)
          stage_ms[k].push_back(result.frame.times.*(stages[k].second));
      if (result.frame.status == kct::TrackStatus::kInvalidInput)
        std::cerr << (options.quiet ? "" : "\n") << "track_sequence: frame " << i << " skipped: "
                  << result.frame.message << "\n";
      if (!options.debug_dir.empty() && i % options.debug_every == 0 && !image.empty()) {
        const std::string path = options.debug_dir + "/" + kct::frame_file_name(static_cast<int>(i));
        const std::string label = std::string(kct::to_string(result.state)) +
                                  cv::format(" q %.2f", result.quality);
        if (!cv::imwrite(path, kct::draw_tracking_overlay(image, result.frame, session.tracker().camera(),
                                                         *mesh, session.tracker().diameter_m(),
                                                         session.tracker().contour_extractor(), label)))
          throw std::runtime_error(path + ": cannot write");
      }
      if (trace.is_open()) {
        const kct::TrackResult& f = result.frame;
        trace << i << ',' << kct::to_string(f.status) << ',' << kct::to_string(result.state) << ','
              << cv::format("%.3f,%d,%d,%d,%.4g,%.4g,%.4g,%.3f,%.3f,%d", result.quality,
                            result.good ? 1 : 0, f.keypoints.tracked, f.keypoints.inliers,
                            f.energy_before, f.energy_after, session.monitor().energy_level(),
                            result.color.valid ? result.color.contrast : -1.0,
                            session.monitor().color_level(), result.searched ? 1 : 0)
              << cv::format(",%.3f,%d,%d,%d,%.3f", result.color.valid ? result.color.visible_fraction : -1.0,
                            result.relocalized ? 1 : 0, result.rotation_corrected ? 1 : 0,
                            result.texture_corrected ? 1 : 0, result.texture_correlation)
              << cv::format(",%.2f", f.frame_time_ms)
              << '\n';
      }
      if (!options.quiet) {
        std::cerr << "\r[" << (i + 1) << "/" << frames << "] " << std::setw(12)
                  << kct::to_string(result.frame.status) << " " << std::setw(8) << kct::to_string(result.state)
                  << "  " << std::fixed << std::setprecision(1) << result.frame.frame_time_ms << " ms"
                  << std::flush;
      }
    };
    const kct::SequenceRun run = kct::track_sequence_folder(sequence, mesh, params, run_options);
    if (!options.quiet) std::cerr << "\n";
    frames = run.object_to_camera.size();
    if (!options.output.empty()) kct::write_pose_file(options.output, run.object_to_camera, units);
    if (!options.truth_refinement.empty()) {
      std::ofstream out(options.truth_refinement);
      if (!out) throw std::runtime_error(options.truth_refinement + ": cannot write");
      out << "frame,energy_truth,energy_refined,error_diameters,centre_diameters,rotation_deg,depth_mm\n";
      for (size_t i = 0; i < run.truth_refined.size(); ++i) {
        const kct::TrackResult& r = run.truth_refined[i];
        if (r.status != kct::TrackStatus::kReacquired) continue;  // not refined
        const kct::Pose& t = sequence.poses[i];
        const kct::Pose& p = r.object_to_camera;
        out << i << ',' << cv::format("%.4g,%.4g,", r.energy_before, r.energy_after) << pose_errors(p, t)
            << cv::format(",%.2f\n", ((p * center).z() - (t * center).z()) * 1000.0);
      }
    }

    const kct::SessionStatistics& stats = run.statistics;
    const double median_ms = kct::median(run.frame_ms), p90_ms = kct::percentile(run.frame_ms, 90),
                 max_ms = kct::percentile(run.frame_ms, 100);
    std::ostringstream json;
    json << std::setprecision(6) << "{\n  \"sequence\": " << json_string(options.sequence)
         << ",\n  \"preset\": " << json_string(options.preset) << ",\n  \"frames\": " << frames
         << ",\n  \"model_scale\": " << units.metres_per_unit()
         << ",\n  \"faces\": " << mesh->faces.size() << ",\n  \"vertices\": " << mesh->vertices.size()
         << ",\n  \"width\": " << run.camera.width() << ",\n  \"height\": " << run.camera.height()
         << ",\n  \"extrapolated_frames\": " << run.extrapolated
         << ",\n  \"camera_rate_hz\": " << options.camera_rate_hz
         << ",\n  \"dropped_frames\": " << run.dropped_frames
         << ",\n  \"invalid_frames\": " << stats.invalid_frames
         << ",\n  \"frames_lost\": " << stats.frames_lost << ",\n  \"losses\": " << stats.losses
         << ",\n  \"reacquisitions\": " << stats.reacquisitions
         << ",\n  \"frames_to_reacquire\": [" << join(stats.frames_to_reacquire) << "]"
         << ",\n  \"startup_ms\": " << run.startup_ms
         << ",\n  \"median_ms\": " << median_ms << ",\n  \"p90_ms\": " << p90_ms
         << ",\n  \"max_ms\": " << max_ms << ",\n  \"stage_median_ms\": {";
    for (size_t k = 0; k < stages.size(); ++k)
      json << (k ? ", " : "") << "\"" << stages[k].first << "\": " << kct::median(stage_ms[k]);
    json << "}";
    std::printf("frames            %zu\n", frames);
    std::printf("invalid_frames    %d\n", stats.invalid_frames);
    std::printf("extrapolated      %d\n", run.extrapolated);
    if (options.camera_rate_hz > 0.0)
      std::printf("dropped_frames    %d  (at %.4g Hz)\n", run.dropped_frames, options.camera_rate_hz);
    std::printf("frames_lost       %d\n", stats.frames_lost);
    std::printf("losses            %d\n", stats.losses);
    std::printf("reacquisitions    %d  (frames from loss to re-acquired: %s)\n", stats.reacquisitions,
                stats.frames_to_reacquire.empty() ? "-" : join(stats.frames_to_reacquire).c_str());
    std::printf("startup_ms        %.1f\n", run.startup_ms);
    std::printf("median_ms         %.2f\n", median_ms);
    std::printf("p90_ms            %.2f\n", p90_ms);
    std::printf("max_ms            %.2f\n", max_ms);

    // Score the frames that have ground truth (pose.txt may hold more lines than images).
    int exit_code = 0;
    if (sequence.poses.size() < 2) {
      // pose.txt holds only the initial pose: a tracking run, nothing to score against.
      std::printf("auc               not scored: pose.txt has %zu pose (the initial one); scoring needs one per frame\n",
                  sequence.poses.size());
      json << ",\n  \"scored_frames\": 0";
      if (!options.errors.empty()) {
        std::cerr << "track_sequence: --errors " << options.errors
                  << " not written: pose.txt has only the initial pose, no ground truth to score against\n";
        exit_code = 1;
      }
    } else {
      const kct::SequenceScore score = kct::score_sequence(*score_mesh, run.object_to_camera, sequence.poses);
      if (score.scored_frames < frames)
        std::cerr << "track_sequence: warning: pose.txt has " << sequence.poses.size() << " poses for "
                  << frames << " frames: only the first " << score.scored_frames << " are scored\n";
      if (!options.errors.empty()) {
        std::ofstream out(options.errors);
        out << std::setprecision(9);
        for (double d : score.errors_m) out << d << "\n";
        if (!out) throw std::runtime_error(options.errors + ": cannot write");
      }
      std::printf("scored_frames     %zu\n", score.scored_frames);
      std::printf("auc               %.3f  (of 20; k in [0, 0.2], diameter %.4f m)\n", score.auc,
                  score.diameter_m);
      std::printf("success_5cm5deg   %.4f\n", score.success_5cm5deg);
      std::printf("mean_add_mm       %.3f\n", 1000.0 * score.mean_add_m);
      json << ",\n  \"scored_frames\": " << score.scored_frames << ",\n  \"auc\": " << score.auc
           << ",\n  \"success_5cm5deg\": " << score.success_5cm5deg
           << ",\n  \"mean_add_mm\": " << 1000.0 * score.mean_add_m
           << ",\n  \"diameter_m\": " << score.diameter_m;
    }
    json << "\n}\n";
    if (!options.summary_json.empty()) {
      std::ofstream out(options.summary_json);
      out << json.str();
      if (!out) throw std::runtime_error(options.summary_json + ": cannot write");
    }
    return exit_code;
  } catch (const std::exception& e) {
    std::cerr << "track_sequence: " << e.what() << "\n";
    return 1;
  }
}
