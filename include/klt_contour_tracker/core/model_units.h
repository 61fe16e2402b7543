#pragma once
/// \file model_units.h
/// The one conversion between a model's units and the metres the tracker works in. A model
/// given in millimetres (OPT, BCOT, RBOT exports) has its mesh *and* its poses (pose.txt) in
/// millimetres; `--model-scale 0.001` converts both at the I/O boundary (read_sequence(),
/// write_pose_file(), load_mesh()), so everything inside the core is metres and everything a
/// user reads or writes is in the units they gave. ROS messages and parameters are always
/// metres (REP 103): only the mesh file goes through ~mesh_scale there.

#include <vector>

#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// Metres per model unit (1 for metres, 0.001 for millimetres) and the conversions it implies.
/// Rotations are unit-free; translations and lengths scale.
class ModelUnits {
 public:
  /// Smallest and largest metres per unit accepted (a micrometre to a kilometre per unit).
  static constexpr double kMinScale = 1e-6;
  static constexpr double kMaxScale = 1e3;

  /// Throws std::invalid_argument naming `metres_per_unit`, its value and the allowed range
  /// [kMinScale, kMaxScale] when it is not a finite number in it.
  explicit ModelUnits(double metres_per_unit = 1.0);

  double metres_per_unit() const { return metres_per_unit_; }
  bool is_metres() const { return metres_per_unit_ == 1.0; }

  /// Length in model units -> metres, and back.
  double to_metres(double length) const { return length * metres_per_unit_; }
  double from_metres(double length_m) const { return length_m / metres_per_unit_; }
  /// object_to_camera with its translation in model units -> metres (rotation unchanged), and back.
  Pose to_metres(const Pose& object_to_camera) const;
  Pose from_metres(const Pose& object_to_camera_m) const;
  std::vector<Pose> to_metres(const std::vector<Pose>& poses) const;
  std::vector<Pose> from_metres(const std::vector<Pose>& poses_m) const;

 private:
  double metres_per_unit_;
};

}  // namespace kct
