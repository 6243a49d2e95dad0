#include "generator/part_designs.h"

#include <array>
#include <numbers>
#include <utility>

#include "generator/solid_meshers.h"
#include "geometry/mesh_export.h"

namespace wrap::partgen {

namespace {

// All design dimensions are in millimetres; meshes are scaled to metres at the end.
constexpr double kMetresPerMm = 0.001;
constexpr int kSegments = 48;  // facets of round parts

// Stool and chair: a square seat with four blind pockets from below, round legs with a peg and a
// snap ring that clicks into a groove inside the pocket.
constexpr double kSeatSide = 240.0;
constexpr double kSeatThickness = 25.0;
constexpr double kLegOffset = 85.0;      // leg axes at (+-85, +-85) in the seat frame
constexpr double kLegPocketHalf = 10.0;  // 20 mm square pocket
constexpr double kLegPocketDepth = 15.0;
constexpr double kGrooveHalf = 10.5;   // snap groove, 0.5 mm deep
constexpr double kGrooveBottom = 3.5;  // from the seat's underside
constexpr double kGrooveTop = 7.5;
constexpr double kLegRadius = 12.5;     // 25 mm round leg
constexpr double kLegShoulder = 185.0;  // height of the shoulder the seat rests on
constexpr double kLegPegRadius = 9.5;   // 0.5 mm clearance in the 20 mm pocket
constexpr double kLegRingRadius = 9.8;  // snap ring: passes the mouth with 0.2 mm
constexpr double kLegTop = 199.0;       // peg tip, 1 mm short of the pocket floor

// Chair backrest: two square posts with a peg at each end, a top rail with two pockets; the posts'
// lower pegs go into two pockets at the rear of the seat top.
constexpr double kPostSide = 18.0;
constexpr double kPostLength = 250.0;  // body, without the pegs
constexpr double kPostPegHalf = 6.0;   // 12 mm square peg
constexpr double kPostPegLength = 8.0;
constexpr double kPostPocketHalf = 6.5;   // 0.5 mm clearance
constexpr double kPostPocketDepth = 9.0;  // 1 mm beyond the peg tip
constexpr double kPostRearY = -105.0;     // post axes at (+-85, -105) in the seat frame
constexpr double kRailLength = 210.0;
constexpr double kRailDepth = 20.0;
constexpr double kRailHeight = 40.0;

// Cross and cubes: 60 mm blocks.
constexpr double kBlockSide = 60.0;
constexpr double kBlockHalf = 0.5 * kBlockSide;
constexpr double kCrossPocketHalf = 10.0;  // 20 mm square pocket in each face of the centre
constexpr double kCrossPocketDepth = 8.0;
constexpr double kCrossPegHalf = 9.5;  // 19 mm square peg on each arm
constexpr double kCrossPegLength = 7.0;
// Cube blocks join by two 8 mm studs per face. Vertical joints use studs near two opposite corners
// (the face centre stays free for a 40 mm suction cup); horizontal joints use two studs in the
// lower half of the face, clear of the top pockets.
constexpr double kStudHalf = 4.0;
constexpr double kStudLength = 5.0;
constexpr double kStudPocketHalf = 4.5;   // 0.5 mm clearance
constexpr double kStudPocketDepth = 6.0;  // 1 mm beyond the stud tip
constexpr std::array<std::array<double, 2>, 2> kTopStuds = {{{20.0, 20.0}, {-20.0, -20.0}}};
constexpr std::array<std::array<double, 2>, 2> kSideStuds = {{{15.0, -15.0}, {-15.0, -15.0}}};

/// Design of a pocket or peg on a face of a block centred at the origin: the face's outward
/// normal is `sign` along `axis`; (u, v) are the face coordinates along the other axes, v along
/// z for side faces and u along x, v along y for the top and bottom; `half` is half the square's
/// side; the feature spans [d0, d1] along the outward normal, measured from the face.
Box FaceFeature(int axis, double sign, std::array<double, 2> uv, double half, double d0,
                double d1) {
  Vec3 c = Vec3::Zero();
  Vec3 size = Vec3::Constant(2.0 * half);
  const int u_axis = axis == 2 ? 0 : (axis == 0 ? 1 : 0);
  const int v_axis = axis == 2 ? 1 : 2;
  c[u_axis] = uv[0];
  c[v_axis] = uv[1];
  c[axis] = sign * (kBlockHalf + 0.5 * (d0 + d1));
  size[axis] = d1 - d0;
  return CenteredBox(c, size);
}

Box StudBox(int axis, double sign, std::array<double, 2> uv) {
  return FaceFeature(axis, sign, uv, kStudHalf, 0.0, kStudLength);
}

Box StudPocketBox(int axis, double sign, std::array<double, 2> uv) {
  return FaceFeature(axis, sign, uv, kStudPocketHalf, -kStudPocketDepth, 0.0);
}

Box BlockBox() { return CenteredBox(Vec3::Zero(), Vec3::Constant(kBlockSide)); }

/// Leg pocket (with its snap groove) centred at (x, y) in the seat frame.
std::array<Box, 2> LegPocketBoxes(double x, double y) {
  return {Box{Vec3(x - kLegPocketHalf, y - kLegPocketHalf, 0.0),
              Vec3(x + kLegPocketHalf, y + kLegPocketHalf, kLegPocketDepth)},
          Box{Vec3(x - kGrooveHalf, y - kGrooveHalf, kGrooveBottom),
              Vec3(x + kGrooveHalf, y + kGrooveHalf, kGrooveTop)}};
}

/// Post pocket in the seat top, centred at (x, y) in the seat frame.
Box PostPocketBox(double x, double y) {
  return Box{Vec3(x - kPostPocketHalf, y - kPostPocketHalf, kSeatThickness - kPostPocketDepth),
             Vec3(x + kPostPocketHalf, y + kPostPocketHalf, kSeatThickness)};
}

/// Rail pocket (from below) centred at x in the rail frame.
Box RailPocketBox(double x) {
  return Box{Vec3(x - kPostPocketHalf, -kPostPocketHalf, 0.0),
             Vec3(x + kPostPocketHalf, kPostPocketHalf, kPostPocketDepth)};
}

constexpr std::array<std::array<double, 2>, 4> kLegCorners = {{{kLegOffset, kLegOffset},
                                                               {-kLegOffset, kLegOffset},
                                                               {-kLegOffset, -kLegOffset},
                                                               {kLegOffset, -kLegOffset}}};

/// Seat: frame at the centre of the underside, z up; with two post pockets for the chair.
BoxSolid SeatSolid(bool chair) {
  BoxSolid s;
  s.Add(Box{Vec3(-0.5 * kSeatSide, -0.5 * kSeatSide, 0.0),
            Vec3(0.5 * kSeatSide, 0.5 * kSeatSide, kSeatThickness)});
  for (const auto& [x, y] : kLegCorners) {
    for (const Box& b : LegPocketBoxes(x, y)) s.Subtract(b);
  }
  if (chair) {
    for (double x : {kLegOffset, -kLegOffset}) s.Subtract(PostPocketBox(x, kPostRearY));
  }
  return s;
}

/// Leg profile: frame at the centre of the foot, z up; chamfered foot, shoulder, peg with a snap
/// ring (steep face down so that it catches in the groove), chamfered tip.
std::vector<ProfilePoint> LegProfile() {
  return {{kLegRadius - 1.0, 0.0},
          {kLegRadius, 1.0},
          {kLegRadius, kLegShoulder},
          {kLegPegRadius, kLegShoulder},
          {kLegPegRadius, kLegShoulder + 4.0},
          {kLegRingRadius, kLegShoulder + 4.0},
          {kLegRingRadius, kLegShoulder + 5.5},
          {kLegPegRadius, kLegShoulder + 7.0},
          {kLegPegRadius, kLegTop - 1.0},
          {kLegPegRadius - 1.0, kLegTop}};
}

/// Post: frame at the centre of the body's lower end, z along the post.
BoxSolid PostSolid() {
  BoxSolid s;
  s.Add(Box{Vec3(-0.5 * kPostSide, -0.5 * kPostSide, 0.0),
            Vec3(0.5 * kPostSide, 0.5 * kPostSide, kPostLength)});
  s.Add(Box{Vec3(-kPostPegHalf, -kPostPegHalf, -kPostPegLength),
            Vec3(kPostPegHalf, kPostPegHalf, 0.0)});
  s.Add(Box{Vec3(-kPostPegHalf, -kPostPegHalf, kPostLength),
            Vec3(kPostPegHalf, kPostPegHalf, kPostLength + kPostPegLength)});
  return s;
}

/// Rail: frame at the centre of the underside, the length along x, pockets from below.
BoxSolid RailSolid() {
  BoxSolid s;
  s.Add(Box{Vec3(-0.5 * kRailLength, -0.5 * kRailDepth, 0.0),
            Vec3(0.5 * kRailLength, 0.5 * kRailDepth, kRailHeight)});
  for (double x : {kLegOffset, -kLegOffset}) s.Subtract(RailPocketBox(x));
  return s;
}

/// Cross centre: a block with a pocket in the middle of each face.
BoxSolid CrossCenterSolid() {
  BoxSolid s;
  s.Add(BlockBox());
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      s.Subtract(FaceFeature(axis, sign, {0.0, 0.0}, kCrossPocketHalf, -kCrossPocketDepth, 0.0));
    }
  }
  return s;
}

/// Cross arm: a block with one peg on its top face (+z).
BoxSolid CrossArmSolid() {
  BoxSolid s;
  s.Add(BlockBox());
  s.Add(FaceFeature(2, 1.0, {0.0, 0.0}, kCrossPegHalf, 0.0, kCrossPegLength));
  return s;
}

/// The four cube blocks. In the 2x2x2 (and 2x2x3) cube, with cube i at the origin:
/// anchor (0,0,0) has pockets on +x, +y, +z; block_x (1,0,0) has studs on -x and pockets on +y,
/// +z; block_y (0,1,0) and (1,1,0) have studs on -y and pockets on +z; block_z (every upper
/// layer) has studs on -z and pockets on +z.
BoxSolid CubeBlockSolid(std::string_view kind) {
  BoxSolid s;
  s.Add(BlockBox());
  if (kind == "block_x") {
    for (const auto& uv : kSideStuds) s.Add(StudBox(0, -1.0, uv));
  } else if (kind == "block_y") {
    for (const auto& uv : kSideStuds) s.Add(StudBox(1, -1.0, uv));
  } else if (kind == "block_z") {
    for (const auto& uv : kTopStuds) s.Add(StudBox(2, -1.0, uv));
  }
  if (kind == "anchor") {
    for (const auto& uv : kSideStuds) s.Subtract(StudPocketBox(0, 1.0, uv));
  }
  if (kind == "anchor" || kind == "block_x") {
    for (const auto& uv : kSideStuds) s.Subtract(StudPocketBox(1, 1.0, uv));
  }
  for (const auto& uv : kTopStuds) s.Subtract(StudPocketBox(2, 1.0, uv));
  return s;
}

Result<TriangleMesh> InMetres(Result<TriangleMesh> mm) {
  if (!mm) return mm;
  return Scaled(*mm, kMetresPerMm);
}

/// Aabb in metres of a box in millimetres.
Aabb ToAabb(const Box& b) { return Aabb{b.min * kMetresPerMm, b.max * kMetresPerMm}; }

/// The pure translation by (x, y, z) given in millimetres.
Iso3 Translation(const Vec3& xyz_mm) {
  Iso3 X = Iso3::Identity();
  X.translation() = xyz_mm * kMetresPerMm;
  return X;
}

/// The six cross arms: position of the arm block relative to the centre (unit direction) and the
/// arm's orientation (roll, pitch, yaw in degrees) that points its +z peg at the centre.
struct CrossArm {
  Vec3 direction;
  Vec3 rpy_deg;
};
const std::array<CrossArm, 6>& CrossArms() {
  static const std::array<CrossArm, 6> arms = {{
      {Vec3(1, 0, 0), Vec3(0, -90, 0)},
      {Vec3(-1, 0, 0), Vec3(0, 90, 0)},
      {Vec3(0, 1, 0), Vec3(90, 0, 0)},
      {Vec3(0, -1, 0), Vec3(-90, 0, 0)},
      {Vec3(0, 0, 1), Vec3(180, 0, 0)},
      {Vec3(0, 0, -1), Vec3(0, 0, 0)},
  }};
  return arms;
}

}  // namespace

std::filesystem::path GeneratedPart::RelativePath() const {
  return std::filesystem::path(assembly) / (name + (format == MeshFormat::kStl ? ".stl" : ".obj"));
}

Result<std::vector<GeneratedPart>> GenerateParts() {
  struct Recipe {
    std::string assembly;
    std::string name;
    MeshFormat format;
    Result<TriangleMesh> mesh_mm;
  };
  std::vector<Recipe> recipes;
  recipes.push_back({"stool", "seat", MeshFormat::kStl, SeatSolid(false).Mesh()});
  recipes.push_back({"stool", "leg", MeshFormat::kStl, MeshRevolved(LegProfile(), kSegments)});
  recipes.push_back({"chair", "seat", MeshFormat::kObj, SeatSolid(true).Mesh()});
  recipes.push_back({"chair", "leg", MeshFormat::kObj, MeshRevolved(LegProfile(), kSegments)});
  recipes.push_back({"chair", "post", MeshFormat::kObj, PostSolid().Mesh()});
  recipes.push_back({"chair", "rail", MeshFormat::kObj, RailSolid().Mesh()});
  recipes.push_back({"cross", "center", MeshFormat::kObj, CrossCenterSolid().Mesh()});
  recipes.push_back({"cross", "arm", MeshFormat::kObj, CrossArmSolid().Mesh()});
  for (const char* kind : {"anchor", "block_x", "block_y", "block_z"}) {
    recipes.push_back({"cube", kind, MeshFormat::kObj, CubeBlockSolid(kind).Mesh()});
  }

  std::vector<GeneratedPart> parts;
  for (Recipe& r : recipes) {
    auto mesh = InMetres(std::move(r.mesh_mm));
    if (!mesh) {
      return Fail(ErrorCode::kInternal,
                  "part generator: " + r.assembly + "/" + r.name + ": " + mesh.error().message);
    }
    parts.push_back({r.assembly, r.name, r.format, std::move(*mesh)});
  }
  return parts;
}

Result<void> WritePart(const std::filesystem::path& out_dir, const GeneratedPart& part) {
  const std::filesystem::path path = out_dir / part.RelativePath();
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  if (ec) {
    return Fail(ErrorCode::kIo, "part generator: cannot create '" + path.parent_path().string() +
                                    "': " + ec.message());
  }
  return part.format == MeshFormat::kStl ? WriteStl(path, part.mesh, kFileUnitsPerMetre)
                                         : WriteObj(path, part.mesh, kFileUnitsPerMetre);
}

std::vector<Joint> DesignedJoints() {
  std::vector<Joint> joints;
  const double leg_clearance = (kLegPocketHalf - kLegRingRadius) * kMetresPerMm;
  const double leg_floor = (kLegShoulder + kLegPocketDepth - kLegTop) * kMetresPerMm;
  const double post_clearance = (kPostPocketHalf - kPostPegHalf) * kMetresPerMm;
  const double post_floor = (kPostPocketDepth - kPostPegLength) * kMetresPerMm;

  // Legs go up (+z) into the seat, which rests on their shoulders.
  for (const char* assembly : {"stool", "chair"}) {
    for (const auto& [x, y] : kLegCorners) {
      joints.push_back({std::string(assembly) + "/seat",
                        std::string(assembly) + "/leg",
                        Translation(Vec3(x, y, -kLegShoulder)),
                        Vec3::UnitZ(),
                        {ToAabb(LegPocketBoxes(x, y)[0])},
                        leg_clearance,
                        leg_floor});
    }
  }
  // Posts go down into the seat top, and up into the rail.
  for (double x : {kLegOffset, -kLegOffset}) {
    joints.push_back({"chair/seat",
                      "chair/post",
                      Translation(Vec3(x, kPostRearY, kSeatThickness)),
                      -Vec3::UnitZ(),
                      {ToAabb(PostPocketBox(x, kPostRearY))},
                      post_clearance,
                      post_floor});
    joints.push_back({"chair/rail",
                      "chair/post",
                      Translation(Vec3(x, 0.0, -kPostLength)),
                      Vec3::UnitZ(),
                      {ToAabb(RailPocketBox(x))},
                      post_clearance,
                      post_floor});
  }
  // Cross arms move towards the centre, their peg first.
  for (const CrossArm& arm : CrossArms()) {
    Iso3 X_BM = Translation(arm.direction * kBlockSide);
    X_BM.linear() = RotationFromRpy(arm.rpy_deg * std::numbers::pi / 180.0);
    int axis = 0;
    arm.direction.cwiseAbs().maxCoeff(&axis);
    const double sign = arm.direction[axis];
    joints.push_back(
        {"cross/center",
         "cross/arm",
         X_BM,
         -arm.direction,
         {ToAabb(FaceFeature(axis, sign, {0.0, 0.0}, kCrossPocketHalf, -kCrossPocketDepth, 0.0))},
         (kCrossPocketHalf - kCrossPegHalf) * kMetresPerMm,
         (kCrossPocketDepth - kCrossPegLength) * kMetresPerMm});
  }
  // Cube blocks: horizontal joints along -x and -y, vertical joints along -z.
  const double stud_clearance = (kStudPocketHalf - kStudHalf) * kMetresPerMm;
  const double stud_floor = (kStudPocketDepth - kStudLength) * kMetresPerMm;
  const auto stud_joint = [&](const std::string& base, const std::string& moved, int axis) {
    Joint j{"cube/" + base,
            "cube/" + moved,
            Translation(Vec3::Unit(axis) * kBlockSide),
            -Vec3::Unit(axis),
            {},
            stud_clearance,
            stud_floor};
    for (const auto& uv : axis == 2 ? kTopStuds : kSideStuds) {
      j.pockets_B.push_back(ToAabb(StudPocketBox(axis, 1.0, uv)));
    }
    return j;
  };
  joints.push_back(stud_joint("anchor", "block_x", 0));
  joints.push_back(stud_joint("anchor", "block_y", 1));
  joints.push_back(stud_joint("block_x", "block_y", 1));
  for (const char* base : {"anchor", "block_x", "block_y", "block_z"}) {
    joints.push_back(stud_joint(base, "block_z", 2));
  }
  return joints;
}

}  // namespace wrap::partgen
