#include "sim/mujoco_model.h"

#include <cstring>
#include <mutex>
#include <stdexcept>

namespace wrap {

namespace {

// Thrown by the error handler inside MuJoCo and caught by RunGuarded. MuJoCo is C, but x86-64
// and aarch64 unwind through C frames (their ABIs keep unwind tables), so the throw reaches us;
// MuJoCo may leak the allocation it was making, which is the price of not exiting.
struct MujocoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

thread_local std::vector<std::string> t_warnings;

void OnError(const char* message) { throw MujocoError(message ? message : "unknown error"); }

void OnWarning(const char* message) {
  // Keep the last few only: a warning in a per-frame loop must not grow without bound.
  if (t_warnings.size() < 64) t_warnings.emplace_back(message ? message : "");
}

struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};

// Adds an in-memory file to the VFS (mj_makeEmptyFileVFS + copy).
Result<void> AddFile(mjVFS* vfs, const std::string& name, const std::string& bytes) {
  if (name.size() >= mjMAXVFSNAME) {
    return Fail(ErrorCode::kInternal, "MuJoCo VFS: file name too long: " + name);
  }
  const int status = mj_makeEmptyFileVFS(vfs, name.c_str(), static_cast<int>(bytes.size()));
  if (status == 1) {
    return Fail(ErrorCode::kInvalidInput, "MuJoCo VFS: more than " + std::to_string(mjMAXVFS) +
                                              " files (too many distinct meshes in the cell)");
  }
  if (status == 2) return Fail(ErrorCode::kInternal, "MuJoCo VFS: repeated file name " + name);
  const int index = mj_findFileVFS(vfs, name.c_str());
  if (index < 0) return Fail(ErrorCode::kInternal, "MuJoCo VFS: file vanished: " + name);
  if (!bytes.empty()) std::memcpy(vfs->filedata[index], bytes.data(), bytes.size());
  return {};
}

Result<int> FindId(const mjModel* m, int type, const std::string& name, const char* what) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0)
    return Fail(ErrorCode::kInternal, std::string("MuJoCo model: no ") + what + " '" + name + "'");
  return id;
}

}  // namespace

void InstallMujocoHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = &OnError;
    mju_user_warning = &OnWarning;
  });
}

Result<void> RunGuarded(std::string_view what, const std::function<void()>& body) {
  InstallMujocoHandlers();
  try {
    body();
  } catch (const MujocoError& e) {
    return Fail(ErrorCode::kInternal, "MuJoCo: " + std::string(what) + ": " + e.what());
  }
  return {};
}

std::vector<std::string> TakeMujocoWarnings() {
  std::vector<std::string> out;
  out.swap(t_warnings);
  return out;
}

Result<CellModel> CellModel::Compile(const MjcfDocument& doc) {
  InstallMujocoHandlers();
  // mjVFS is about 2 MB: never on the stack.
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  static const std::string kModelFile = "cell.xml";
  if (auto ok = AddFile(vfs.get(), kModelFile, doc.xml); !ok) return std::unexpected(ok.error());
  for (const MjcfAsset& a : doc.assets) {
    if (auto ok = AddFile(vfs.get(), a.name, a.bytes); !ok) return std::unexpected(ok.error());
  }
  char error[1024] = "";
  mjModel* raw = nullptr;
  auto guarded = RunGuarded("compiling the cell", [&] {
    raw = mj_loadXML(kModelFile.c_str(), vfs.get(), error, sizeof error);
  });
  if (!guarded) return std::unexpected(guarded.error());
  if (!raw) {
    std::string message = error;
    for (char& c : message) {
      if (c == '\n') c = ' ';
    }
    return Fail(ErrorCode::kInvalidInput, "MuJoCo could not compile the cell: " + message);
  }

  CellModel cell;
  cell.model_.reset(raw);
  const mjModel* m = raw;
  for (const std::vector<std::string>& joints : doc.robot_joints) {
    std::vector<int> adr;
    for (const std::string& j : joints) {
      auto id = FindId(m, mjOBJ_JOINT, j, "joint");
      if (!id) return std::unexpected(id.error());
      adr.push_back(m->jnt_qposadr[*id]);
    }
    cell.robot_qpos_.push_back(std::move(adr));
  }
  for (const auto& fingers : doc.finger_joints) {
    std::array<int, 2> adr = {-1, -1};
    for (int k = 0; k < 2; ++k) {
      if (fingers[k].empty()) continue;
      auto id = FindId(m, mjOBJ_JOINT, fingers[k], "joint");
      if (!id) return std::unexpected(id.error());
      adr[k] = m->jnt_qposadr[*id];
    }
    cell.finger_qpos_.push_back(adr);
  }
  for (const std::string& body : doc.part_bodies) {
    auto id = FindId(m, mjOBJ_BODY, body, "body");
    if (!id) return std::unexpected(id.error());
    const int mocap = m->body_mocapid[*id];
    // A physics model's parts are free bodies: their first joint is the free joint.
    const int joint = m->body_jntadr[*id];
    const bool free =
        mocap < 0 && m->body_jntnum[*id] == 1 && joint >= 0 && m->jnt_type[joint] == mjJNT_FREE;
    if (mocap < 0 && !free) {
      return Fail(ErrorCode::kInternal,
                  "MuJoCo model: body '" + body + "' is neither mocap nor free");
    }
    cell.part_mocap_.push_back(mocap);
    cell.part_qpos_.push_back(free ? m->jnt_qposadr[joint] : -1);
  }
  return cell;
}

std::unique_ptr<mjData, void (*)(mjData*)> CellModel::MakeData() const {
  mjData* data = nullptr;
  (void)RunGuarded("allocating data", [&] { data = mj_makeData(model_.get()); });
  return {data, [](mjData* d) {
            if (d) mj_deleteData(d);
          }};
}

Result<void> CellModel::Apply(const SceneState& state, mjData* data) const {
  if (!data) return Fail(ErrorCode::kInternal, "MuJoCo: no data");
  if (state.q.size() != robot_qpos_.size() || state.opening_m.size() != robot_qpos_.size() ||
      state.X_WP.size() != part_mocap_.size()) {
    return Fail(ErrorCode::kInvalidInput, "scene state has " + std::to_string(state.q.size()) +
                                              " robots and " + std::to_string(state.X_WP.size()) +
                                              " parts; the model " +
                                              std::to_string(robot_qpos_.size()) + " and " +
                                              std::to_string(part_mocap_.size()));
  }
  for (size_t r = 0; r < robot_qpos_.size(); ++r) {
    if (state.q[r].size() != static_cast<long>(robot_qpos_[r].size())) {
      return Fail(ErrorCode::kInvalidInput, "scene state: robot " + std::to_string(r) + " has " +
                                                std::to_string(state.q[r].size()) +
                                                " joint values, the model " +
                                                std::to_string(robot_qpos_[r].size()));
    }
    for (size_t j = 0; j < robot_qpos_[r].size(); ++j)
      data->qpos[robot_qpos_[r][j]] = state.q[r][j];
    for (int adr : finger_qpos_[r]) {
      if (adr >= 0) data->qpos[adr] = 0.5 * std::max(0.0, state.opening_m[r]);
    }
  }
  for (size_t p = 0; p < part_mocap_.size(); ++p) {
    const Iso3& X = state.X_WP[p];
    const int i = part_mocap_[p];
    Eigen::Quaterniond q(X.linear());
    q.normalize();
    if (i < 0) {
      mjtNum* qpos = data->qpos + part_qpos_[p];
      for (int k = 0; k < 3; ++k) qpos[k] = X.translation()[k];
      qpos[3] = q.w();
      qpos[4] = q.x();
      qpos[5] = q.y();
      qpos[6] = q.z();
      continue;
    }
    for (int k = 0; k < 3; ++k) data->mocap_pos[3 * i + k] = X.translation()[k];
    data->mocap_quat[4 * i + 0] = q.w();
    data->mocap_quat[4 * i + 1] = q.x();
    data->mocap_quat[4 * i + 2] = q.y();
    data->mocap_quat[4 * i + 3] = q.z();
  }
  return RunGuarded("computing positions", [&] {
    mj_kinematics(model_.get(), data);
    mj_comPos(model_.get(), data);
    mj_camlight(model_.get(), data);
  });
}

}  // namespace wrap
