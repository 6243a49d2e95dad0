// The document: undo/redo history, dirty flag, saving (atomic, round trip), recovery file.
#include "gui/document.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "gui/commands.h"
#include "gui_fixture.h"
#include "model/project_io.h"

namespace wrap::gui {
namespace {

using testing::ExampleProject;
using testing::OpenStool;
using testing::ScratchDir;

std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Document, NewIsEmptyCleanAndUntitled) {
  Document doc;
  EXPECT_TRUE(doc.project().parts.empty());
  EXPECT_FALSE(doc.dirty());
  EXPECT_FALSE(doc.CanUndo());
  EXPECT_FALSE(doc.CanRedo());
  EXPECT_TRUE(doc.path().empty());
  EXPECT_EQ(doc.ResolvePath().filename(), "untitled.json");
}

TEST(Document, OpenReadsTheProject) {
  Document doc = OpenStool();
  EXPECT_EQ(doc.project().name, "stool");
  EXPECT_EQ(doc.project().parts.size(), 5u);
  EXPECT_EQ(doc.project().steps.size(), 4u);
  EXPECT_FALSE(doc.dirty());
}

TEST(Document, OpenFailsWithIoForAMissingFileAndInvalidInputForBadJson) {
  auto missing = Document::Open(ScratchDir("open_missing") / "nope.json");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);
  const auto bad = ScratchDir("open_bad") / "bad.json";
  std::ofstream(bad) << "{ this is not json";
  auto broken = Document::Open(bad);
  ASSERT_FALSE(broken);
  EXPECT_EQ(broken.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(broken.error().message.find("bad.json"), std::string::npos);
}

TEST(Document, UndoRedoRestoreExactly) {
  Document doc = OpenStool();
  const Project p0 = doc.project();
  ASSERT_TRUE(doc.Execute(AddStep("extra")));
  const Project p1 = doc.project();
  ASSERT_TRUE(doc.Execute(RenameNode("leg1", "front_leg")));
  const Project p2 = doc.project();
  EXPECT_EQ(doc.UndoLabel(), "rename 'leg1' to 'front_leg'");
  ASSERT_TRUE(doc.Undo());
  EXPECT_EQ(doc.project(), p1);
  EXPECT_EQ(doc.RedoLabel(), "rename 'leg1' to 'front_leg'");
  ASSERT_TRUE(doc.Undo());
  EXPECT_EQ(doc.project(), p0);
  EXPECT_FALSE(doc.Undo());
  ASSERT_TRUE(doc.Redo());
  ASSERT_TRUE(doc.Redo());
  EXPECT_EQ(doc.project(), p2);
  EXPECT_FALSE(doc.Redo());
}

TEST(Document, ANewCommandDropsTheRedoHistory) {
  Document doc = OpenStool();
  ASSERT_TRUE(doc.Execute(AddStep("a")));
  ASSERT_TRUE(doc.Undo());
  ASSERT_TRUE(doc.CanRedo());
  ASSERT_TRUE(doc.Execute(AddStep("b")));
  EXPECT_FALSE(doc.CanRedo());
}

TEST(Document, AFailedCommandChangesNothing) {
  Document doc = OpenStool();
  const Project before = doc.project();
  const unsigned long revision = doc.revision();
  auto r = doc.Execute(AddStep("seat"));  // the name of a part
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(doc.project(), before);
  EXPECT_FALSE(doc.dirty());
  EXPECT_FALSE(doc.CanUndo());
  EXPECT_EQ(doc.revision(), revision);
}

TEST(Document, ACommandThatChangesNothingMakesNoEntry) {
  Document doc = OpenStool();
  Part seat = doc.project().parts[0];
  ASSERT_TRUE(doc.Execute(SetPart("seat", seat)));
  EXPECT_FALSE(doc.CanUndo());
  EXPECT_FALSE(doc.dirty());
}

TEST(Document, DirtyFollowsEditsSavesAndUndo) {
  const auto dir = ScratchDir("dirty");
  Document doc = OpenStool();
  ASSERT_TRUE(doc.SaveAs(dir / "stool.json"));
  EXPECT_FALSE(doc.dirty());
  ASSERT_TRUE(doc.Execute(AddStep("x")));
  EXPECT_TRUE(doc.dirty());
  ASSERT_TRUE(doc.Undo());
  EXPECT_FALSE(doc.dirty()) << "undone back to the saved state";
  ASSERT_TRUE(doc.Redo());
  EXPECT_TRUE(doc.dirty());
  ASSERT_TRUE(doc.Save());
  EXPECT_FALSE(doc.dirty());
  ASSERT_TRUE(doc.Undo());
  EXPECT_TRUE(doc.dirty()) << "undone past the saved state";
  ASSERT_TRUE(doc.Redo());
  EXPECT_FALSE(doc.dirty());
}

TEST(Document, MergedEditsAreOneUndoEntry) {
  Document doc = OpenStool();
  const Project before = doc.project();
  Part seat = doc.project().parts[0];
  for (int i = 1; i <= 5; ++i) {
    seat.color[0] = 0.1 * i;
    ASSERT_TRUE(doc.Execute(SetPart("seat", seat, "part:seat:color")));
  }
  EXPECT_DOUBLE_EQ(doc.project().parts[0].color[0], 0.5);
  ASSERT_TRUE(doc.Undo());
  EXPECT_EQ(doc.project(), before);
  EXPECT_FALSE(doc.CanUndo());
}

TEST(Document, CloseMergeStartsANewEntry) {
  Document doc = OpenStool();
  Part seat = doc.project().parts[0];
  seat.color[0] = 0.1;
  ASSERT_TRUE(doc.Execute(SetPart("seat", seat, "part:seat:color")));
  const Project first = doc.project();
  doc.CloseMerge();
  seat.color[0] = 0.2;
  ASSERT_TRUE(doc.Execute(SetPart("seat", seat, "part:seat:color")));
  ASSERT_TRUE(doc.Undo());
  EXPECT_EQ(doc.project(), first);
}

TEST(Document, SaveIsRefusedWhenUntitled) {
  Document doc;
  auto r = doc.Save();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
}

TEST(Document, RoundTripThroughTheProjectFile) {
  const auto dir = ScratchDir("round_trip");
  Document doc = OpenStool();
  // Edits of every kind, then save, reopen and compare.
  ASSERT_TRUE(doc.Execute(RenameNode("leg4", "last_leg")));
  Part seat = doc.project().parts[0];
  seat.color = {0.25, 0.5, 0.75, 1.0};
  seat.mass_kg = 0.42;
  seat.initial_pose.xyz = Vec3(-0.25, 0.01, 0.75);
  ASSERT_TRUE(doc.Execute(SetPart("seat", seat)));
  Mating m = doc.project().steps[0].mating;
  m.force_N = 17.5;
  m.axis = Vec3(0, 1, 0);
  m.connection_limits = WrenchBox{Vec3(1, 2, 3), Vec3(4, 5, 6)};
  ASSERT_TRUE(doc.Execute(SetMating("seat+leg1", m)));
  ASSERT_TRUE(doc.Execute(AddRobot("ur10e", "vacuum_cup")));
  WrenchLimits limits;
  limits.two_finger.force_N = Vec3(10, 20, 30);
  ASSERT_TRUE(doc.Execute(SetWrenchLimits("ur5e_a", limits)));
  ASSERT_TRUE(doc.SaveAs(dir / "edited.json"));

  auto again = Document::Open(dir / "edited.json");
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_EQ(again->project(), doc.project());
  EXPECT_EQ(again->project().steps.back().inputs[1], "last_leg");
  // The meshes still resolve from the new folder.
  const auto mesh = dir / again->project().parts[0].mesh;
  EXPECT_TRUE(std::filesystem::exists(mesh)) << mesh;
}

TEST(Document, SaveAsRewritesRelativePathsForTheNewFolder) {
  const auto dir = ScratchDir("save_as") / "deeper" / "still";
  std::filesystem::create_directories(dir);
  Document doc = OpenStool();
  ASSERT_TRUE(doc.SaveAs(dir / "s.json"));
  EXPECT_EQ(doc.path(), dir / "s.json");
  EXPECT_FALSE(doc.dirty());
  for (const Part& part : doc.project().parts) {
    EXPECT_TRUE(std::filesystem::exists(dir / part.mesh)) << part.mesh;
  }
}

TEST(Document, SaveAsKeepsTheUndoHistoryNamingTheSameFiles) {
  const auto dir = ScratchDir("save_as_undo") / "elsewhere";
  std::filesystem::create_directories(dir);
  Document doc = OpenStool();
  const Project original = doc.project();
  ASSERT_TRUE(doc.Execute(AddStep("extra")));
  Part seat = doc.project().parts[0];
  seat.mass_kg = 0.5;
  ASSERT_TRUE(doc.Execute(SetPart("seat", seat)));
  ASSERT_TRUE(doc.SaveAs(dir / "moved.json"));
  EXPECT_FALSE(doc.dirty());
  // Both edits can still be undone, and the undone states name the same mesh files from the
  // new folder.
  ASSERT_TRUE(doc.CanUndo());
  EXPECT_NE(doc.UndoLabel().find("seat"), std::string::npos) << doc.UndoLabel();
  ASSERT_TRUE(doc.Undo());
  EXPECT_TRUE(doc.dirty());
  EXPECT_FALSE(doc.project().parts[0].mass_kg.has_value() &&
               *doc.project().parts[0].mass_kg == 0.5);
  ASSERT_TRUE(doc.Undo());
  EXPECT_EQ(doc.project().steps.size(), original.steps.size());
  EXPECT_FALSE(doc.CanUndo());
  for (const Part& part : doc.project().parts) {
    EXPECT_TRUE(std::filesystem::exists(dir / part.mesh)) << part.mesh;
  }
  ASSERT_TRUE(doc.Redo());
  ASSERT_TRUE(doc.Redo());
  EXPECT_FALSE(doc.dirty()) << "redone back to the state saved as";
}

TEST(Document, RevisionsAreUniqueAcrossDocuments) {
  Document a = OpenStool();
  Document b = OpenStool();
  Document c;
  EXPECT_NE(a.revision(), b.revision());
  EXPECT_NE(b.revision(), c.revision());
  const unsigned long before = a.revision();
  ASSERT_TRUE(a.Execute(AddStep("x")));
  EXPECT_NE(a.revision(), before);
  EXPECT_NE(a.revision(), b.revision());
}

TEST(Document, SaveWritesAtomicallyAndLeavesNoTemporaryFile) {
  const auto dir = ScratchDir("atomic");
  Document doc = OpenStool();
  ASSERT_TRUE(doc.SaveAs(dir / "p.json"));
  ASSERT_TRUE(doc.Execute(AddStep("new_step")));
  ASSERT_TRUE(doc.Save());
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1);
  EXPECT_NE(Slurp(dir / "p.json").find("\"new_step\""), std::string::npos);
}

TEST(Document, RecoveryFileHoldsTheUnsavedProject) {
  const auto dir = ScratchDir("recovery");
  Document doc = OpenStool();
  ASSERT_TRUE(doc.SaveAs(dir / "p.json"));
  auto nothing = doc.WriteRecovery();
  ASSERT_TRUE(nothing);
  EXPECT_FALSE(*nothing) << "clean: nothing to recover";
  EXPECT_FALSE(Document::HasRecovery(dir / "p.json"));

  ASSERT_TRUE(doc.Execute(AddStep("unsaved_step")));
  auto wrote = doc.WriteRecovery();
  ASSERT_TRUE(wrote);
  EXPECT_TRUE(*wrote);
  EXPECT_EQ(doc.RecoveryPath(), dir / "p.json.recovery");
  EXPECT_TRUE(Document::HasRecovery(dir / "p.json"));
  // Exactly the project as it stands, in the project format.
  ProjectParse parse = ParseProject(Slurp(doc.RecoveryPath()), "recovery");
  ASSERT_TRUE(parse.project);
  EXPECT_EQ(*parse.project, doc.project());
  auto again = doc.WriteRecovery();
  ASSERT_TRUE(again);
  EXPECT_FALSE(*again) << "unchanged since the last recovery write";

  // A new session on the file (as after a crash) offers it and recovers as one undoable edit.
  auto reopened = Document::Open(dir / "p.json");
  ASSERT_TRUE(reopened);
  EXPECT_EQ(reopened->project().steps.size(), 4u);
  ASSERT_TRUE(reopened->Recover());
  EXPECT_EQ(reopened->project(), doc.project());
  EXPECT_TRUE(reopened->dirty());
  ASSERT_TRUE(reopened->Undo());
  EXPECT_EQ(reopened->project().steps.size(), 4u);

  // Saving removes it.
  ASSERT_TRUE(doc.Save());
  EXPECT_FALSE(std::filesystem::exists(doc.RecoveryPath()));
  EXPECT_FALSE(Document::HasRecovery(dir / "p.json"));
}

TEST(RebasePaths, KeepsVariablesAndAbsolutePaths) {
  Project p;
  Part a, b, c;
  a.mesh = "../meshes/a.stl";
  b.mesh = "${FABRICA}/b.obj";
  c.mesh = "/abs/c.stl";
  p.parts = {a, b, c};
  RebasePaths(p, "/x/projects", "/x/out/deep");
  EXPECT_EQ(p.parts[0].mesh, "../../meshes/a.stl");
  EXPECT_EQ(p.parts[1].mesh, "${FABRICA}/b.obj");
  EXPECT_EQ(p.parts[2].mesh, "/abs/c.stl");
}

}  // namespace
}  // namespace wrap::gui
