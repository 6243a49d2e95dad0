// The parts of STEP import that need no OpenCASCADE: file checks before parsing, closed-solid
// checks after tessellation, and the queries on an imported StepAssembly.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "geometry/detail/step_common.h"
#include "geometry/step_import.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

constexpr const char* kStepMagic = "ISO-10303-21;";
constexpr const char* kStepEnd = "END-ISO-10303-21;";

std::string Quote(const std::string& s) { return "'" + s + "'"; }

std::string LowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// `count` bytes from `offset` (fewer at the end of the file).
std::string ReadBytes(const fs::path& path, uintmax_t offset, size_t count) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(offset));
  std::string bytes(count, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(count));
  bytes.resize(static_cast<size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

/// The start of a file with a UTF-8 byte-order mark and leading white space skipped.
std::string_view SkipLeading(std::string_view s) {
  if (s.starts_with("\xEF\xBB\xBF")) s.remove_prefix(3);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  return s;
}

/// A few printable characters of `s` for a message.
std::string Preview(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 16)) {
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  return out;
}

}  // namespace

namespace detail {

Result<void> CheckStepFile(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) {
    if (ec && ec != std::errc::no_such_file_or_directory) {
      return Fail(ErrorCode::kIo,
                  "STEP file " + Quote(name) + " cannot be accessed: " + ec.message());
    }
    return Fail(ErrorCode::kIo, "STEP file " + Quote(name) + " not found");
  }
  if (!fs::is_regular_file(status)) {
    return Fail(ErrorCode::kIo, "STEP file " + Quote(name) + " is not a regular file");
  }
  const uintmax_t size = fs::file_size(path, ec);
  if (ec || !std::ifstream(path, std::ios::binary)) {
    return Fail(ErrorCode::kIo, "STEP file " + Quote(name) + " cannot be read: " +
                                    (ec ? ec.message() : std::string(std::strerror(errno))));
  }
  if (size == 0) {
    return Fail(ErrorCode::kInvalidInput, "STEP file " + Quote(name) + " is empty (0 bytes)");
  }
  const std::string head_bytes = ReadBytes(path, 0, 256);
  const std::string_view head = SkipLeading(head_bytes);
  if (!head.starts_with(kStepMagic)) {
    std::string what = "does not start with '" + std::string(kStepMagic) + "' (it starts with '" +
                       Preview(head) + "')";
    if (head.starts_with("<?xml") || head.starts_with("<")) {
      what = "is XML (STEP-XML, ISO 10303-28, is not read; export ISO 10303-21 instead)";
    } else if (head.starts_with("PK")) {
      what = "is a zip archive (a compressed .stpZ?); unzip it first";
    } else if (head.starts_with("solid") || LowerExtension(path) == ".stl") {
      what += "; is it an STL file? name it .stl";
    }
    return Fail(ErrorCode::kInvalidInput, "'" + name + "' is not a STEP file: it " + what);
  }
  // The end marker, with trailing white space (and padding NULs) allowed after it.
  const uintmax_t tail_size = std::min<uintmax_t>(size, 4096);
  std::string tail = ReadBytes(path, size - tail_size, static_cast<size_t>(tail_size));
  while (!tail.empty() &&
         (tail.back() == '\0' || std::isspace(static_cast<unsigned char>(tail.back())))) {
    tail.pop_back();
  }
  if (!tail.ends_with(kStepEnd)) {
    return Fail(ErrorCode::kInvalidInput, "STEP file " + Quote(name) +
                                              " is truncated: it does not end with '" +
                                              std::string(kStepEnd) + "' (" + std::to_string(size) +
                                              " bytes; was the download or export cut short?)");
  }
  return {};
}

Result<TriangleMesh> CheckClosedSolid(TriangleMesh mesh, const std::string& what) {
  if (mesh.triangles.empty()) {
    return Fail(ErrorCode::kInvalidInput, what + " has no triangles after tessellation");
  }
  const MeshTopology topology = AnalyzeTopology(mesh);
  if (!topology.closed()) {
    return Fail(ErrorCode::kInvalidInput,
                what + " does not mesh closed (" + std::to_string(topology.boundary_edges) +
                    " open edges, " + std::to_string(topology.non_manifold_edges) +
                    " non-manifold edges); expected a closed solid: repair it in the CAD tool "
                    "(or export it as a solid, not as surfaces)");
  }
  const double volume = ComputeMassProperties(mesh).volume_m3;
  if (!(std::abs(volume) > 0.0)) {
    return Fail(ErrorCode::kInvalidInput, what + " encloses no volume");
  }
  if (volume < 0.0) {
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  }
  return mesh;
}

std::string EntityAtLine(const fs::path& path, long line) {
  std::ifstream in(path, std::ios::binary);
  std::string text, entity;
  for (long n = 1; n <= line && std::getline(in, text); ++n) {
    const size_t at = text.find_first_not_of(" \t");
    if (at == std::string::npos || text[at] != '#') continue;
    size_t end = at + 1;
    while (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end]))) ++end;
    if (end > at + 1) entity = text.substr(at, end - at);
  }
  return entity;
}

std::string WithEntityOfLine(const fs::path& path, const std::string& message) {
  const size_t at = message.find("Line ");
  if (at == std::string::npos) return message;
  size_t end = at + 5;
  while (end < message.size() && std::isdigit(static_cast<unsigned char>(message[end]))) ++end;
  if (end == at + 5 || end - at > 15) return message;
  const std::string entity = EntityAtLine(path, std::stol(message.substr(at + 5, end - at - 5)));
  if (entity.empty()) return message;
  return message.substr(0, end) + " (near entity " + entity + ")" + message.substr(end);
}

std::string StepTypeName(const std::string& occt_name) {
  std::string name = occt_name;
  if (std::none_of(name.begin(), name.end(),
                   [](char c) { return std::islower(static_cast<unsigned char>(c)); })) {
    return name;
  }
  if (const size_t at = name.find('_'); at != std::string::npos) name = name.substr(at + 1);
  std::string out;
  for (size_t i = 0; i < name.size(); ++i) {
    const auto c = static_cast<unsigned char>(name[i]);
    if (std::isupper(c) && i > 0) out += '_';
    out += static_cast<char>(std::toupper(c));
  }
  return out;
}

}  // namespace detail

int StepAssembly::triangles() const {
  size_t n = 0;
  for (const StepSolid& s : solids) n += s.mesh.triangles.size();
  return static_cast<int>(n);
}

bool LooksLikeStep(const fs::path& path) {
  const std::string ext = LowerExtension(path);
  if (ext == ".step" || ext == ".stp" || ext == ".p21") return true;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  const std::string head = ReadBytes(path, 0, 64);
  return SkipLeading(head).starts_with(kStepMagic);
}

TriangleMesh MergedInstances(const StepAssembly& assembly) {
  TriangleMesh merged;
  for (const StepInstance& inst : assembly.instances) {
    const TriangleMesh& mesh = assembly.solids[static_cast<size_t>(inst.solid)].mesh;
    const int offset = static_cast<int>(merged.vertices.size());
    for (const Vec3& v : mesh.vertices) merged.vertices.push_back(inst.X_AS * v);
    for (const auto& t : mesh.triangles) {
      merged.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
    }
  }
  return merged;
}

Result<TriangleMesh> FindStepSolid(const StepAssembly& assembly, const std::string& name,
                                   const std::string& file) {
  for (const StepSolid& s : assembly.solids) {
    if (s.name == name) return s.mesh;
  }
  for (const StepInstance& inst : assembly.instances) {
    if (inst.name == name) return assembly.solids[static_cast<size_t>(inst.solid)].mesh;
  }
  std::string names;
  constexpr size_t kShown = 12;
  for (size_t i = 0; i < assembly.solids.size() && i < kShown; ++i) {
    names += (i ? ", " : "") + Quote(assembly.solids[i].name);
  }
  if (assembly.solids.size() > kShown) {
    names += " and " + std::to_string(assembly.solids.size() - kShown) + " more";
  }
  return Fail(ErrorCode::kInvalidInput, "STEP file " + Quote(file) + " has no solid or part " +
                                            Quote(name) + "; its solids are " + names);
}

}  // namespace wrap
