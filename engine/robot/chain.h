// Serial kinematic chains and the shapes attached to their links (the robot stage's plain data).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/pose.h"
#include "geometry/mesh.h"

namespace wrap {

/// A primitive or mesh collision/visual shape, in the frame of the link that carries it.
struct Shape {
  enum class Type { kCapsule, kCylinder, kBox, kSphere, kMesh };
  Type type = Type::kCapsule;
  /// Capsule/cylinder: segment end points p0, p1 [m] (the axis), radius [m]. Sphere: centre p0
  /// (p1 = p0), radius [m].
  Vec3 p0 = Vec3::Zero();
  Vec3 p1 = Vec3::Zero();
  double radius = 0.0;
  /// Box: pose of the box centre in the link frame and half extents [m].
  Iso3 X_LS = Iso3::Identity();
  Vec3 half_extents = Vec3::Zero();
  /// Mesh: vertices in the link frame [m] (shared with the renderer).
  TriangleMesh mesh;
  std::string name;  ///< For messages, e.g. "upper_arm/tube".
};

/// One joint of a serial chain. The joint frame J is at `X_PJ` in the parent link frame P at
/// q = 0; the child link frame equals J moved by the joint: Rot(axis, q) or Trans(axis * q).
struct Joint {
  enum class Type { kRevolute, kPrismatic };
  std::string name;  ///< e.g. "shoulder_pan".
  Type type = Type::kRevolute;
  Iso3 X_PJ = Iso3::Identity();      ///< Joint frame in the parent link frame.
  Vec3 axis = Vec3::UnitZ();         ///< Unit axis in the joint frame.
  double lower = -3.14159265358979;  ///< Position limits [rad or m].
  double upper = 3.14159265358979;
  double max_velocity = 1.0;      ///< [rad/s or m/s].
  double max_acceleration = 5.0;  ///< [rad/s^2 or m/s^2].
  double max_effort = 0.0;        ///< [N m or N], 0 when unknown.
};

/// A link: its collision and visual shapes in its own frame.
struct Link {
  std::string name;              ///< e.g. "forearm".
  std::vector<Shape> collision;  ///< Conservative collision shapes.
  std::vector<Shape> visual;     ///< Display shapes (may equal collision).
};

/// A serial arm: link 0 is the base (fixed in the robot base frame), link i+1 follows joint i.
/// The flange frame is `X_LF` in the last link; end effectors attach at the flange.
struct Chain {
  std::string name;              ///< Catalog key or URDF robot name.
  std::vector<Link> links;       ///< joints.size() + 1 links.
  std::vector<Joint> joints;     ///< Movable joints, base to tip.
  Iso3 X_LF = Iso3::Identity();  ///< Flange in the last link's frame.
  int dof() const { return static_cast<int>(joints.size()); }
};

}  // namespace wrap
