#pragma once
/// \file object_search.h
/// Finding the object anywhere in a frame by its colours (ours, beyond the paper), for the
/// tracking session: to tell a lost track (the outline no longer separates the object's colours
/// from the background's) and to re-acquire it after an occlusion, a fast move or a visit
/// outside the image, where the local refinement around the last pose cannot reach.
///
/// Colours are learned at trusted poses (ColorHistograms, SRT3D's model). The search renders the
/// object's silhouette at the last good rotation and a few depths and correlates it, as a
/// template, with the frame's per-pixel foreground posterior (correlate_mask): the score of a
/// placement is the mean posterior inside the silhouette minus the mean in a ring around it, over
/// the pixels in the image, so an object entering the image is found once part of it is in.
/// Coarse to fine: the whole frame is correlated at half the working size and its best peaks
/// again at the working size around them (cv::matchTemplate over the whole working frame was a
/// quarter of a lost frame's time; mask_correlation.h says why it is no longer matchTemplate).

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/color_histograms.h"
#include "klt_contour_tracker/core/mask_correlation.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/renderer.h"

namespace kct {

class WorkerThreads;

/// Settings of the colour search (all ours).
struct ObjectSearchSettings {
  int working_width_px = 320;    ///< frames are halved until at most this wide, px
  int band_px = 4;               ///< width of the learning bands at the working size, px
  double learning_rate = 0.2;    ///< weight of a new frame in the histograms, (0, 1]
  /// Depths searched, as factors of the reference pose's depth.
  std::vector<double> depth_scales = {0.7, 0.85, 1.0, 1.2, 1.45};
  /// Placements with less of the silhouette inside the image are not scored, (0, 1].
  double min_visible_fraction = 0.3;
  /// Width of the ring around the silhouette, as a fraction of its larger side (at least 2 px).
  double ring_fraction = 0.15;
  /// Correlate at half the working size first, then search the best coarse peaks again at the
  /// working size (a third of the work of a whole-frame search); false: the working size only.
  bool coarse_to_fine = true;
  /// The silhouettes are drawn from the mesh simplified (simplified_mesh()) as far as it stays
  /// within this share of its diameter, [0, 0.05]; 0 = the mesh as given. At 0.001 a
  /// silhouette moves by at most 0.25 px at the working size while the object is at least its
  /// diameter away (fx about 260 px at 320 px wide). The contrast is sensitive to a systematic
  /// sub-pixel shift of the outline (the simplified mesh's vertices stay on the surface, so a
  /// convex outline shrinks): a clean two-colour sphere scores 0.880 at 0.001, 0.929 at 0.002.
  double silhouette_error_diameters = 0.0;
  /// Threads in all, the caller's included, for the depths of a search and the poses of a
  /// score (results do not depend on it), [1, 64].
  int threads = 1;

  /// Throws std::invalid_argument naming the first bad field and its allowed range.
  void validate() const;
};

/// A pose the search found and its colour contrast.
struct SearchCandidate {
  Pose object_to_camera = Pose::Identity();
  double contrast = 0.0;          ///< mean posterior inside - in the ring, [-1, 1]
  double visible_fraction = 0.0;  ///< share of the silhouette inside the image, [0, 1]
};

/// The ring of pixels around a silhouette: `mask` (CV_8UC1, 0 or 255) dilated by OpenCV's disc
/// of radius `ring_px` (cv::MORPH_ELLIPSE, 2 ring_px + 1 wide), minus the mask; 255 on the ring.
cv::Mat silhouette_ring(const cv::Mat& mask, int ring_px);

/// The object's colour model and the searches that use it.
class ObjectSearch {
 public:
  /// Throws std::invalid_argument for an empty mesh or invalid settings.
  ObjectSearch(std::shared_ptr<const Mesh> mesh, const ObjectSearchSettings& settings = {});
  ~ObjectSearch();
  ObjectSearch(const ObjectSearch&) = delete;
  ObjectSearch& operator=(const ObjectSearch&) = delete;

  /// Changes settings().threads (the learned colours are kept). Throws std::invalid_argument
  /// outside [1, 64].
  void set_threads(int threads);

  /// Learns the colours from `bgr` (CV_8UC3, undistorted, the camera's size) at a trusted pose.
  /// Returns false (nothing learned) when the silhouette is too small or mostly outside.
  bool learn(const cv::Mat& bgr, const Pose& object_to_camera, const PinholeCamera& camera);
  bool ready() const { return histograms_.ready(); }
  void clear() { histograms_.clear(); }

  /// Contrast and visible fraction of the silhouette at `object_to_camera` in `bgr` (contrast 0
  /// when the model is not ready or less than min_visible_fraction of it is in the image).
  SearchCandidate score(const cv::Mat& bgr, const Pose& object_to_camera,
                        const PinholeCamera& camera) const;
  /// score() for several poses in one frame (the working image and its posterior computed
  /// once); one result per pose, in order.
  std::vector<SearchCandidate> score(const cv::Mat& bgr, const std::vector<Pose>& object_to_camera,
                                     const PinholeCamera& camera) const;

  /// Searches the frame: the rotation of `reference` (object_to_camera) at the depths
  /// depth_scales x its depth, placed anywhere its silhouette is at least min_visible_fraction
  /// in the image and, with `reach_px` > 0, its centre at most `reach_px` (full-resolution px)
  /// from the reference's projected centre (0: anywhere). One candidate per depth (its best
  /// placement), best contrast first; empty when the model is not ready.
  std::vector<SearchCandidate> search(const cv::Mat& bgr, const Pose& reference,
                                      const PinholeCamera& camera, double reach_px = 0.0) const;

  const ObjectSearchSettings& settings() const { return settings_; }

  /// True when a CV_8UC3 image carries no colour (a grey camera's frames stored as BGR: fewer
  /// than 2 % of a grid of samples differ by more than 8 levels between channels): colour
  /// statistics would only repeat the grey level, so the session does not use them.
  static bool looks_grey(const cv::Mat& bgr);

 private:
  /// How often a frame of `width` is halved to reach working_width_px.
  int halvings(int width) const;
  /// `bgr` at the working size and the camera scaled to it.
  cv::Mat working_image(const cv::Mat& bgr, const PinholeCamera& camera,
                        PinholeCamera& working_camera) const;
  /// Where score() renders a pose's silhouette, in working-image pixels: the object's projected
  /// bounding box with room for the ring, within one image size around the image.
  cv::Rect silhouette_canvas(const Pose& object_to_camera,
                             const PinholeCamera& working_camera) const;
  /// The silhouette of one rotation and depth as the search correlates it: rendered on a square
  /// canvas (side = 2 half + 1 px) with the object's centre at the canvas centre, its ring, both
  /// as CV_32F 0/1 templates, and their integral images (for the parts inside the image).
  struct SilhouetteTemplate {
    int half = 0, side = 0;
    double area = 0.0;  ///< silhouette pixels
    MaskRuns inside, ring;  ///< the silhouette's and the ring's pixels, as runs
    cv::Mat inside_integral, ring_integral;
    bool empty() const { return area <= 0.0; }
  };
  /// The silhouette of `reference`'s rotation at `depth_m` seen by `working_camera` (whose image
  /// is `image_size`); empty when too small or too large to correlate.
  SilhouetteTemplate silhouette_template(const PinholeCamera& working_camera, const cv::Size& image_size,
                                         const Pose& reference, double depth_m) const;
  /// The contrast of `silhouette` centred on each pixel of `centres` of `posterior`: CV_32F,
  /// indexed from centres.tl(), kNotScored where less than min_visible_fraction of it or none of
  /// its ring is in the image; `visible` gets the share of the silhouette in the image.
  cv::Mat contrast_map(const cv::Mat& posterior, const SilhouetteTemplate& silhouette,
                       const cv::Rect& centres, cv::Mat& visible) const;
  /// Per-pixel P(foreground | colour) of a working-size image, CV_32F.
  cv::Mat posterior_map(const cv::Mat& working_bgr) const;

  std::shared_ptr<const Mesh> mesh_;
  ObjectSearchSettings settings_;
  double diameter_m_ = 0.0;
  /// Draws the silhouettes: of mesh_ simplified within silhouette_error_diameters.
  Renderer renderer_;
  ColorHistograms histograms_;
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();
  Eigen::AlignedBox3d box_object_;  ///< the mesh's bounding box
  std::unique_ptr<WorkerThreads> workers_;  ///< settings_.threads threads
};

}  // namespace kct
