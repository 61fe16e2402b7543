#include <gtest/gtest.h>

#include <random>

#include "klt_contour_tracker/core/icosphere.h"

namespace kct {
namespace {

/// Smallest of the three edge-plane dots (>= 0 inside the spherical triangle).
double containment(const Icosphere& sphere, int face, const Eigen::Vector3d& d) {
  const Eigen::Vector3i& f = sphere.faces()[face];
  const auto& v = sphere.vertices();
  return std::min({d.dot(v[f[0]].cross(v[f[1]]).normalized()),
                   d.dot(v[f[1]].cross(v[f[2]]).normalized()),
                   d.dot(v[f[2]].cross(v[f[0]]).normalized())});
}

TEST(Icosphere, VertexAndFaceCounts) {
  const int expected_vertices[] = {12, 42, 162, 642, 2562};
  for (int n = 0; n <= 4; ++n) {
    const Icosphere sphere(n);
    EXPECT_EQ(static_cast<int>(sphere.vertices().size()), expected_vertices[n]) << n;
    EXPECT_EQ(static_cast<int>(sphere.faces().size()), 20 << (2 * n)) << n;
  }
}

TEST(Icosphere, UnitVerticesAndOutwardFaces) {
  const Icosphere sphere(3);
  for (const auto& v : sphere.vertices()) EXPECT_NEAR(v.norm(), 1.0, 1e-12);
  double total_solid_angle = 0.0;
  for (const auto& f : sphere.faces()) {
    const auto &a = sphere.vertices()[f[0]], &b = sphere.vertices()[f[1]],
               &c = sphere.vertices()[f[2]];
    const double triple = a.dot(b.cross(c));
    EXPECT_GT(triple, 0.0);  // counter-clockwise seen from outside
    // Van Oosterom-Strackee solid angle of the spherical triangle.
    total_solid_angle +=
        2.0 * std::atan2(triple, 1.0 + a.dot(b) + b.dot(c) + c.dot(a));
  }
  // The spherical triangles tile the sphere without gaps or overlaps.
  EXPECT_NEAR(total_solid_angle, 4.0 * M_PI, 1e-9);
}

TEST(Icosphere, FaceLookupContainsDirection) {
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss;
  for (int n : {0, 1, 4}) {
    const Icosphere sphere(n);
    for (int trial = 0; trial < 3000; ++trial) {
      const Eigen::Vector3d d(gauss(rng), gauss(rng), gauss(rng));
      const Eigen::Vector3d unit = d.normalized();
      const int face = sphere.face_containing(3.7 * d);  // scale must not matter
      ASSERT_GE(face, 0);
      ASSERT_LT(face, static_cast<int>(sphere.faces().size()));
      EXPECT_GE(containment(sphere, face, unit), -1e-12) << "n=" << n << " trial " << trial;
      EXPECT_EQ(sphere.face_vertices_containing(d), sphere.faces()[face]);
    }
  }
}

TEST(Icosphere, FaceLookupOnVerticesAndEdgeMidpoints) {
  const Icosphere sphere(2);
  // Directions exactly on vertices and edge midpoints are the hard cases for the descent.
  std::vector<Eigen::Vector3d> directions(sphere.vertices());
  for (const auto& f : sphere.faces())
    directions.push_back((sphere.vertices()[f[0]] + sphere.vertices()[f[1]]).normalized());
  for (const auto& d : directions) {
    const int face = sphere.face_containing(d);
    EXPECT_GE(containment(sphere, face, d), -1e-12);
  }
}

TEST(Icosphere, RejectsBadSubdivisions) {
  EXPECT_THROW(Icosphere(-1), std::invalid_argument);
  EXPECT_THROW(Icosphere(8), std::invalid_argument);
  const Icosphere sphere(1);
  EXPECT_EQ(sphere.face_containing(Eigen::Vector3d::Zero()), 0);
}

}  // namespace
}  // namespace kct
