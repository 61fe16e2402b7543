#pragma once
/// \file debug_drawing.h
/// The tracking overlay shown on `~debug_image` and written by `track_sequence --debug-dir`:
/// the model's contour (green) and sharp edges (yellow) at the frame's pose, the KLT inliers
/// (cyan), the object frame's axes (x red, y green, z blue) and a status line.

#include <opencv2/core.hpp>
#include <string>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/contour_extractor.h"
#include "klt_contour_tracker/core/tracker.h"

namespace kct {

/// Returns a BGR copy of `image` (grey or BGR, the frame given to Tracker::track) with the
/// overlay for `result`. `extractor` gives the contour and sharp edges (Algorithm 1); when it
/// is null (no refinement, e.g. klt_only) the mesh's silhouette-independent sharp edges are
/// drawn instead from `mesh`. The axes are 0.3 `diameter_m` long (the mesh's diameter, metres,
/// e.g. Tracker::diameter_m(): passed in because Mesh::diameter() costs ~0.1 s on a 150k-face
/// mesh, too much per frame). `label` is appended to the status line (e.g. the tracking state).
cv::Mat draw_tracking_overlay(const cv::Mat& image, const TrackResult& result,
                              const PinholeCamera& camera, const Mesh& mesh, double diameter_m,
                              const ContourExtractor* extractor, const std::string& label = "");

}  // namespace kct
