#pragma once
/// \file pose_refiner.h
/// Contour-energy refinement of a preliminary pose (paper Sec. 3.2-3.4 and supplement):
/// Basin-Hopping + SLSQP on the blurred frame inside the search area, then a short final
/// run on the original frame.

#include <memory>
#include <opencv2/core.hpp>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/keypoint_tracker.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {

class VisibilityTable;
class ContourExtractor;
class ContourEnergy;

/// Outcome of one refinement.
struct RefineResult {
  Pose object_to_camera = Pose::Identity();  ///< refined pose
  double energy_before = 0.0;  ///< Eq. 5 at the preliminary pose, unblurred frame
  double energy_after = 0.0;   ///< Eq. 5 at the refined pose, unblurred frame
  int hops = 0;                ///< hops of both stages
  int evaluations = 0;         ///< energy evaluations of both stages
};

/// Refines poses of one mesh; owns the visibility table, contour extractor and energy.
class PoseRefiner {
 public:
  /// Builds (or loads from params.visibility_cache_dir) the face-visibility table.
  PoseRefiner(std::shared_ptr<const Mesh> mesh, const TrackerParams& params);
  ~PoseRefiner();

  /// Refines `preliminary` on `gray` (CV_8UC1). `keypoints` holds the KLT inliers when the
  /// preliminary pose came from PnP (search area = reprojection constraint, Sec. 3.4), or is
  /// null when it was extrapolated (search area = Euler/translation box).
  RefineResult refine(const cv::Mat& gray, const PinholeCamera& camera, const Pose& preliminary,
                      const KeypointResult* keypoints);

  /// Contour energy (Eq. 5) of a pose on an unblurred frame, for diagnostics.
  double energy(const cv::Mat& gray, const PinholeCamera& camera, const Pose& object_to_camera) const;

  void set_params(const TrackerParams& params);
  const ContourExtractor& contour_extractor() const { return *extractor_; }

 private:
  std::shared_ptr<const Mesh> mesh_;
  TrackerParams params_;
  std::shared_ptr<const VisibilityTable> visibility_;
  std::shared_ptr<const ContourExtractor> extractor_;
  std::unique_ptr<ContourEnergy> energy_;
  std::uint32_t frame_counter_ = 0;
};

}  // namespace kct
