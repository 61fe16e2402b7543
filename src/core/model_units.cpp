#include "klt_contour_tracker/core/model_units.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace kct {

ModelUnits::ModelUnits(double metres_per_unit) : metres_per_unit_(metres_per_unit) {
  if (!(std::isfinite(metres_per_unit) && metres_per_unit >= kMinScale &&
        metres_per_unit <= kMaxScale)) {
    std::ostringstream message;
    message << "model scale (metres per model unit) is " << metres_per_unit << "; allowed: ["
            << kMinScale << ", " << kMaxScale << "] (1 for metres, 0.001 for millimetres)";
    throw std::invalid_argument(message.str());
  }
}

Pose ModelUnits::to_metres(const Pose& object_to_camera) const {
  Pose pose = object_to_camera;
  pose.translation() *= metres_per_unit_;
  return pose;
}

Pose ModelUnits::from_metres(const Pose& object_to_camera_m) const {
  Pose pose = object_to_camera_m;
  pose.translation() /= metres_per_unit_;
  return pose;
}

std::vector<Pose> ModelUnits::to_metres(const std::vector<Pose>& poses) const {
  std::vector<Pose> out;
  out.reserve(poses.size());
  for (const Pose& pose : poses) out.push_back(to_metres(pose));
  return out;
}

std::vector<Pose> ModelUnits::from_metres(const std::vector<Pose>& poses_m) const {
  std::vector<Pose> out;
  out.reserve(poses_m.size());
  for (const Pose& pose : poses_m) out.push_back(from_metres(pose));
  return out;
}

}  // namespace kct
