// `wrap render` end to end, as a separate process (one GL platform library per process): golden
// images, EGL and OSMesa agreeing, no DISPLAY needed, and clear exit-2 errors on bad input.
//
// Golden images live in tests/golden/render; WRAP_UPDATE_GOLDEN=1 rewrites them (see
// tests/golden/README.md). A mismatch writes actual, expected and diff PNGs under
// WRAP_TEST_OUT_DIR/golden_failures.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "model/validate.h"
#include "render/image.h"
#include "render/render_job.h"
#include "robot/kinematics.h"
#include "sim/scene.h"
#include "task/plan_json.h"

extern char** environ;

namespace wrap::render {
namespace {

namespace fs = std::filesystem;

// Golden tolerance: 99% of channel values within 3 levels.
constexpr int kTolerance = 3;
constexpr double kFractionWithin = 0.99;

struct ProcessRun {
  int code = -1;
  std::string out;
  std::string err;
};

std::string Slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path OutDir(const std::string& name) {
  const fs::path dir = fs::path(WRAP_TEST_OUT_DIR) / name;
  fs::remove_all(dir);
  return dir;
}

// Runs the `wrap` executable with `args`, without DISPLAY or WAYLAND_DISPLAY (as on a CI machine
// with no display) and with `env` applied (nullopt removes a variable).
ProcessRun RunWrap(const std::vector<std::string>& args,
                   const std::map<std::string, std::optional<std::string>>& env = {}) {
  std::map<std::string, std::optional<std::string>> changes = env;
  changes.try_emplace("DISPLAY", std::nullopt);
  changes.try_emplace("WAYLAND_DISPLAY", std::nullopt);
  std::vector<std::string> vars;
  for (char** e = environ; *e; ++e) {
    const std::string var(*e);
    if (!changes.contains(var.substr(0, var.find('=')))) vars.push_back(var);
  }
  for (const auto& [name, value] : changes) {
    if (value) vars.push_back(name + "=" + *value);
  }
  std::vector<char*> envp;
  for (std::string& v : vars) envp.push_back(v.data());
  envp.push_back(nullptr);

  std::vector<std::string> argv_s = {WRAP_EXE};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);

  fs::create_directories(WRAP_TEST_OUT_DIR);
  const std::string tag = std::to_string(::getpid()) + "_" + std::to_string(std::rand());
  const fs::path out_file = fs::path(WRAP_TEST_OUT_DIR) / ("stdout_" + tag);
  const fs::path err_file = fs::path(WRAP_TEST_OUT_DIR) / ("stderr_" + tag);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  posix_spawn_file_actions_addopen(&actions, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  pid_t pid = 0;
  ProcessRun run;
  const int spawned = posix_spawn(&pid, WRAP_EXE, &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    ADD_FAILURE() << "cannot run " << WRAP_EXE;
    return run;
  }
  int status = 0;
  waitpid(pid, &status, 0);
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  run.out = Slurp(out_file);
  run.err = Slurp(err_file);
  fs::remove(out_file);
  fs::remove(err_file);
  return run;
}

std::string Project(const std::string& name) {
  return (fs::path(WRAP_SOURCE_DIR) / "projects" / (name + ".json")).string();
}

// Compares a rendered image with its golden twin (or rewrites the twin when asked to).
void ExpectMatchesGolden(const fs::path& actual_file, const std::string& golden_name) {
  const fs::path golden = fs::path(WRAP_GOLDEN_DIR) / golden_name;
  auto actual = ReadPng(actual_file);
  ASSERT_TRUE(actual.has_value()) << actual.error().message;
  if (const char* update = std::getenv("WRAP_UPDATE_GOLDEN");
      update && std::string(update) == "1") {
    fs::create_directories(golden.parent_path());
    ASSERT_TRUE(WritePng(*actual, golden).has_value());
    GTEST_SKIP() << "rewrote " << golden;
  }
  auto expected = ReadPng(golden);
  ASSERT_TRUE(expected.has_value())
      << expected.error().message << " (create it with WRAP_UPDATE_GOLDEN=1, see "
      << "tests/golden/README.md)";
  const ImageDifference d = CompareImages(*actual, *expected, kTolerance);
  if (d.same_size && d.fraction_within >= kFractionWithin) return;
  const fs::path dir = fs::path(WRAP_TEST_OUT_DIR) / "golden_failures";
  fs::create_directories(dir);
  const std::string stem = fs::path(golden_name).stem().string();
  (void)WritePng(*actual, dir / (stem + "_actual.png"));
  (void)WritePng(*expected, dir / (stem + "_expected.png"));
  if (d.same_size)
    (void)WritePng(DifferenceImage(*actual, *expected, kTolerance), dir / (stem + "_diff.png"));
  ADD_FAILURE() << golden_name << ": " << (d.same_size ? "" : "size differs; ")
                << 100.0 * d.fraction_within << "% of channels within +-" << kTolerance << " (need "
                << 100.0 * kFractionWithin << "%), max difference " << d.max_difference << "; see "
                << dir.string();
}

struct GoldenCase {
  std::string project;
  std::vector<std::string> options;
  std::string image;   // file written by wrap render
  std::string golden;  // name under tests/golden/render
};

void PrintTo(const GoldenCase& c, std::ostream* os) { *os << c.golden; }

class Golden : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(Golden, MatchesWithinTolerance) {
  const GoldenCase& c = GetParam();
  const fs::path dir = OutDir("golden_" + fs::path(c.golden).stem().string());
  std::vector<std::string> args = {"render",     Project(c.project), "-o",
                                   dir.string(), "--size",           "160x120"};
  args.insert(args.end(), c.options.begin(), c.options.end());
  const ProcessRun r = RunWrap(args);
  ASSERT_EQ(r.code, 0) << r.err;
  ExpectMatchesGolden(dir / c.image, "render/" + c.golden);
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, Golden,
    ::testing::Values(GoldenCase{"stool", {}, "initial.png", "stool_initial.png"},
                      GoldenCase{"cross_openarm", {}, "initial.png", "cross_openarm_initial.png"},
                      GoldenCase{"half_stool",
                                 {"--goal", "--explode", "0.5"},
                                 "goal_exploded.png",
                                 "half_stool_goal_exploded.png"}),
    [](const auto& p) { return fs::path(p.param.golden).stem().string(); });

TEST(RenderCli, EglAndOsmesaDrawTheSameImage) {
  std::map<std::string, Image> images;
  for (const std::string backend : {"egl", "osmesa"}) {
    const fs::path dir = OutDir("backend_" + backend);
    const ProcessRun r = RunWrap({"render", Project("stool"), "-o", dir.string(), "--size",
                                  "160x120", "--backend", backend});
    ASSERT_EQ(r.code, 0) << backend << ": " << r.err;
    EXPECT_NE(r.out.find(backend == "egl" ? "EGL" : "OSMesa"), std::string::npos) << r.out;
    auto image = ReadPng(dir / "initial.png");
    ASSERT_TRUE(image.has_value());
    images[backend] = *image;
  }
  const ImageDifference d = CompareImages(images["egl"], images["osmesa"], kTolerance);
  ASSERT_TRUE(d.same_size);
  EXPECT_GE(d.fraction_within, kFractionWithin) << "max difference " << d.max_difference;
}

TEST(RenderCli, WorksWithoutDisplayAndWritesTheSheet) {
  const fs::path dir = OutDir("no_display");
  const ProcessRun r = RunWrap({"render", Project("cross"), "-o", dir.string(), "--size", "200x150",
                                "--explode", "0.4", "--camera", "120,-45"},
                               {{"DISPLAY", std::nullopt}, {"XAUTHORITY", std::nullopt}});
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"initial.png", "goal.png", "goal_exploded.png", "contact_sheet.png"}) {
    EXPECT_TRUE(fs::exists(dir / f)) << f;
    EXPECT_NE(r.out.find(f), std::string::npos) << r.out;
  }
  auto frame = ReadPng(dir / "initial.png");
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->width, 200);
  EXPECT_EQ(frame->height, 150);
  // Three snapshots side by side with a title and captions.
  auto sheet = ReadPng(dir / "contact_sheet.png");
  ASSERT_TRUE(sheet.has_value());
  EXPECT_GT(sheet->width, 3 * 200);
  EXPECT_GT(sheet->height, 150);
  // Not blank: a rendered frame has many colours.
  std::set<int> colours;
  for (size_t i = 0; i + 2 < frame->rgb.size(); i += 3) {
    colours.insert(frame->rgb[i] << 16 | frame->rgb[i + 1] << 8 | frame->rgb[i + 2]);
  }
  EXPECT_GT(colours.size(), 200u);
}

struct BadCase {
  std::string name;
  std::vector<std::string> options;
  std::string phrase;  // expected in the message
};

void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, ExitsTwoWithAClearMessage) {
  const BadCase& c = GetParam();
  const fs::path dir = OutDir("bad_" + c.name);
  std::vector<std::string> args = {"render", Project("stool"), "-o", dir.string()};
  args.insert(args.end(), c.options.begin(), c.options.end());
  const ProcessRun r = RunWrap(args);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(c.phrase), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "initial.png"));
}

INSTANTIATE_TEST_SUITE_P(
    Options, BadInput,
    ::testing::Values(BadCase{"backend", {"--backend", "vulkan"}, "unknown GL backend 'vulkan'"},
                      BadCase{"size_zero", {"--size", "0x480"}, "--size"},
                      BadCase{"size_text", {"--size", "big"}, "WIDTHxHEIGHT"},
                      BadCase{"size_huge", {"--size", "100000x100"}, "between 16 and 8192"},
                      BadCase{"camera", {"--camera", "10"}, "AZIMUTH,ELEVATION"},
                      BadCase{"elevation", {"--camera", "10,120"}, "elevation"},
                      BadCase{"explode", {"--explode", "-1"}, "--explode"},
                      BadCase{"plan_missing", {"--plan", "no_such_plan.json"}, "no_such_plan.json"},
                      BadCase{"plan_and_goal", {"--plan", "p.json", "--goal"}, "--goal"},
                      BadCase{"frames_zero", {"--frames", "0"}, "at least 1 frame"},
                      BadCase{"frames", {"--frames", "5"}, "need --plan"},
                      BadCase{"at", {"--at", "0,1"}, "need --plan"}),
    [](const auto& p) { return p.param.name; });

// A hand-made plan of the stool: the initial keyframe, then ur5e_a picks the seat, which is lifted
// 5 cm while every robot stays at home (no IK: only the drawing is tested).
fs::path WriteStoolPlan(const fs::path& dir) {
  const LoadedProject loaded = LoadProject(Project("stool"));
  EXPECT_TRUE(loaded.ok());
  auto scene = BuildCellScene(*loaded.project, loaded.check, Project("stool"));
  EXPECT_TRUE(scene.has_value());
  const AssemblyTree& tree = *loaded.check.tree;
  Plan plan;
  plan.project = loaded.project->name;
  for (const auto& r : loaded.project->robots) plan.robots.push_back(r.name);
  for (const auto& p : loaded.project->parts) plan.parts.push_back(p.name);
  for (const auto& n : tree.nodes) plan.nodes.push_back(n.name);
  plan.milestone_steps = {tree.step_order.front()};
  plan.stats.planner = "hand-made";
  for (const SceneRobot& r : scene->robots) plan.initial.q.push_back(r.home);
  for (size_t p = 0; p < scene->parts.size(); ++p) {
    const ScenePart& part = scene->parts[p];
    plan.initial.objects.push_back(
        {static_cast<int>(p), part.X_WP_initial * part.X_AP.inverse(), true});
  }
  PlanAction pick;
  pick.type = ActionType::kPick;
  pick.robots = {0};
  pick.objects = {0};
  PlanHold hold;
  hold.robot = 0;
  hold.grasp.subassembly = 0;
  hold.grasp.index = 3;
  hold.grasp.part = 0;
  hold.grasp.width_m = 0.02;
  pick.grasps = {hold};
  pick.milestone = 0;
  pick.keyframe = plan.initial;
  pick.keyframe.objects[0].X_WA.translation().z() += 0.05;
  pick.keyframe.objects[0].resting = false;
  plan.actions.push_back(pick);
  fs::create_directories(dir);
  const fs::path file = dir / "plan.json";
  EXPECT_TRUE(SavePlan(plan, file).has_value());
  return file;
}

// A plan with motion: robot 0 turns its first joint by 0.5 rad in 2 s and picks the seat at
// t = 2 s. MotionState follows the trajectories (the seat rests until the pick, then rides with
// the TCP), and --frames N draws N moments evenly in time.
TEST(RenderCli, MotionFramesFollowTheTrajectories) {
  const fs::path input = WriteStoolPlan(OutDir("motion_input"));
  auto read = ReadPlanFile(input);
  ASSERT_TRUE(read.has_value());
  Plan plan = *read;
  const LoadedProject loaded = LoadProject(Project("stool"));
  ASSERT_TRUE(loaded.ok());
  auto scene = BuildCellScene(*loaded.project, loaded.check, Project("stool"));
  ASSERT_TRUE(scene.has_value());
  const JointVector home = plan.initial.q[0];
  JointVector turned = home;
  turned[0] += 0.5;
  plan.actions[0].keyframe.q[0] = turned;
  plan.actions[0].start_s = 0.0;
  plan.actions[0].end_s = 2.0;
  plan.stats.makespan_s = 2.0;
  for (size_t r = 0; r < plan.robots.size(); ++r) {
    RobotTrajectory tr;
    tr.robot = static_cast<int>(r);
    const JointVector q0 = plan.initial.q[r];
    const JointVector zero = JointVector::Zero(q0.size());
    if (r == 0) {
      // Constant acceleration between knots: 0 -> v at 1 s (mid-way), v -> 0 at 2 s.
      const JointVector v = turned - home;
      tr.knots = {{0.0, home, zero, -1.0},
                  {1.0, JointVector(0.5 * (home + turned)), v, -1.0},
                  {2.0, turned, zero, 0.022}};
    } else {
      tr.knots = {{0.0, q0, zero, -1.0}, {2.0, q0, zero, -1.0}};
    }
    plan.trajectories.push_back(tr);
  }
  const AssemblyTree& tree = *loaded.check.tree;
  auto start = MotionState(*scene, tree, plan, 0.0);
  auto mid = MotionState(*scene, tree, plan, 1.0);
  auto end = MotionState(*scene, tree, plan, 2.0);
  ASSERT_TRUE(start && mid && end);
  EXPECT_NEAR(start->q[0][0], home[0], 1e-12);
  EXPECT_NEAR(mid->q[0][0], home[0] + 0.25, 1e-12);
  EXPECT_NEAR(end->q[0][0], turned[0], 1e-12);
  // Before the pick the seat rests where it started; at the pick it sits at the grasp.
  EXPECT_TRUE(mid->X_WP[0].isApprox(start->X_WP[0], 1e-12));
  const SceneRobot& r0 = scene->robots[0];
  const Iso3 X_WT = TcpPose(r0.chain, r0.X_WB, turned, r0.end_effector.X_FT);
  const PlanGrasp& g = plan.actions[0].grasps[0].grasp;
  const Iso3 expected = X_WT * (scene->parts[0].X_AP * g.X_PG).inverse() * scene->parts[0].X_AP;
  EXPECT_TRUE(end->X_WP[0].isApprox(expected, 1e-9));
  EXPECT_NEAR(end->opening_m[0], 0.022, 1e-12);

  const fs::path file = input.parent_path() / "motion.json";
  ASSERT_TRUE(SavePlan(plan, file).has_value());
  const fs::path frames = OutDir("motion_frames");
  ProcessRun r = RunWrap({"render", Project("stool"), "--plan", file.string(), "-o",
                          frames.string(), "--size", "160x120", "--frames", "3"});
  ASSERT_EQ(r.code, 0) << r.err;
  auto first = ReadPng(frames / "frame_000.png");
  auto last = ReadPng(frames / "frame_002.png");
  ASSERT_TRUE(first.has_value() && last.has_value());
  EXPECT_LT(CompareImages(*first, *last, kTolerance).fraction_within, 1.0);
}

TEST(RenderCli, PlanKeyframesAreDrawn) {
  const fs::path plan = WriteStoolPlan(OutDir("plan_input"));
  const fs::path dir = OutDir("plan");
  ProcessRun r = RunWrap({"render", Project("stool"), "--plan", plan.string(), "-o", dir.string(),
                          "--size", "160x120"});
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"plan_000_initial.png", "plan_001_pick.png", "contact_sheet.png"}) {
    EXPECT_TRUE(fs::exists(dir / f)) << f;
    EXPECT_NE(r.out.find(f), std::string::npos) << r.out;
  }
  EXPECT_FALSE(fs::exists(dir / "initial.png"));
  EXPECT_FALSE(fs::exists(dir / "goal.png"));
  // The seat rises and ur5e_a's fingers close: the two keyframes differ.
  auto before = ReadPng(dir / "plan_000_initial.png");
  auto after = ReadPng(dir / "plan_001_pick.png");
  ASSERT_TRUE(before.has_value() && after.has_value());
  const ImageDifference d = CompareImages(*before, *after, kTolerance);
  ASSERT_TRUE(d.same_size);
  EXPECT_LT(d.fraction_within, 1.0);
  EXPECT_GT(d.max_difference, 20);

  // Keyframe indices as times: --frames N evenly, --at picks keyframes.
  const fs::path frames = OutDir("plan_frames");
  r = RunWrap({"render", Project("stool"), "--plan", plan.string(), "-o", frames.string(), "--size",
               "160x120", "--frames", "3"});
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"frame_000.png", "frame_001.png", "frame_002.png"}) {
    EXPECT_TRUE(fs::exists(frames / f)) << f;
  }
  auto last = ReadPng(frames / "frame_002.png");
  ASSERT_TRUE(last.has_value());
  EXPECT_GE(CompareImages(*last, *after, kTolerance).fraction_within, kFractionWithin);
  const fs::path at = OutDir("plan_at");
  r = RunWrap({"render", Project("stool"), "--plan", plan.string(), "-o", at.string(), "--size",
               "160x120", "--at", "1,0"});
  ASSERT_EQ(r.code, 0) << r.err;
  auto first = ReadPng(at / "frame_000.png");
  ASSERT_TRUE(first.has_value());
  EXPECT_GE(CompareImages(*first, *after, kTolerance).fraction_within, kFractionWithin);
  EXPECT_TRUE(fs::exists(at / "frame_001.png"));
  r = RunWrap({"render", Project("stool"), "--plan", plan.string(), "-o",
               OutDir("plan_at_bad").string(), "--at", "2"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--at"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("keyframe"), std::string::npos) << r.err;
}

TEST(RenderCli, PlanOfAnotherProjectOrMalformedExitsTwo) {
  const fs::path plan = WriteStoolPlan(OutDir("plan_other_input"));
  const fs::path dir = OutDir("plan_other");
  ProcessRun r = RunWrap({"render", Project("cross"), "--plan", plan.string(), "-o", dir.string(),
                          "--size", "160x120"});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(plan.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("parts[0]"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "plan_000_initial.png"));

  // A keyframe with 5 joint values for a UR5e: named by file and field.
  std::ifstream in(plan);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "\"ur5e_b\": [";
  const size_t pos = text.rfind(key);
  ASSERT_NE(pos, std::string::npos);
  const size_t comma = text.find(',', pos + key.size());
  text.erase(pos + key.size(), comma + 1 - (pos + key.size()));
  const fs::path broken = plan.parent_path() / "broken.json";
  std::ofstream(broken) << text;
  r = RunWrap({"render", Project("stool"), "--plan", broken.string(), "-o", dir.string()});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("broken.json: actions[0].keyframe.q.ur5e_b: expected 6 numbers"),
            std::string::npos)
      << r.err;
}

TEST(RenderCli, NoGlExitsTwoNamingWhatWasTried) {
  // glvnd's libEGL with no vendor library: no EGL display of any kind.
  const fs::path dir = OutDir("no_gl");
  const ProcessRun r =
      RunWrap({"render", Project("stool"), "-o", dir.string(), "--size", "160x120"},
              {{"__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/vendor.json"}});
  ASSERT_NE(r.code, 0) << "rendered without an EGL vendor library: this libEGL is not glvnd's, "
                          "so the test cannot hide the driver (Debian's libegl1 is glvnd's; "
                          "scripts/install_deps.sh installs it with libegl-dev)";
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("EGL: no offscreen context"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("surfaceless"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--backend osmesa"), std::string::npos) << r.err;
}

// A stand-in ffmpeg on PATH: records its arguments and the concat list, writes the output file
// (its last argument), and fails when asked to.
fs::path FakeFfmpeg(bool fail) {
  const fs::path dir = fs::path(WRAP_TEST_OUT_DIR) / (fail ? "fake_ffmpeg_fail" : "fake_ffmpeg");
  fs::create_directories(dir);
  const fs::path exe = dir / "ffmpeg";
  std::ofstream(exe) << "#!/bin/sh\n"
                     << "echo \"$@\" > \"" << (dir / "args").string() << "\"\n"
                     << "for a; do last=\"$a\"; case \"$a\" in *.ffconcat) cp \"$a\" \""
                     << (dir / "list").string() << "\";; esac; done\n"
                     << (fail ? "echo 'Unknown encoder libx264' >&2; exit 1\n"
                              : "echo video > \"$last\"\n");
  fs::permissions(exe, fs::perms::owner_all);
  return dir;
}

TEST(RenderCli, VideoGoesThroughFfmpeg) {
  const fs::path bin = FakeFfmpeg(false);
  const fs::path dir = OutDir("video_ok");
  const fs::path video = dir / "cell.mp4";
  const std::string path = bin.string() + ":/usr/bin:/bin";
  ProcessRun r = RunWrap({"render", Project("stool"), "-o", dir.string(), "--size", "160x120",
                          "--video", video.string()},
                         {{"PATH", path}});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(video));
  EXPECT_NE(r.out.find("cell.mp4"), std::string::npos) << r.out;
  const std::string args = Slurp(bin / "args");
  EXPECT_NE(args.find("-f concat"), std::string::npos) << args;
  EXPECT_NE(args.find("libx264"), std::string::npos) << args;
  const std::string list = Slurp(bin / "list");
  EXPECT_NE(list.find("initial.png"), std::string::npos) << list;
  EXPECT_NE(list.find("goal.png"), std::string::npos) << list;

  const fs::path failing = FakeFfmpeg(true);
  r = RunWrap({"render", Project("stool"), "-o", OutDir("video_fail").string(), "--size", "160x120",
               "--video", (dir / "bad.mp4").string()},
              {{"PATH", failing.string() + ":/usr/bin:/bin"}});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("ffmpeg failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Unknown encoder"), std::string::npos) << r.err;
}

TEST(RenderCli, UnwritableOutputFolderExitsTwo) {
  // A folder below a regular file cannot be made, even by root.
  const fs::path file = fs::path(WRAP_TEST_OUT_DIR) / "a_file";
  fs::create_directories(file.parent_path());
  std::ofstream(file) << "x";
  const ProcessRun r = RunWrap({"render", Project("stool"), "-o", (file / "sub").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("output folder"), std::string::npos) << r.err;
}

TEST(RenderCli, MissingProjectAndMissingFfmpegExitTwo) {
  ProcessRun r = RunWrap({"render", "no_such_project.json", "-o", OutDir("missing").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no_such_project.json"), std::string::npos) << r.err;
  // No ffmpeg on an empty PATH: said before anything is drawn.
  const fs::path empty = fs::path(WRAP_TEST_OUT_DIR) / "empty_path";
  fs::create_directories(empty);
  r = RunWrap({"render", Project("stool"), "-o", OutDir("video").string(), "--video",
               (fs::path(WRAP_TEST_OUT_DIR) / "v.mp4").string()},
              {{"PATH", empty.string()}});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("ffmpeg"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace wrap::render
