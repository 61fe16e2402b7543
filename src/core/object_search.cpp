#include "klt_contour_tracker/core/object_search.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "klt_contour_tracker/core/check_range.h"
#include "klt_contour_tracker/core/mesh_simplification.h"
#include "klt_contour_tracker/core/worker_threads.h"

namespace kct {
namespace {

constexpr const char* kOwner = "ObjectSearchSettings";
/// A placement the contrast map does not score (too little of it in the image, or out of reach).
constexpr float kNotScored = -2.0f;
/// Coarse to fine: the search areas (centres, working px) from which the coarse level is used
/// (a tracked search's small window is correlated at the working size at once), ...
constexpr int kCoarseMinCentres = 48 * 48;
/// ... the smallest object (radius at the working size, px) that still shows at half size, ...
constexpr double kCoarseMinRadiusPx = 12.0;
/// ... how many of the coarse map's peaks are searched again at the working size (different
/// places, at least a quarter of the object's radius apart), ...
constexpr int kCoarsePeaks = 3;
/// ... and how far around each (working px): a coarse pixel covers 2 x 2, plus a pixel of slack.
constexpr double kFineReachPx = 2.5;

int ring_width_px(const cv::Mat& mask, double fraction) {
  const cv::Rect box = cv::boundingRect(mask);
  return std::max(2, static_cast<int>(std::lround(fraction * std::max(box.width, box.height))));
}

/// The object's centre placed at `pixel` (working camera) at depth `depth_m`, rotation kept.
Pose placed_at(const Pose& reference, const Eigen::Vector3d& center_object,
               const PinholeCamera& camera, const Eigen::Vector2d& pixel, double depth_m) {
  Pose pose = reference;
  const Eigen::Vector3d center_camera = depth_m * camera.back_project(pixel);
  pose.translation() = center_camera - reference.linear() * center_object;
  return pose;
}

}  // namespace

void ObjectSearchSettings::validate() const {
  check_range(kOwner, "working_width_px", working_width_px, 32, 100000);
  check_range(kOwner, "band_px", band_px, 1, 100);
  check_range(kOwner, "learning_rate", learning_rate, 1e-6, 1.0);
  if (depth_scales.empty())
    throw std::invalid_argument("ObjectSearchSettings.depth_scales must not be empty");
  for (double s : depth_scales) check_range(kOwner, "depth_scales[i]", s, 0.05, 20.0);
  check_range(kOwner, "min_visible_fraction", min_visible_fraction, 1e-3, 1.0);
  check_range(kOwner, "ring_fraction", ring_fraction, 0.01, 2.0);
  check_range(kOwner, "silhouette_error_diameters", silhouette_error_diameters, 0.0, 0.05);
  check_range(kOwner, "threads", threads, 1, 64);
}

namespace {

/// `mesh` after checking it and the settings (ObjectSearch's first members need both).
std::shared_ptr<const Mesh> checked(std::shared_ptr<const Mesh> mesh,
                                    const ObjectSearchSettings& settings) {
  if (!mesh || mesh->faces.empty()) throw std::invalid_argument("ObjectSearch: empty mesh");
  settings.validate();
  return mesh;
}

}  // namespace

ObjectSearch::ObjectSearch(std::shared_ptr<const Mesh> mesh, const ObjectSearchSettings& settings)
    : mesh_(checked(std::move(mesh), settings)),
      settings_(settings),
      diameter_m_(mesh_->diameter()),
      renderer_(settings_.silhouette_error_diameters > 0.0
                    ? std::make_shared<const Mesh>(simplified_mesh(
                          *mesh_, settings_.silhouette_error_diameters * diameter_m_))
                    : mesh_) {
  center_object_ = mesh_->bounding_box_center();
  box_object_ = mesh_->bounding_box();
  workers_ = std::make_unique<WorkerThreads>(settings_.threads);
}

ObjectSearch::~ObjectSearch() = default;

void ObjectSearch::set_threads(int threads) {
  check_range(kOwner, "threads", threads, 1, 64);
  if (threads == settings_.threads) return;
  settings_.threads = threads;
  workers_ = std::make_unique<WorkerThreads>(threads);
}

bool ObjectSearch::looks_grey(const cv::Mat& bgr) {
  if (bgr.type() != CV_8UC3 || bgr.empty()) return true;
  const int step_r = std::max(1, bgr.rows / 48), step_c = std::max(1, bgr.cols / 64);
  int samples = 0, coloured = 0;
  for (int r = 0; r < bgr.rows; r += step_r) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(r);
    for (int c = 0; c < bgr.cols; c += step_c) {
      const cv::Vec3b& p = row[c];
      const int spread = std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]});
      ++samples;
      if (spread > 8) ++coloured;
    }
  }
  return coloured * 50 < samples;  // < 2 %
}

int ObjectSearch::halvings(int width) const {
  int steps = 0;
  while (width > settings_.working_width_px && steps < 8) {
    width = (width + 1) / 2;
    ++steps;
  }
  return steps;
}

cv::Mat ObjectSearch::working_image(const cv::Mat& bgr, const PinholeCamera& camera,
                                    PinholeCamera& working_camera) const {
  if (bgr.type() != CV_8UC3 || bgr.size() != camera.size())
    throw std::invalid_argument("ObjectSearch: the image must be CV_8UC3 of the camera's size");
  const int steps = halvings(bgr.cols);
  if (steps == 0) {
    working_camera = PinholeCamera(camera.fx(), camera.fy(), camera.cx(), camera.cy(),
                                   camera.width(), camera.height());
    return bgr;
  }
  const double s = std::ldexp(1.0, -steps);
  const cv::Size size(std::max(1, static_cast<int>(std::lround(bgr.cols * s))),
                      std::max(1, static_cast<int>(std::lround(bgr.rows * s))));
  const double sx = static_cast<double>(size.width) / bgr.cols;
  const double sy = static_cast<double>(size.height) / bgr.rows;
  // Pixel centres: u' + 0.5 = (u + 0.5) * scale.
  working_camera = PinholeCamera(camera.fx() * sx, camera.fy() * sy, (camera.cx() + 0.5) * sx - 0.5,
                                 (camera.cy() + 0.5) * sy - 0.5, size.width, size.height);
  cv::Mat small;
  cv::resize(bgr, small, size, 0, 0, cv::INTER_AREA);
  return small;
}

cv::Mat ObjectSearch::posterior_map(const cv::Mat& working_bgr) const {
  cv::Mat posterior(working_bgr.size(), CV_32F);
  for (int r = 0; r < working_bgr.rows; ++r) {
    const cv::Vec3b* pixels = working_bgr.ptr<cv::Vec3b>(r);
    float* out = posterior.ptr<float>(r);
    for (int c = 0; c < working_bgr.cols; ++c) out[c] = histograms_.posterior(pixels[c]);
  }
  return posterior;
}

bool ObjectSearch::learn(const cv::Mat& bgr, const Pose& object_to_camera,
                         const PinholeCamera& camera) {
  PinholeCamera working_camera;
  const cv::Mat small = working_image(bgr, camera, working_camera);
  const cv::Mat mask = renderer_.render_silhouette(object_to_camera, working_camera);
  return histograms_.learn(small, mask, settings_.band_px, settings_.learning_rate);
}

cv::Rect ObjectSearch::silhouette_canvas(const Pose& object_to_camera,
                                         const PinholeCamera& working_camera) const {
  // At most one image size beyond the image on every side: a silhouette reaching further
  // (the object at the lens) is cut there, as its visible share is small anyway.
  const int width = working_camera.width(), height = working_camera.height();
  const cv::Rect limit(-width, -height, 3 * width, 3 * height);
  double u_min = 1e300, u_max = -1e300, v_min = 1e300, v_max = -1e300;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d point_camera =
        object_to_camera * box_object_.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    if (!(point_camera.z() > 1e-3)) return limit;  // the box crosses the camera plane
    const Eigen::Vector2d pixel = working_camera.project(point_camera);
    u_min = std::min(u_min, pixel.x());
    u_max = std::max(u_max, pixel.x());
    v_min = std::min(v_min, pixel.y());
    v_max = std::max(v_max, pixel.y());
  }
  if (!(u_max - u_min < 1e7 && v_max - v_min < 1e7)) return limit;  // NaN or absurd
  // The projected box bounds the silhouette; the margin holds its ring (ring_width_px of a
  // silhouette no larger than the box) and a pixel of rounding.
  const double margin_px =
      std::max(2.0, settings_.ring_fraction * std::max(u_max - u_min, v_max - v_min)) + 2.0;
  const int x0 = static_cast<int>(std::floor(std::max(u_min - margin_px, -1e6)));
  const int y0 = static_cast<int>(std::floor(std::max(v_min - margin_px, -1e6)));
  const int x1 = static_cast<int>(std::ceil(std::min(u_max + margin_px, 1e6)));
  const int y1 = static_cast<int>(std::ceil(std::min(v_max + margin_px, 1e6)));
  return cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1) & limit;
}

SearchCandidate ObjectSearch::score(const cv::Mat& bgr, const Pose& object_to_camera,
                                    const PinholeCamera& camera) const {
  return score(bgr, std::vector<Pose>{object_to_camera}, camera).front();
}

std::vector<SearchCandidate> ObjectSearch::score(const cv::Mat& bgr,
                                                 const std::vector<Pose>& object_to_camera,
                                                 const PinholeCamera& camera) const {
  std::vector<SearchCandidate> results(object_to_camera.size());
  for (std::size_t i = 0; i < results.size(); ++i) results[i].object_to_camera = object_to_camera[i];
  if (!ready()) return results;
  // The working image and its posterior are the same for every pose.
  PinholeCamera working_camera;
  const cv::Mat small = working_image(bgr, camera, working_camera);
  const cv::Mat posterior = posterior_map(small);
  // Each pose writes only its own result.
  workers_->parallel_for(static_cast<int>(results.size()), [&](int i) {
    SearchCandidate& result = results[static_cast<std::size_t>(i)];
    if (!(result.object_to_camera.translation().z() > 0)) return;
    // Rendered on a canvas around the silhouette and its ring, not only the image: the share
    // outside the image is the visible fraction's denominator.
    const cv::Rect canvas_rect = silhouette_canvas(result.object_to_camera, working_camera);
    if (canvas_rect.empty()) return;
    const PinholeCamera canvas_camera(working_camera.fx(), working_camera.fy(),
                                      working_camera.cx() - canvas_rect.x,
                                      working_camera.cy() - canvas_rect.y, canvas_rect.width,
                                      canvas_rect.height);
    const cv::Mat canvas = renderer_.render_silhouette(result.object_to_camera, canvas_camera);
    const double total = cv::countNonZero(canvas);
    if (total <= 0) return;
    // The image's part of the canvas, in canvas pixels.
    const cv::Rect image_rect =
        (cv::Rect(0, 0, small.cols, small.rows) & canvas_rect) - canvas_rect.tl();
    if (image_rect.empty()) return;
    const cv::Mat mask = canvas(image_rect);
    result.visible_fraction = cv::countNonZero(mask) / total;
    if (result.visible_fraction < settings_.min_visible_fraction) return;
    const cv::Mat ring =
        silhouette_ring(canvas, ring_width_px(canvas, settings_.ring_fraction))(image_rect);
    if (cv::countNonZero(ring) == 0) return;
    const cv::Mat posterior_visible = posterior(image_rect + canvas_rect.tl());
    result.contrast = cv::mean(posterior_visible, mask)[0] - cv::mean(posterior_visible, ring)[0];
  });
  return results;
}

cv::Mat silhouette_ring(const cv::Mat& mask, int ring_px) {
  if (mask.type() != CV_8UC1 || ring_px < 1)
    throw std::invalid_argument("silhouette_ring: a CV_8UC1 mask and ring_px >= 1 are needed");
  // Written out rather than cv::dilate() with the disc element: OpenCV's dilation by a
  // non-rectangular element visits every element pixel for every image pixel (~(2r+1)^2 / 1.3),
  // which made the rings a seventh of a frame's time when the colour search scores two dozen
  // poses. The disc's rows are centred runs, so the dilation is the union, over the mask's
  // horizontal runs, of those runs widened row by row: the same pixels (checked against
  // cv::dilate in the tests) at a few spans per mask row.
  const cv::Mat element =
      cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * ring_px + 1, 2 * ring_px + 1});
  std::vector<int> half_width(element.rows, -1);
  for (int j = 0; j < element.rows; ++j) {
    const uchar* e = element.ptr<uchar>(j);
    int first = -1, last = -1;
    for (int i = 0; i < element.cols; ++i)
      if (e[i]) {
        if (first < 0) first = i;
        last = i;
      }
    if (first < 0) continue;
    if (first + last != 2 * ring_px || cv::countNonZero(element.row(j)) != last - first + 1) {
      // Not centred runs (another OpenCV version's disc): the library's dilation.
      cv::Mat dilated;
      cv::dilate(mask, dilated, element);
      return dilated & ~mask;
    }
    half_width[j] = ring_px - first;
  }
  // The union of the disc's rows around every run of mask pixels in a row: each run paints,
  // for each row offset, one span (memset) widened by that row's half-width.
  cv::Mat dilated(mask.size(), CV_8UC1, cv::Scalar(0));
  for (const MaskRuns::Run& run : MaskRuns::of(mask).runs)
    for (int j = 0; j < element.rows; ++j) {
      const int yy = run.row + j - ring_px;
      if (half_width[j] < 0 || yy < 0 || yy >= mask.rows) continue;
      const int from = std::max(0, run.begin - half_width[j]);
      const int to = std::min(mask.cols - 1, run.end - 1 + half_width[j]);
      std::memset(dilated.ptr<uchar>(yy) + from, 255, static_cast<std::size_t>(to - from + 1));
    }
  return dilated & ~mask;
}

ObjectSearch::SilhouetteTemplate ObjectSearch::silhouette_template(
    const PinholeCamera& working_camera, const cv::Size& image_size, const Pose& reference,
    double depth_m) const {
  SilhouetteTemplate t;
  const double radius_px = working_camera.fx() * 0.5 * diameter_m_ / depth_m;
  const int ring_guess =
      std::max(2, static_cast<int>(std::ceil(settings_.ring_fraction * 2.0 * radius_px)));
  const int half = static_cast<int>(std::ceil(radius_px)) + ring_guess + 2;
  const int side = 2 * half + 1;
  if (side > 4 * std::max(image_size.width, image_size.height) || side < 5) return t;
  const PinholeCamera canvas_camera(working_camera.fx(), working_camera.fy(), half, half, side,
                                    side);
  const Pose centred =
      placed_at(reference, center_object_, canvas_camera, Eigen::Vector2d(half, half), depth_m);
  const cv::Mat mask = renderer_.render_silhouette(centred, canvas_camera);
  MaskRuns inside = MaskRuns::of(mask);
  const double area = static_cast<double>(inside.pixels);
  if (area < 4) return t;
  const cv::Mat ring = silhouette_ring(mask, ring_width_px(mask, settings_.ring_fraction));
  t.inside = std::move(inside);
  t.ring = MaskRuns::of(ring);
  cv::integral(mask / 255, t.inside_integral, CV_32S);
  cv::integral(ring / 255, t.ring_integral, CV_32S);
  t.half = half;
  t.side = side;
  t.area = area;
  return t;
}

cv::Mat ObjectSearch::contrast_map(const cv::Mat& posterior, const SilhouetteTemplate& silhouette,
                                   const cv::Rect& centres, cv::Mat& visible) const {
  const int half = silhouette.half, side = silhouette.side;
  // Placements reaching outside the image: the posterior padded with zeros, so sums count
  // only pixels inside it. The areas inside the image are the templates' sums over their
  // overlap with the image rectangle: read from integral images, not correlated.
  // Template top-left at padded (c, r) centres it on image pixel (c, r); only the window the
  // centres need is padded and correlated.
  cv::Mat window;
  const cv::Rect needed(centres.x - half, centres.y - half, centres.width + side - 1,
                        centres.height + side - 1);
  const cv::Rect inside = needed & cv::Rect(0, 0, posterior.cols, posterior.rows);
  cv::copyMakeBorder(posterior(inside), window, inside.y - needed.y,
                     needed.br().y - inside.br().y, inside.x - needed.x,
                     needed.br().x - inside.br().x, cv::BORDER_CONSTANT, 0);
  // index (c, r): centre centres.tl() + (c, r)
  const cv::Mat prefix = row_prefix_sums(window);
  const cv::Mat posterior_inside = correlate_mask(prefix, silhouette.inside);
  const cv::Mat posterior_ring = correlate_mask(prefix, silhouette.ring);
  // Template pixels of the placement centred on image pixel (c, r) that fall in the image.
  auto in_image = [&](const cv::Mat& integral, int r, int c) {
    const int j0 = std::max(0, half - r), j1 = std::min(side, half - r + posterior.rows);
    const int i0 = std::max(0, half - c), i1 = std::min(side, half - c + posterior.cols);
    if (j0 >= j1 || i0 >= i1) return 0.0f;
    return static_cast<float>(integral.at<int>(j1, i1) - integral.at<int>(j0, i1) -
                              integral.at<int>(j1, i0) + integral.at<int>(j0, i0));
  };
  const double area = silhouette.area;
  const float min_area = static_cast<float>(settings_.min_visible_fraction * area);
  cv::Mat contrast(posterior_inside.size(), CV_32F, cv::Scalar(kNotScored));
  visible = cv::Mat(posterior_inside.size(), CV_32F, cv::Scalar(0.0f));
  for (int r = 0; r < contrast.rows; ++r) {
    const float* pi = posterior_inside.ptr<float>(r);
    const float* pr = posterior_ring.ptr<float>(r);
    float* out = contrast.ptr<float>(r);
    float* shown = visible.ptr<float>(r);
    for (int c = 0; c < contrast.cols; ++c) {
      const int u = centres.x + c, v = centres.y + r;  // image pixel
      const float area_inside = in_image(silhouette.inside_integral, v, u);
      const float area_ring = in_image(silhouette.ring_integral, v, u);
      shown[c] = static_cast<float>(std::min(1.0, area_inside / area));
      if (area_inside < min_area || area_ring < 1.0f) continue;
      out[c] = pi[c] / area_inside - pr[c] / area_ring;
    }
  }
  return contrast;
}

std::vector<SearchCandidate> ObjectSearch::search(const cv::Mat& bgr, const Pose& reference,
                                                  const PinholeCamera& camera,
                                                  double reach_px) const {
  std::vector<SearchCandidate> candidates;
  const double reference_depth = (reference * center_object_).z();
  if (!ready() || !(reference_depth > 0)) return candidates;
  PinholeCamera working_camera;
  const cv::Mat small = working_image(bgr, camera, working_camera);
  const cv::Mat posterior = posterior_map(small);
  // The coarse level: the posterior at half the working size (each pixel the mean of 2 x 2),
  // correlated first over the whole search area, its best peaks then placed at the working size.
  cv::Mat coarse_posterior;
  PinholeCamera coarse_camera;
  const bool coarse = settings_.coarse_to_fine && small.cols >= 64 && small.rows >= 64;
  if (coarse) {
    const cv::Size size((small.cols + 1) / 2, (small.rows + 1) / 2);
    cv::resize(posterior, coarse_posterior, size, 0, 0, cv::INTER_AREA);
    const double sx = static_cast<double>(size.width) / small.cols;
    const double sy = static_cast<double>(size.height) / small.rows;
    coarse_camera = PinholeCamera(working_camera.fx() * sx, working_camera.fy() * sy,
                                  (working_camera.cx() + 0.5) * sx - 0.5,
                                  (working_camera.cy() + 0.5) * sy - 0.5, size.width, size.height);
  }
  // The reach around the reference's centre, in working-image px (0: anywhere).
  const Eigen::Vector2d reference_px = working_camera.project(reference * center_object_);
  const double reach_working = reach_px > 0.0 ? reach_px * working_camera.fx() / camera.fx() : 0.0;
  // The centres (image pixels of `image`) within the reach, or every pixel; empty when none.
  const auto centres_within = [&](const cv::Mat& image, const Eigen::Vector2d& centre_px,
                                  double reach) {
    cv::Rect centres(0, 0, image.cols, image.rows);
    if (!(reach > 0.0)) return centres;
    const double x0 = std::floor(centre_px.x() - reach), y0 = std::floor(centre_px.y() - reach);
    const double x1 = std::ceil(centre_px.x() + reach), y1 = std::ceil(centre_px.y() + reach);
    if (!(x1 >= 0.0 && y1 >= 0.0 && x0 < image.cols && y0 < image.rows)) return cv::Rect();
    const int left = static_cast<int>(std::max(0.0, x0)), top = static_cast<int>(std::max(0.0, y0));
    return centres & cv::Rect(left, top,
                              static_cast<int>(std::min<double>(image.cols - 1, x1)) - left + 1,
                              static_cast<int>(std::min<double>(image.rows - 1, y1)) - top + 1);
  };
  // A contrast map's `count` best scored centres within the reach, best first, each at least
  // `suppress_px` (in both directions) from the ones before (fewer when fewer are scored).
  struct Peak {
    cv::Point at;  ///< image pixel
    float contrast;
    float visible_fraction;
  };
  const auto peaks = [](const cv::Mat& contrast, const cv::Mat& visible, const cv::Rect& centres,
                        const Eigen::Vector2d& centre_px, double reach, int count,
                        int suppress_px) {
    const double reach2 = reach > 0.0 ? reach * reach : 0.0;
    cv::Mat scores = contrast.clone();
    if (reach2 > 0.0)
      for (int r = 0; r < scores.rows; ++r) {
        float* s = scores.ptr<float>(r);
        for (int c = 0; c < scores.cols; ++c)
          if ((Eigen::Vector2d(centres.x + c, centres.y + r) - centre_px).squaredNorm() > reach2)
            s[c] = kNotScored;
      }
    std::vector<Peak> found;
    for (int k = 0; k < count; ++k) {
      // The first maximum in row-major order (ties: the same pixel whatever the thread count).
      float best = kNotScored;
      cv::Point best_at(-1, -1);
      for (int r = 0; r < scores.rows; ++r) {
        const float* s = scores.ptr<float>(r);
        for (int c = 0; c < scores.cols; ++c)
          if (s[c] > best) {
            best = s[c];
            best_at = {c, r};
          }
      }
      if (best_at.x < 0) break;
      found.push_back({best_at + centres.tl(), best, visible.at<float>(best_at)});
      cv::rectangle(scores, best_at - cv::Point(suppress_px, suppress_px),
                    best_at + cv::Point(suppress_px, suppress_px), cv::Scalar(kNotScored),
                    cv::FILLED);
    }
    return found;
  };
  // One candidate per depth, each depth on its own (the order kept: a tie sorts the same way
  // whatever the thread count).
  std::vector<std::optional<SearchCandidate>> per_depth(settings_.depth_scales.size());
  // The centres searched (the same at every depth), at the working and the coarse size.
  const cv::Rect centres = centres_within(small, reference_px, reach_working);
  if (centres.empty()) return candidates;
  Eigen::Vector2d coarse_reference = Eigen::Vector2d::Zero();
  double coarse_reach = 0.0;
  cv::Rect coarse_centres;
  if (coarse) {
    coarse_reference = coarse_camera.project(reference * center_object_);
    coarse_reach = reach_working * coarse_camera.fx() / working_camera.fx();
    coarse_centres = centres_within(coarse_posterior, coarse_reference, coarse_reach);
  }
  workers_->parallel_for(static_cast<int>(per_depth.size()), [&](int d) {
    const double depth_m = reference_depth * settings_.depth_scales[static_cast<std::size_t>(d)];
    const double radius_px = working_camera.fx() * 0.5 * diameter_m_ / depth_m;
    const SilhouetteTemplate silhouette =
        silhouette_template(working_camera, small.size(), reference, depth_m);
    if (silhouette.empty()) return;
    std::vector<Peak> found;
    cv::Mat visible;
    // Coarse to fine when the area searched is large and the object large enough to show at
    // half size: the coarse map's best peaks, each searched again at the working size within
    // kFineReachPx (the coarse pixel's footprint and a pixel of slack).
    if (coarse && centres.area() > kCoarseMinCentres && radius_px >= kCoarseMinRadiusPx) {
      if (coarse_centres.empty()) return;
      const SilhouetteTemplate coarse_silhouette =
          silhouette_template(coarse_camera, coarse_posterior.size(), reference, depth_m);
      if (coarse_silhouette.empty()) return;
      cv::Mat coarse_visible;
      const cv::Mat coarse_map =
          contrast_map(coarse_posterior, coarse_silhouette, coarse_centres, coarse_visible);
      const int suppress = std::max(2, static_cast<int>(0.25 * radius_px * coarse_camera.fx() /
                                                        working_camera.fx()));
      for (const Peak& p : peaks(coarse_map, coarse_visible, coarse_centres, coarse_reference, coarse_reach,
                                 kCoarsePeaks, suppress)) {
        const Eigen::Vector2d fine_px(2.0 * p.at.x + 0.5, 2.0 * p.at.y + 0.5);
        const cv::Rect fine_centres =
            centres_within(small, fine_px, kFineReachPx) & centres;
        if (fine_centres.empty()) continue;
        const cv::Mat fine_map = contrast_map(posterior, silhouette, fine_centres, visible);
        for (const Peak& q : peaks(fine_map, visible, fine_centres, reference_px, reach_working, 1, 0))
          found.push_back(q);
      }
    } else {
      const cv::Mat map = contrast_map(posterior, silhouette, centres, visible);
      found = peaks(map, visible, centres, reference_px, reach_working, 1, 0);
    }
    if (found.empty()) return;
    const Peak best = *std::max_element(found.begin(), found.end(), [](const Peak& a, const Peak& b) {
      return a.contrast < b.contrast;
    });
    SearchCandidate candidate;
    candidate.object_to_camera = placed_at(reference, center_object_, working_camera,
                                           Eigen::Vector2d(best.at.x, best.at.y), depth_m);
    candidate.contrast = best.contrast;
    candidate.visible_fraction = best.visible_fraction;
    per_depth[static_cast<std::size_t>(d)] = candidate;
  });
  for (const auto& candidate : per_depth)
    if (candidate) candidates.push_back(*candidate);
  std::sort(candidates.begin(), candidates.end(),
            [](const SearchCandidate& a, const SearchCandidate& b) { return a.contrast > b.contrast; });
  return candidates;
}

}  // namespace kct
