#pragma once
/// \file pose_refiner.h
/// Contour-energy refinement of a preliminary pose. optimizer = "basin_hopping" (paper Sec.
/// 3.2-3.4 and supplement): Basin-Hopping + SLSQP on the blurred frame inside the search area,
/// then a short final run on the original frame. optimizer = "coarse_to_fine" (ours, the
/// `realtime` preset): Levenberg-Marquardt over an image pyramid on a weighted sum of cues
/// (pose_cost.h): the contour energy with an analytic gradient and the keypoint reprojection.

#include <memory>
#include <opencv2/core.hpp>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/keypoint_tracker.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/pose_cost.h"
#include "klt_contour_tracker/core/stage_times.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {

class VisibilityTable;
class ContourExtractor;
class ContourEnergy;
class ContourCost;
class KeypointCost;

/// Outcome of one refinement.
struct RefineResult {
  Pose object_to_camera = Pose::Identity();  ///< refined pose
  double energy_before = 0.0;  ///< Eq. 5 at the preliminary pose, unblurred frame
  double energy_after = 0.0;   ///< Eq. 5 at the refined pose, unblurred frame
  int hops = 0;                ///< hops of both stages (coarse_to_fine: linearizations)
  int evaluations = 0;         ///< energy evaluations of both stages
  /// coarse_to_fine: false when the refined pose did not lower the objective and the
  /// preliminary pose was kept (always true for basin_hopping).
  bool accepted = true;
  /// Stage times of the refinement (image, contour extraction, energy, optimizer), ms.
  StageTimes times;
};

/// Refines poses of one mesh; owns the visibility table, contour extractor and energy.
class PoseRefiner {
 public:
  /// Builds (or loads from params.visibility_cache_dir) the face-visibility table.
  PoseRefiner(std::shared_ptr<const Mesh> mesh, const TrackerParams& params);
  ~PoseRefiner();

  /// A second refiner of the same mesh and parameters for another thread: it shares the
  /// visibility table (immutable) and has its own contour extractor (whose caches are not
  /// shared between threads) and its own contour and keypoint cues, but none of the cues
  /// add_cue() added. Its refine() gives the same result as this one's when this one has no
  /// added cue (coarse_to_fine; basin_hopping seeds from a per-refiner frame counter).
  std::unique_ptr<PoseRefiner> replica() const;
  /// True when cues were added with add_cue().
  bool has_added_cues() const { return !extra_cues_.empty(); }

  /// The pyramid level the coarse_to_fine refinement of `preliminary` starts at: the coarsest
  /// (pyramid_levels - 1), or the coarsest at which the object's diameter is still at least
  /// pyramid_min_object_px (level l has 1 / 2^l of the resolution); 0 at the least.
  int coarsest_level(const PinholeCamera& camera, const Pose& preliminary) const;

  /// Refines `preliminary` on `gray` (CV_8UC1). `keypoints` holds the KLT inliers when the
  /// preliminary pose came from PnP (search area = reprojection constraint, Sec. 3.4), or is
  /// null when it was extrapolated (search area = Euler/translation box).
  /// With optimizer = coarse_to_fine, energy_before/after are Eq. 5 on the full-resolution
  /// level blurred by blur_sigma_px, both over the contour extracted at the refined pose.
  /// `occlusion_mask` (coarse_to_fine only): PoseCostFrame::occlusion_mask for this call.
  RefineResult refine(const cv::Mat& gray, const PinholeCamera& camera, const Pose& preliminary,
                      const KeypointResult* keypoints, const cv::Mat& occlusion_mask = cv::Mat());

  /// coarse_to_fine only (a no-op otherwise): the frame's image work (pyramid, image
  /// derivatives, each cue's begin_frame) for `gray` (CV_8UC1, the frame refine() will get),
  /// with the object expected near `predicted` (e.g. the previous pose). The tracker calls it
  /// on a second thread while KLT runs; refine() does it itself when it was not called.
  /// `bgr`: the same frame in colour (CV_8UC3, undistorted) for colour cues, or empty.
  void prepare_frame(const cv::Mat& gray, const PinholeCamera& camera, const Pose& predicted,
                     const cv::Mat& bgr = cv::Mat());

  /// Adds a cue to the coarse_to_fine objective (e.g. a region or colour cue) with `weight`.
  void add_cue(std::shared_ptr<PoseCost> cue, double weight);
  /// Removes the cues add_cue() added.
  void clear_cues();

  /// Contour energy (Eq. 5) of a pose on an unblurred frame, for diagnostics.
  double energy(const cv::Mat& gray, const PinholeCamera& camera, const Pose& object_to_camera) const;

  void set_params(const TrackerParams& params);
  const ContourExtractor& contour_extractor() const { return *extractor_; }
  /// The same extractor, shared (e.g. with a cue added by add_cue(); used in the same thread).
  std::shared_ptr<const ContourExtractor> shared_contour_extractor() const { return extractor_; }

 private:
  PoseRefiner() = default;  ///< for replica()
  std::shared_ptr<const Mesh> mesh_;
  TrackerParams params_;
  std::shared_ptr<const VisibilityTable> visibility_;
  std::shared_ptr<const ContourExtractor> extractor_;
  std::unique_ptr<ContourEnergy> energy_;
  std::uint32_t frame_counter_ = 0;
  double size_m_ = 0.0;   ///< mesh diameter (costly to compute on large meshes: cached)
  double radius_m_ = 0.0; ///< largest distance of a vertex from the bounding-box centre
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();

  RefineResult refine_coarse_to_fine(const cv::Mat& gray, const PinholeCamera& camera,
                                     const Pose& preliminary, const KeypointResult* keypoints,
                                     const cv::Mat& occlusion_mask);
  /// shift_search_diameters (see TrackerParams): the image-plane shift of `preliminary` with
  /// the highest contour energy on pyramid `level` (coarsest_level()'s), when it beats the
  /// unshifted pose.
  bool search_shift(const Pose& preliminary, int level, Pose* shifted);
  void build_cues();
  PoseCostFrame cost_frame_;
  PoseCostSum costs_;
  std::shared_ptr<ContourCost> contour_cost_;
  std::shared_ptr<KeypointCost> keypoint_cost_;
  std::vector<std::pair<std::shared_ptr<PoseCost>, double>> extra_cues_;
  cv::Mat prepared_gray_;  ///< the frame prepare_frame() prepared (held: its buffer stays unique)
  double prepared_ms_ = 0.0;
};

}  // namespace kct
