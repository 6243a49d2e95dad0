// Shapes, meshes and a UR5e-like arm built in code for the collision, cell and URDF tests.
#pragma once

#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "../geometry/test_meshes.h"
#include "geometry/mesh.h"
#include "robot/cell.h"
#include "robot/chain.h"

namespace wrap::testing {

inline Shape Capsule(const Vec3& p0, const Vec3& p1, double r, std::string name = "capsule") {
  Shape s;
  s.type = Shape::Type::kCapsule;
  s.p0 = p0;
  s.p1 = p1;
  s.radius = r;
  s.name = std::move(name);
  return s;
}

inline Shape Cylinder(const Vec3& p0, const Vec3& p1, double r, std::string name = "cylinder") {
  Shape s = Capsule(p0, p1, r, std::move(name));
  s.type = Shape::Type::kCylinder;
  return s;
}

inline Shape Sphere(const Vec3& c, double r, std::string name = "sphere") {
  Shape s = Capsule(c, c, r, std::move(name));
  s.type = Shape::Type::kSphere;
  return s;
}

inline Shape Box(const Vec3& center, const Vec3& half, std::string name = "box") {
  Shape s;
  s.type = Shape::Type::kBox;
  s.X_LS.translation() = center;
  s.half_extents = half;
  s.name = std::move(name);
  return s;
}

/// Closed box mesh from `lo` to `hi` [m]: 8 vertices, 12 outward triangles.
inline TriangleMesh BoxMesh(const Vec3& lo, const Vec3& hi) { return test_meshes::MakeBox(lo, hi); }

inline Shape MeshShape(TriangleMesh mesh, std::string name = "mesh") {
  Shape s;
  s.type = Shape::Type::kMesh;
  s.mesh = std::move(mesh);
  s.name = std::move(name);
  return s;
}

inline Iso3 Translation(double x, double y, double z) {
  Iso3 X = Iso3::Identity();
  X.translation() = Vec3(x, y, z);
  return X;
}

inline Iso3 Pose(const Vec3& xyz, const Vec3& rpy) {
  Iso3 X = Iso3::Identity();
  X.linear() = RotationFromRpy(rpy);
  X.translation() = xyz;
  return X;
}

// ---- UR5e: standard DH and the collision capsules of ROBOTS.md 1.1 and 1.4 ----

/// DH frames 0..6 of a UR5e at q (frame 0 = base, frame 6 = flange) in the world, the base at
/// X_WB: the link frames the cell takes.
inline std::vector<Iso3> Ur5eFrames(const std::array<double, 6>& q,
                                    const Iso3& X_WB = Iso3::Identity()) {
  constexpr double d[6] = {0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996};
  constexpr double a[6] = {0.0, -0.425, -0.3922, 0.0, 0.0, 0.0};
  constexpr double alpha[6] = {std::numbers::pi / 2,  0.0, 0.0, std::numbers::pi / 2,
                               -std::numbers::pi / 2, 0.0};
  std::vector<Iso3> X(7, X_WB);
  for (int i = 0; i < 6; ++i) {
    Iso3 T = Iso3::Identity();
    T.rotate(Eigen::AngleAxisd(q[i], Vec3::UnitZ()));
    T.translate(Vec3(a[i], 0.0, d[i]));
    T.rotate(Eigen::AngleAxisd(alpha[i], Vec3::UnitX()));
    X[i + 1] = X[i] * T;
  }
  return X;
}

/// A UR5e chain whose link i frame is DH frame i, with the fact sheet's capsules.
inline Chain Ur5eChain() {
  Chain c;
  c.name = "ur5e";
  const char* names[7] = {"base",    "shoulder", "upper_arm", "forearm",
                          "wrist_1", "wrist_2",  "wrist_3"};
  for (const char* n : names) c.links.push_back(Link{n, {}, {}});
  c.links[0].collision = {Cylinder({0, 0, 0}, {0, 0, 0.099}, 0.0755, "base")};
  c.links[1].collision = {Capsule({0, -0.0995, 0}, {0, 0.0205, 0}, 0.060, "shoulder")};
  c.links[2].collision = {Capsule({0.425, 0, 0.158}, {0.425, 0, 0.038}, 0.060, "upper_arm/housing"),
                          Capsule({0.425, 0, 0.138}, {0.025, 0, 0.138}, 0.050, "upper_arm/tube")};
  c.links[3].collision = {Capsule({0.3922, 0, 0.147}, {0.3922, 0, 0.027}, 0.055, "forearm/housing"),
                          Capsule({0.3822, 0, 0.007}, {0.0022, 0, 0.007}, 0.038, "forearm/tube")};
  c.links[4].collision = {Capsule({0, -0.0063, 0}, {0, -0.1463, 0}, 0.040, "wrist_1")};
  c.links[5].collision = {Capsule({0, 0.1202, 0}, {0, 0, 0}, 0.040, "wrist_2/a"),
                          Capsule({0, 0, 0.0607}, {0, 0, -0.0193}, 0.040, "wrist_2/b")};
  c.links[6].collision = {Cylinder({0, 0, 0.001}, {0, 0, -0.039}, 0.040, "wrist_3")};
  const char* joints[6] = {"shoulder_pan", "shoulder_lift", "elbow",
                           "wrist_1",      "wrist_2",       "wrist_3"};
  for (const char* n : joints) c.joints.push_back(Joint{.name = n});
  return c;
}

/// A Robotiq 2F-85-like gripper, open: body and finger boxes of ROBOTS.md 2.1, TCP 0.1493 m.
inline CellEndEffector Gripper2f85() {
  CellEndEffector ee;
  ee.name = "robotiq_2f85";
  ee.collision = {Box({0, 0, 0.045}, {0.045, 0.035, 0.045}, "body"),
                  Box({0.0585, 0, 0.108}, {0.0158, 0.0135, 0.053}, "finger_right"),
                  Box({-0.0585, 0, 0.108}, {0.0158, 0.0135, 0.053}, "finger_left")};
  ee.X_FT = Translation(0, 0, 0.1493);
  return ee;
}

}  // namespace wrap::testing
