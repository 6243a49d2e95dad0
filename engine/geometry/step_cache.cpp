#include "geometry/step_cache.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <string_view>
#include <utility>

#include "core/file_io.h"
#include "geometry/detail/step_common.h"
#include "geometry/detail/step_serial.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

constexpr size_t kMemoryEntries = 8;

/// The cache key: the file's digest and size, the tessellation and the format version.
std::string KeyOf(const detail::Digest& file, size_t size, const StepTessellation& t) {
  std::string params(reinterpret_cast<const char*>(&t.linear_deflection_m), sizeof(double));
  params.append(reinterpret_cast<const char*>(&t.angular_deflection_rad), sizeof(double));
  params += std::to_string(detail::kStepFormatVersion) + "/" + std::to_string(size);
  return detail::Hex16(file.a) + detail::Hex16(file.b) + "-" +
         detail::Hex16(detail::HashBytes(params).a);
}

// ---- This process's cache ---------------------------------------------------------------------

struct MemoryCache {
  std::mutex mutex;
  std::deque<std::pair<std::string, std::shared_ptr<const StepAssembly>>> entries;  // newest last

  std::shared_ptr<const StepAssembly> Find(const std::string& key) {
    std::lock_guard lock(mutex);
    for (const auto& [k, a] : entries) {
      if (k == key) return a;
    }
    return nullptr;
  }
  void Add(const std::string& key, std::shared_ptr<const StepAssembly> a) {
    std::lock_guard lock(mutex);
    entries.emplace_back(key, std::move(a));
    while (entries.size() > kMemoryEntries) entries.pop_front();
  }
};

MemoryCache& Memory() {
  static MemoryCache cache;
  return cache;
}

}  // namespace

fs::path StepCacheDirFor(const fs::path& project_file) {
  const fs::path dir = project_file.has_parent_path() ? project_file.parent_path() : fs::path(".");
  return dir / ".wrap-cache" / "step";
}

void ClearStepMemoryCache() {
  std::lock_guard lock(Memory().mutex);
  Memory().entries.clear();
}

Result<StepLoad> LoadStep(const fs::path& path, const StepLoadOptions& options) {
  // The file's checks first, so that a missing or foreign file is reported as ImportStep does.
  if (auto ok = detail::CheckStepFile(path); !ok) return std::unexpected(ok.error());
  auto bytes = ReadFile(path);
  if (!bytes) return std::unexpected(bytes.error());
  const std::string key = KeyOf(detail::HashBytes(*bytes), bytes->size(), options.tessellation);
  StepLoad load;
  if (!options.cache_dir.empty()) load.cache_file = options.cache_dir / (key + ".wrapstep");
  if ((load.assembly = Memory().Find(key))) {
    load.source = StepSource::kMemory;
    return load;
  }
  if (!load.cache_file.empty()) {
    std::error_code ec;
    if (fs::is_regular_file(load.cache_file, ec)) {
      if (auto cached = ReadFile(load.cache_file)) {
        if (auto a = detail::DeserializeStepAssembly(*cached, key)) {
          load.assembly = std::make_shared<const StepAssembly>(std::move(*a));
          load.source = StepSource::kDiskCache;
          Memory().Add(key, load.assembly);
          return load;
        }
      }
    }
  }
  auto imported = ImportStep(path, options.tessellation);
  if (!imported) return std::unexpected(imported.error());
  load.assembly = std::make_shared<const StepAssembly>(std::move(*imported));
  load.source = StepSource::kImported;
  Memory().Add(key, load.assembly);
  if (!load.cache_file.empty()) {
    std::error_code ec;
    fs::create_directories(options.cache_dir, ec);
    if (ec) {
      load.cache_problem = "cannot create '" + options.cache_dir.string() + "': " + ec.message();
    } else if (auto ok = WriteFileAtomic(load.cache_file,
                                         detail::SerializeStepAssembly(*load.assembly, key));
               !ok) {
      load.cache_problem = ok.error().message;
    }
  }
  return load;
}

}  // namespace wrap
