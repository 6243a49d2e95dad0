// The one file that includes assimp: its errors become Result errors here.
#include "geometry/mesh_import.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <unordered_map>
#include <utility>
#include <vector>

#include "geometry/detail/vertex_welder.h"

namespace wrap {
namespace {

/// What assimp's internal consistency checks throw instead of aborting (see below).
class AssimpAssertion : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace
}  // namespace wrap

// Debian's assimp 5.2 is built with ASSIMP_BUILD_DEBUG: its ~1600 `ai_assert` checks stay on, and
// a failed one calls Assimp::aiAssertViolation, which prints and aborts the process. Corrupt input
// reaches some of them (a damaged 3MF zip does at once). This definition takes the place of the
// library's (the library calls it through the PLT and the executable's definition comes first), so
// a failed check throws instead; assimp's importers catch std::exception and fail the import, and
// ImportMesh catches what escapes them. It is process-wide, and assimp is used in this file only.
namespace Assimp {
__attribute__((visibility("default"))) void aiAssertViolation(const char* failed_expression,
                                                              const char* file, int line) {
  throw wrap::AssimpAssertion(std::string("assimp internal check '") + failed_expression +
                              "' failed (" + file + ":" + std::to_string(line) + ")");
}
}  // namespace Assimp

namespace wrap {

namespace fs = std::filesystem;

namespace {

/// Affine map of an assimp node transform (row-major, translation in the last column).
Eigen::Affine3d ToAffine(const aiMatrix4x4& m) {
  Eigen::Matrix4d M;
  M << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  Eigen::Affine3d X;
  X.matrix() = M;
  X.makeAffine();
  return X;
}

/// Lower-case extension of `path` with its dot, e.g. ".ply".
std::string LowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// Up to `max_bytes` from the start of the file.
std::string ReadHead(const fs::path& path, size_t max_bytes) {
  std::ifstream in(path, std::ios::binary);
  std::string head(max_bytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  return head;
}

uint32_t LittleEndianU32(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  for (size_t k = 4; k-- > 0;) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
  return v;
}

Error Damaged(const std::string& name, const std::string& what) {
  return Error{ErrorCode::kInvalidInput, "mesh file '" + name + "' is damaged: " + what};
}

/// A PLY header must end in an `end_header` line, and no element count may exceed the bytes
/// after the header (each element takes at least one): assimp 5.2 loops for ever without the line
/// (a download cut short in the header) and for minutes on a count of millions in a small file.
std::optional<Error> CheckPlyHeader(const fs::path& path, const std::string& name,
                                    uintmax_t file_size) {
  // A header is a few hundred bytes; 64 KiB leaves room for long comments.
  const std::string header = ReadHead(path, 65536);
  if (!header.starts_with("ply")) return std::nullopt;  // assimp names the bad magic number
  const size_t at = header.find("\nend_header");
  const size_t after = at == std::string::npos ? at : at + 11;
  if (after == std::string::npos || after >= header.size() ||
      (header[after] != '\n' && header[after] != '\r')) {
    return Damaged(name,
                   "no 'end_header' line in the first 64 KiB; expected a complete PLY header (is "
                   "the file truncated?)");
  }
  const uintmax_t body = file_size - std::min<uintmax_t>(file_size, after + 1);
  std::istringstream lines(header.substr(0, at));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string keyword, element;
    uintmax_t count = 0;
    if (words >> keyword >> element >> count && keyword == "element" && count > body) {
      return Damaged(name, "its header declares " + std::to_string(count) + " '" + element +
                               "' elements but only " + std::to_string(body) +
                               " bytes follow the header (is the file truncated?)");
    }
  }
  return std::nullopt;
}

/// The vertex and face counts of an OFF file may not exceed its size: assimp 5.2 allocates what
/// they say before reading (seen: seconds and gigabytes for a count with extra digits).
std::optional<Error> CheckOffCounts(const fs::path& path, const std::string& name,
                                    uintmax_t file_size) {
  std::istringstream in(ReadHead(path, 65536));
  std::string word;
  // The keyword (OFF, COFF, NOFF, ...) may share its line with the counts; comments start with #.
  if (!(in >> word) || !word.ends_with("OFF")) return std::nullopt;
  uintmax_t counts[2] = {0, 0};
  for (uintmax_t& count : counts) {
    while (in >> std::ws && in.peek() == '#') std::getline(in, word);
    if (!(in >> count)) return std::nullopt;  // assimp reports the bad header
  }
  if (counts[0] > file_size || counts[1] > file_size - counts[0]) {
    return Damaged(name, "its header declares " + std::to_string(counts[0]) + " vertices and " +
                             std::to_string(counts[1]) + " faces in a file of " +
                             std::to_string(file_size) + " bytes (is the file truncated?)");
  }
  return std::nullopt;
}

/// The lengths in a GLB header must fit the file: assimp 5.2 allocates whatever the JSON chunk
/// length says (seen: 1.3 GB and 10 s for a one-bit error in a 1.5 kB file).
std::optional<Error> CheckGlbLengths(const fs::path& path, const std::string& name,
                                     uintmax_t file_size) {
  const std::string head = ReadHead(path, 20);
  if (head.size() < 20 || !head.starts_with("glTF")) return std::nullopt;
  const uint32_t total = LittleEndianU32(head, 8);
  const uint32_t chunk = LittleEndianU32(head, 12);
  if (total > file_size || chunk > total - std::min<uint32_t>(total, 20)) {
    return Damaged(name, "its GLB header claims " + std::to_string(total) +
                             " bytes and a first "
                             "chunk of " +
                             std::to_string(chunk) + " bytes, but the file has " +
                             std::to_string(file_size) + " bytes (is it truncated?)");
  }
  return std::nullopt;
}

/// COLLADA text must hold no control characters (XML forbids them) and only digits in its index
/// lists (`<p>`, `<vcount>`, `<v>`, `<h>`): assimp 5.2 loops for ever on a letter in a `<p>`.
std::optional<Error> CheckColladaText(const fs::path& path, const std::string& name,
                                      uintmax_t file_size) {
  const std::string text = ReadHead(path, static_cast<size_t>(file_size));
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') {
      return Damaged(name, "control character " + std::to_string(c) + " at byte " +
                               std::to_string(i) + "; expected XML text");
    }
  }
  for (const std::string tag : {"p", "vcount", "v", "h"}) {
    const std::string open = "<" + tag;
    for (size_t at = text.find(open); at != std::string::npos; at = text.find(open, at + 1)) {
      const size_t next = at + open.size();
      if (next >= text.size() ||
          (text[next] != '>' && !std::isspace(static_cast<unsigned char>(text[next])))) {
        continue;  // a longer tag name such as <polylist>
      }
      const size_t begin = text.find('>', next);
      if (begin == std::string::npos) break;
      if (text[begin - 1] == '/') continue;  // <p/>
      for (size_t i = begin + 1; i < text.size() && text[i] != '<'; ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (!std::isdigit(c) && !std::isspace(c)) {
          return Damaged(name, "character '" + std::string(1, text[i]) + "' at byte " +
                                   std::to_string(i) + " inside a <" + tag +
                                   "> index list; expected digits and spaces");
        }
      }
    }
  }
  return std::nullopt;
}

/// Rejects damaged files on which assimp 5.2 hangs or runs away (found by fuzzing it). Empty
/// when the file may go to assimp.
///
/// Fuzzing (about 9000 files: bit flips, random bytes, cut files and inserted digits in STL, OBJ,
/// PLY, OFF, glTF, GLB, 3MF and DAE) with these checks and the throwing aiAssertViolation found
/// no crash or hang left, but assimp is still not safe against every hostile file; known left:
/// a COLLADA <accessor> whose stride overruns its array reads out of bounds (segfault), and a
/// PLY face list length in the millions takes seconds before failing.
std::optional<Error> RejectKnownHangs(const fs::path& path, const std::string& name,
                                      uintmax_t file_size) {
  const std::string ext = LowerExtension(path);
  const std::string magic = ReadHead(path, 4);
  if (ext == ".ply" || magic.starts_with("ply")) {
    if (auto error = CheckPlyHeader(path, name, file_size)) return error;
  }
  if (ext == ".off") {
    if (auto error = CheckOffCounts(path, name, file_size)) return error;
  }
  if (ext == ".glb" || magic == "glTF") {
    if (auto error = CheckGlbLengths(path, name, file_size)) return error;
  }
  if (ext == ".dae") return CheckColladaText(path, name, file_size);
  return std::nullopt;
}

/// True when some mesh of the scene has a face of three or more corners (read before validation:
/// every pointer is checked).
bool HasPolygons(const aiScene& scene) {
  if (scene.mMeshes == nullptr) return false;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr || mesh->mFaces == nullptr) continue;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      if (mesh->mFaces[f].mNumIndices >= 3) return true;
    }
  }
  return false;
}

/// Copies the triangles of every mesh instance in the node tree into one welded mesh.
Result<TriangleMesh> FlattenScene(const aiScene& scene, const std::string& name,
                                  const MeshImportOptions& options) {
  detail::VertexWelder welder(options.weld_tolerance);
  TriangleMesh mesh;
  // Depth-first over the nodes with their accumulated transforms (no recursion: a deep file
  // cannot overflow the stack).
  std::vector<std::pair<const aiNode*, Eigen::Affine3d>> stack;
  stack.emplace_back(scene.mRootNode, ToAffine(scene.mRootNode->mTransformation));
  std::vector<int> local;  // mesh vertex index -> welded index, -1 until used
  while (!stack.empty()) {
    const auto [node, X] = stack.back();
    stack.pop_back();
    // A mirroring transform turns counter-clockwise triangles clockwise: swap two corners back.
    const bool mirrored = X.linear().determinant() < 0.0;
    for (unsigned m = 0; m < node->mNumMeshes; ++m) {
      if (node->mMeshes[m] >= scene.mNumMeshes) continue;
      const aiMesh& am = *scene.mMeshes[node->mMeshes[m]];
      if ((am.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0 || am.mVertices == nullptr) {
        continue;
      }
      local.assign(am.mNumVertices, -1);
      for (unsigned f = 0; f < am.mNumFaces; ++f) {
        const aiFace& face = am.mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines
        Eigen::Vector3i tri;
        bool valid = true;
        for (int k = 0; k < 3; ++k) {
          const unsigned vi = face.mIndices[k];
          if (vi >= am.mNumVertices) {
            valid = false;
            break;
          }
          if (local[vi] < 0) {
            const aiVector3D& v = am.mVertices[vi];
            const Vec3 p = options.scale * (X * Vec3(v.x, v.y, v.z));
            if (!p.allFinite()) {
              return Fail(ErrorCode::kInvalidInput,
                          "mesh file '" + name + "' has a vertex with a non-finite coordinate (" +
                              std::to_string(v.x) + ", " + std::to_string(v.y) + ", " +
                              std::to_string(v.z) + "); expected finite numbers");
            }
            local[vi] = welder.Add(p);
          }
          tri[k] = local[vi];
        }
        if (!valid) continue;
        if (mirrored) std::swap(tri[1], tri[2]);
        // Corners welded together leave a triangle with no area and no edges: drop it.
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;
        mesh.triangles.push_back(tri);
      }
    }
    // Children pushed in reverse so they are visited in file order.
    for (unsigned c = node->mNumChildren; c-- > 0;) {
      if (node->mChildren[c] != nullptr) {
        stack.emplace_back(node->mChildren[c], X * ToAffine(node->mChildren[c]->mTransformation));
      }
    }
  }
  if (mesh.triangles.empty()) {
    return Fail(ErrorCode::kInvalidInput,
                "'" + name + "' contains no triangles (" + std::to_string(scene.mNumMeshes) +
                    " meshes of points, lines or collapsed faces); expected a surface mesh");
  }
  mesh.vertices = std::move(welder.vertices());
  return mesh;
}

}  // namespace

Result<TriangleMesh> ImportMesh(const fs::path& path, const MeshImportOptions& options) {
  const std::string name = path.string();
  if (!std::isfinite(options.scale) || options.scale <= 0.0) {
    return Fail(ErrorCode::kInvalidInput, "mesh import '" + name + "': scale " +
                                              std::to_string(options.scale) +
                                              " is not a positive finite number");
  }
  if (!std::isfinite(options.weld_tolerance) || options.weld_tolerance < 0.0) {
    return Fail(ErrorCode::kInvalidInput, "mesh import '" + name + "': weld tolerance " +
                                              std::to_string(options.weld_tolerance) +
                                              " m is not a finite number >= 0");
  }

  // File-system problems are ours to report: assimp would only say "unable to open".
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) {
    if (ec && ec != std::errc::no_such_file_or_directory) {
      return Fail(ErrorCode::kIo, "mesh file '" + name + "' cannot be accessed: " + ec.message());
    }
    return Fail(ErrorCode::kIo, "mesh file '" + name + "' not found");
  }
  if (fs::is_directory(status)) {
    return Fail(ErrorCode::kIo, "mesh file '" + name + "' is a directory, not a file");
  }
  if (!fs::is_regular_file(status)) {
    return Fail(ErrorCode::kIo, "mesh file '" + name + "' is not a regular file");
  }
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) {
    return Fail(ErrorCode::kIo, "mesh file '" + name + "' cannot be read: " + ec.message());
  }
  if (!std::ifstream(path, std::ios::binary)) {
    return Fail(ErrorCode::kIo,
                "mesh file '" + name + "' cannot be opened: " + std::strerror(errno));
  }
  if (size == 0) {
    return Fail(ErrorCode::kInvalidInput, "mesh file '" + name +
                                              "' is empty (0 bytes); expected a mesh such as "
                                              "STL, OBJ, PLY, glTF, OFF, 3MF or DAE");
  }

  if (const std::optional<Error> damaged = RejectKnownHangs(path, name, size)) {
    return std::unexpected(*damaged);
  }

  // No DefaultLogger is created, so assimp's messages go to its silent NullLogger.
  Assimp::Importer importer;
  // Keep coordinates as written: a Z-up COLLADA file stays Z-up (assimp would rotate it to Y-up).
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene = nullptr;
  try {
    // Read without post-processing first, so that a file with no faces at all (a point cloud, a
    // text file named .obj) is reported as such rather than as a failed validation.
    scene = importer.ReadFile(name, 0);
    if (scene != nullptr && !HasPolygons(*scene)) {
      return Fail(ErrorCode::kInvalidInput,
                  "'" + name + "' contains no triangles (" + std::to_string(scene->mNumMeshes) +
                      " meshes, none with faces); expected a surface mesh");
    }
    // Validation runs first and rejects inconsistent data before the other steps touch it. No
    // aiProcess_JoinIdenticalVertices: in assimp 5.2 it also merges some distinct vertices a few
    // um apart (seen: 1.2 um in a 54 mm part); our welder below is exact or uses the tolerance.
    constexpr unsigned kSteps =
        aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_SortByPType;
    if (scene != nullptr) scene = importer.ApplyPostProcessing(kSteps);
  } catch (const std::exception& e) {
    // The importers catch their own errors; this is for what escapes them: a failed internal
    // check in a post-processing step, an allocation failure on a hostile file.
    return Fail(ErrorCode::kInvalidInput,
                "cannot read mesh file '" + name + "': " + e.what() + "; expected a mesh file");
  }
  if (scene == nullptr || scene->mRootNode == nullptr) {
    return Fail(ErrorCode::kInvalidInput, "cannot read mesh file '" + name +
                                              "': " + importer.GetErrorString() +
                                              "; expected a mesh file assimp 5.2 can read");
  }
  return FlattenScene(*scene, name, options);
}

}  // namespace wrap
