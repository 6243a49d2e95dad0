#include "question_json.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace wrap {

namespace {

using nlohmann::json;
constexpr double kInf = std::numeric_limits<double>::infinity();

// A field that is missing or of the wrong shape: its name goes into the error.
struct BadField : std::runtime_error {
  using std::runtime_error::runtime_error;
};

json Number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}

double ReadNumber(const json& j, const std::string& field) {
  if (j.is_number()) return j.get<double>();
  if (j == "inf") return kInf;
  if (j == "-inf") return -kInf;
  throw BadField(field + ": expected a number");
}

const json& At(const json& j, const std::string& key, const std::string& field) {
  if (!j.is_object() || !j.contains(key)) throw BadField(field + key + ": missing");
  return j[key];
}

template <typename Vec>
json Vector(const Vec& v) {
  json out = json::array();
  for (int i = 0; i < v.size(); ++i) out.push_back(Number(v[i]));
  return out;
}

template <int N>
Eigen::Matrix<double, N, 1> ReadVector(const json& j, const std::string& field) {
  if (!j.is_array() || j.size() != N)
    throw BadField(field + ": expected " + std::to_string(N) + " numbers");
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) v[i] = ReadNumber(j[i], field);
  return v;
}

// The 3x4 matrix [R | p], row by row: exact, unlike a rotation vector.
json PoseJson(const Iso3& X) {
  json out = json::array();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) out.push_back(X.matrix()(r, c));
  }
  return out;
}

Iso3 ReadPose(const json& j, const std::string& field) {
  const Eigen::Matrix<double, 12, 1> v = ReadVector<12>(j, field);
  Iso3 X = Iso3::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) X.matrix()(r, c) = v[4 * r + c];
  }
  return X;
}

json Bounds(const WrenchBounds& b) {
  return {{"lower", Vector(b.lower)}, {"upper", Vector(b.upper)}};
}

WrenchBounds ReadBounds(const json& j, const std::string& field) {
  WrenchBounds b;
  b.lower = ReadVector<6>(At(j, "lower", field + "."), field + ".lower");
  b.upper = ReadVector<6>(At(j, "upper", field + "."), field + ".upper");
  return b;
}

int ReadInt(const json& j, const std::string& field) {
  if (!j.is_number_integer()) throw BadField(field + ": expected an integer");
  return j.get<int>();
}

json MatingJson(const MatingLoad& m) {
  return {{"moved", m.moved},
          {"base", m.base},
          {"axis", Vector(m.axis_W)},
          {"contact", Vector(m.p_WContact)},
          {"force_N", m.force_N},
          {"torque_Nm", m.torque_Nm},
          {"transverse_fraction", m.transverse_fraction},
          {"offset_m", m.offset_m}};
}

MatingLoad ReadMating(const json& j) {
  MatingLoad m;
  m.moved = ReadInt(At(j, "moved", "mating."), "mating.moved");
  m.base = ReadInt(At(j, "base", "mating."), "mating.base");
  m.axis_W = ReadVector<3>(At(j, "axis", "mating."), "mating.axis");
  m.p_WContact = ReadVector<3>(At(j, "contact", "mating."), "mating.contact");
  m.force_N = ReadNumber(At(j, "force_N", "mating."), "mating.force_N");
  m.torque_Nm = ReadNumber(At(j, "torque_Nm", "mating."), "mating.torque_Nm");
  m.transverse_fraction =
      ReadNumber(At(j, "transverse_fraction", "mating."), "mating.transverse_fraction");
  m.offset_m = ReadNumber(At(j, "offset_m", "mating."), "mating.offset_m");
  return m;
}

void ReadBodies(const json& j, StepConfiguration& c) {
  for (const json& b : At(j, "bodies", "")) {
    c.bodies.push_back({At(b, "name", "bodies[].").get<std::string>(),
                        ReadNumber(At(b, "mass_kg", "bodies[]."), "bodies[].mass_kg"),
                        ReadVector<3>(At(b, "com", "bodies[]."), "bodies[].com")});
  }
  for (const json& k : At(j, "connections", "")) {
    WrenchConnection x;
    x.body_a = ReadInt(At(k, "body_a", "connections[]."), "connections[].body_a");
    x.body_b = ReadInt(At(k, "body_b", "connections[]."), "connections[].body_b");
    x.X_WC = ReadPose(At(k, "X_WC", "connections[]."), "connections[].X_WC");
    x.limits = ReadBounds(At(k, "limits", "connections[]."), "connections[].limits");
    x.name = At(k, "name", "connections[].").get<std::string>();
    c.connections.push_back(std::move(x));
  }
}

void ReadSupports(const json& j, StepConfiguration& c) {
  for (const json& g : At(j, "grippers", "")) {
    WrenchGripper x;
    x.name = At(g, "name", "grippers[].").get<std::string>();
    x.body = ReadInt(At(g, "body", "grippers[]."), "grippers[].body");
    x.X_WG = ReadPose(At(g, "X_WG", "grippers[]."), "grippers[].X_WG");
    x.kind = At(g, "vacuum", "grippers[].").get<bool>() ? EndEffectorKind::kVacuum
                                                        : EndEffectorKind::kTwoFinger;
    x.assembly_limits = ReadBounds(At(g, "assembly", "grippers[]."), "grippers[].assembly");
    x.transport_limits = ReadBounds(At(g, "transport", "grippers[]."), "grippers[].transport");
    c.grippers.push_back(std::move(x));
  }
  for (const json& t : At(j, "tables", "")) {
    WrenchTableSupport x;
    x.body = ReadInt(At(t, "body", "tables[]."), "tables[].body");
    for (const json& v : At(t, "polygon", "tables[].")) {
      x.p_WV.push_back(ReadVector<3>(v, "tables[].polygon[]"));
    }
    x.friction = ReadNumber(At(t, "friction", "tables[]."), "tables[].friction");
    x.pyramid_edges = ReadInt(At(t, "pyramid_edges", "tables[]."), "tables[].pyramid_edges");
    x.normal_W = ReadVector<3>(At(t, "normal", "tables[]."), "tables[].normal");
    c.tables.push_back(std::move(x));
  }
}

}  // namespace

json WrenchQuestionToJson(const WrenchQuestion& q) {
  const StepConfiguration& c = q.config;
  json j;
  j["source"] = q.source;
  j["gate"] = static_cast<int>(q.query.gate);
  j["mode"] = static_cast<int>(q.query.mode);
  j["lambda"] = q.query.lambda;
  j["accel_margin_mps2"] = q.query.accel_margin_mps2;
  j["gravity"] = Vector(c.gravity_W);
  j["bodies"] = json::array();
  for (const WrenchBody& b : c.bodies) {
    j["bodies"].push_back({{"name", b.name}, {"mass_kg", b.mass_kg}, {"com", Vector(b.p_WBcm)}});
  }
  j["connections"] = json::array();
  for (const WrenchConnection& k : c.connections) {
    j["connections"].push_back({{"body_a", k.body_a},
                                {"body_b", k.body_b},
                                {"X_WC", PoseJson(k.X_WC)},
                                {"limits", Bounds(k.limits)},
                                {"name", k.name}});
  }
  j["grippers"] = json::array();
  for (const WrenchGripper& g : c.grippers) {
    j["grippers"].push_back({{"name", g.name},
                             {"body", g.body},
                             {"X_WG", PoseJson(g.X_WG)},
                             {"vacuum", g.kind == EndEffectorKind::kVacuum},
                             {"assembly", Bounds(g.assembly_limits)},
                             {"transport", Bounds(g.transport_limits)}});
  }
  j["tables"] = json::array();
  for (const WrenchTableSupport& t : c.tables) {
    json polygon = json::array();
    for (const Vec3& v : t.p_WV) polygon.push_back(Vector(v));
    j["tables"].push_back({{"body", t.body},
                           {"polygon", polygon},
                           {"friction", t.friction},
                           {"pyramid_edges", t.pyramid_edges},
                           {"normal", Vector(t.normal_W)}});
  }
  if (c.mating) j["mating"] = MatingJson(*c.mating);
  return j;
}

Result<WrenchQuestion> WrenchQuestionFromJson(const json& j) {
  WrenchQuestion q;
  try {
    q.source = At(j, "source", "").get<std::string>();
    q.query.gate = static_cast<WrenchGate>(ReadInt(At(j, "gate", ""), "gate"));
    q.query.mode = static_cast<MatingWrenchMode>(ReadInt(At(j, "mode", ""), "mode"));
    q.query.lambda = ReadNumber(At(j, "lambda", ""), "lambda");
    q.query.accel_margin_mps2 = ReadNumber(At(j, "accel_margin_mps2", ""), "accel_margin_mps2");
    q.config.gravity_W = ReadVector<3>(At(j, "gravity", ""), "gravity");
    ReadBodies(j, q.config);
    ReadSupports(j, q.config);
    if (j.contains("mating")) q.config.mating = ReadMating(j["mating"]);
  } catch (const std::exception& e) {
    return Fail(ErrorCode::kInvalidInput, std::string("wrench question: ") + e.what());
  }
  return q;
}

}  // namespace wrap
