// The one file that includes OpenCASCADE: STEP reading (XCAF product structure, BRepMesh
// tessellation) and writing (constructive solids for tests and generated examples). Its
// exceptions and messages become Result errors here.
#include "geometry/step_import.h"

#include <APIHeaderSection_MakeHeader.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <Poly_Triangulation.hxx>
#include <Quantity_ColorRGBA.hxx>
#include <STEPCAFControl_Controller.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <StepData_StepModel.hxx>
#include <StepRepr_NextAssemblyUsageOccurrence.hxx>
#include <StepRepr_RepresentationContext.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TDF_Label.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDF_Tool.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_TShape.hxx>
#include <TransferBRep.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>
#include <gp_Ax2.hxx>
#include <gp_Trsf.hxx>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <map>
#include <mutex>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "geometry/detail/step_common.h"
#include "geometry/detail/step_isolation.h"
#include "geometry/detail/vertex_welder.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

using Rgba4 = std::array<double, 4>;

// OpenCASCADE works in millimetres here (its tolerances are tuned for them); Wrap in metres.
constexpr double kMetresPerMm = 0.001;
// Hostile files: bounds on the assembly's depth and size.
constexpr int kMaxDepth = 64;
constexpr size_t kMaxInstances = 100000;

/// Collects OpenCASCADE's messages (instead of printing them) while a read or write runs.
class MessageCollector : public Message_Printer {
 public:
  void Clear() { messages_.clear(); }
  const std::vector<std::string>& messages() const { return messages_; }

 protected:
  void send(const TCollection_AsciiString& text, const Message_Gravity gravity) const override {
    if (gravity < Message_Alarm || messages_.size() >= 20) return;
    // "**** ERR StepFile : Undefined Parsing: Line 5: ...    ****" -> "Line 5: ..."
    std::string s = text.ToCString();
    for (const std::string noise : {"****", "ERR StepFile :", "Undefined Parsing:"}) {
      for (size_t at = s.find(noise); at != std::string::npos; at = s.find(noise)) {
        s.erase(at, noise.size());
      }
    }
    const size_t b = s.find_first_not_of(" \t\r\n");
    const size_t e = s.find_last_not_of(" \t\r\n");
    if (b != std::string::npos) messages_.push_back(s.substr(b, e - b + 1));
  }

 private:
  mutable std::vector<std::string> messages_;
};

/// OpenCASCADE's static parameters and messenger are process-wide: one user at a time.
std::mutex& OcctMutex() {
  static std::mutex mutex;
  return mutex;
}

MessageCollector& Collector() {
  static const Handle(MessageCollector) collector = [] {
    STEPCAFControl_Controller::Init();
    Handle(MessageCollector) c = new MessageCollector();
    const Handle(Message_Messenger)& messenger = Message::DefaultMessenger();
    messenger->ChangePrinters().Clear();
    messenger->AddPrinter(c);
    return c;
  }();
  return *collector;
}

/// Whether OcctSession takes OcctMutex: not in an import's child process, which inherits it
/// locked (detail::ImportInChild) and is its only thread.
enum class Locking { kLock, kInheritedLock };

/// OpenCASCADE for one read or write: the lock, a clean message list and an XCAF document that
/// is closed again at the end.
class OcctSession {
 public:
  explicit OcctSession(Locking locking = Locking::kLock) {
    if (locking == Locking::kLock) lock_ = std::unique_lock(OcctMutex());
    Collector().Clear();
    app_ = XCAFApp_Application::GetApplication();
    app_->NewDocument("MDTV-XCAF", doc_);
  }
  ~OcctSession() {
    if (!doc_.IsNull() && doc_->IsOpened()) app_->Close(doc_);
  }
  OcctSession(const OcctSession&) = delete;
  OcctSession& operator=(const OcctSession&) = delete;

  Handle(TDocStd_Document) & doc() { return doc_; }
  Handle(XCAFDoc_ShapeTool) shapes() const { return XCAFDoc_DocumentTool::ShapeTool(doc_->Main()); }
  Handle(XCAFDoc_ColorTool) colors() const { return XCAFDoc_DocumentTool::ColorTool(doc_->Main()); }

  /// The collected messages, "; "-joined, or `fallback` when there are none.
  static std::string Messages(const std::string& fallback) {
    std::string out;
    for (const std::string& m : Collector().messages()) out += (out.empty() ? "" : "; ") + m;
    return out.empty() ? fallback : out;
  }

 private:
  std::unique_lock<std::mutex> lock_;
  Handle(XCAFApp_Application) app_;
  Handle(TDocStd_Document) doc_;
};

std::string Quote(const std::string& s) { return "'" + s + "'"; }

std::string LabelName(const TDF_Label& label) {
  Handle(TDataStd_Name) name;
  if (label.IsNull() || !label.FindAttribute(TDataStd_Name::GetID(), name)) return "";
  return TCollection_AsciiString(name->Get()).ToCString();  // UTF-8
}

std::string LabelKey(const TDF_Label& label) {
  TCollection_AsciiString entry;
  TDF_Tool::Entry(label, entry);
  return entry.ToCString();
}

/// An instance name worth keeping: not empty, not XCAF's "=>[0:1:1:2]" nor a bare "NAUO12".
bool MeaningfulInstanceName(const std::string& name) {
  if (name.empty() || name.starts_with("=>")) return false;
  if (name.starts_with("NAUO") && name.find_first_not_of("0123456789", 4) == std::string::npos) {
    return false;
  }
  return true;
}

std::optional<Rgba4> ToRgba(const Quantity_ColorRGBA& c) {
  // The file's COLOUR_RGB values are display (sRGB) values; OpenCASCADE holds linear RGB.
  double r = 0, g = 0, b = 0;
  c.GetRGB().Values(r, g, b, Quantity_TOC_sRGB);
  Rgba4 rgba = {r, g, b, static_cast<double>(c.Alpha())};
  for (double& v : rgba) {
    if (!std::isfinite(v)) return std::nullopt;
    v = std::clamp(v, 0.0, 1.0);  // the sRGB conversion's rounding may leave 1 + 1e-16
  }
  return rgba;
}

std::optional<Rgba4> LabelColor(const Handle(XCAFDoc_ColorTool) & colors, const TDF_Label& label) {
  Quantity_ColorRGBA c;
  if (label.IsNull()) return std::nullopt;
  if (colors->GetColor(label, XCAFDoc_ColorSurf, c) ||
      colors->GetColor(label, XCAFDoc_ColorGen, c)) {
    return ToRgba(c);
  }
  return std::nullopt;
}

/// The colour of a solid: its own, else the one most of its faces have.
std::optional<Rgba4> SolidColor(const Handle(XCAFDoc_ColorTool) & colors,
                                const TopoDS_Shape& solid) {
  Quantity_ColorRGBA c;
  if (colors->GetColor(solid, XCAFDoc_ColorSurf, c) ||
      colors->GetColor(solid, XCAFDoc_ColorGen, c)) {
    return ToRgba(c);
  }
  std::map<Rgba4, int> votes;
  for (TopExp_Explorer f(solid, TopAbs_FACE); f.More(); f.Next()) {
    if (colors->GetColor(f.Current(), XCAFDoc_ColorSurf, c) ||
        colors->GetColor(f.Current(), XCAFDoc_ColorGen, c)) {
      if (const auto rgba = ToRgba(c)) ++votes[*rgba];
    }
  }
  std::optional<Rgba4> best;
  int most = 0;
  for (const auto& [rgba, n] : votes) {
    if (n > most) best = rgba, most = n;
  }
  return best;
}

/// Rotation and translation [m] of a rigid OpenCASCADE transform in millimetres.
Iso3 ToIso3(const gp_Trsf& t) {
  Iso3 X = Iso3::Identity();
  const gp_Mat m = t.VectorialPart();  // includes the scale factor (1 for a rigid transform)
  Mat3 R;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) R(i, j) = m.Value(i + 1, j + 1);
  }
  X.linear() = R;
  const gp_XYZ p = t.TranslationPart();
  X.translation() = kMetresPerMm * Vec3(p.X(), p.Y(), p.Z());
  return X;
}

/// Reading: the state of one ImportStep call.
class StepReader {
 public:
  StepReader(std::string file, const StepTessellation& tessellation, OcctSession& session,
             STEPCAFControl_Reader& reader)
      : file_(std::move(file)), tess_(tessellation), session_(session), reader_(reader) {}

  Result<StepAssembly> Run() {
    shapes_ = session_.shapes();
    colors_ = session_.colors();
    TDF_LabelSequence roots;
    shapes_->GetFreeShapes(roots);
    for (int i = 1; i <= roots.Length(); ++i) {
      if (auto ok = Visit(roots.Value(i), TDF_Label(), gp_Trsf(), std::nullopt, 0); !ok) {
        return std::unexpected(ok.error());
      }
    }
    if (out_.instances.empty()) {
      std::string why = "contains no solid";
      if (!out_.warnings.empty()) why += " (" + out_.warnings.front() + ")";
      return Fail(ErrorCode::kInvalidInput,
                  "STEP file " + Quote(file_) + " " + why +
                      "; expected at least one closed solid (MANIFOLD_SOLID_BREP or a closed "
                      "shell)");
    }
    return std::move(out_);
  }

  StepAssembly& out() { return out_; }

 private:
  /// A node of the product structure: an assembly (recurse) or a leaf product (its solids
  /// become instances). `X` is the node's frame in the root frame (mm); `inherited` the nearest
  /// colour an enclosing instance gives.
  Result<void> Visit(const TDF_Label& label, const TDF_Label& instance, const gp_Trsf& X,
                     std::optional<Rgba4> inherited, int depth) {
    if (depth > kMaxDepth) {
      return Fail(ErrorCode::kInvalidInput,
                  "STEP file " + Quote(file_) + ": the assembly structure is nested deeper than " +
                      std::to_string(kMaxDepth) + " levels at " + Quote(LabelName(label)));
    }
    if (const auto own = LabelColor(colors_, instance)) inherited = own;
    if (XCAFDoc_ShapeTool::IsAssembly(label)) {
      TDF_LabelSequence components;
      XCAFDoc_ShapeTool::GetComponents(label, components);
      for (int i = 1; i <= components.Length(); ++i) {
        const TDF_Label& component = components.Value(i);
        TDF_Label referred;
        if (!XCAFDoc_ShapeTool::GetReferredShape(component, referred)) continue;
        const gp_Trsf Xc = X * XCAFDoc_ShapeTool::GetLocation(component).Transformation();
        if (auto ok = Visit(referred, component, Xc, inherited, depth + 1); !ok) return ok;
      }
      return {};
    }
    const auto solids = SolidsOf(label);
    if (!solids) return std::unexpected(solids.error());
    for (const int s : *solids) {
      if (out_.instances.size() >= kMaxInstances) {
        return Fail(ErrorCode::kInvalidInput, "STEP file " + Quote(file_) + " has more than " +
                                                  std::to_string(kMaxInstances) + " parts");
      }
      StepInstance inst;
      const std::string instance_name = LabelName(instance);
      inst.name = MeaningfulInstanceName(instance_name) && solids->size() == 1
                      ? instance_name
                      : out_.solids[static_cast<size_t>(s)].name;
      inst.solid = s;
      inst.color = inherited ? inherited : solid_colors_[static_cast<size_t>(s)];
      if (auto placed = Place(inst, X); !placed) return std::unexpected(placed.error());
      out_.instances.push_back(std::move(inst));
    }
    return {};
  }

  /// Sets the instance's pose from `X` (mm). A transform that scales or mirrors cannot be a
  /// pose: its linear part is baked into a copy of the solid's mesh for this instance.
  Result<void> Place(StepInstance& inst, const gp_Trsf& X) {
    const double scale = X.ScaleFactor();
    if (!std::isfinite(scale) || std::abs(scale) < 1e-9) {
      return Fail(ErrorCode::kInvalidInput,
                  "STEP file " + Quote(file_) + ": instance " + Quote(inst.name) +
                      " has a singular placement (scale " + std::to_string(scale) + ")");
    }
    if (std::abs(scale - 1.0) < 1e-9 && !X.IsNegative()) {
      inst.X_AS = ToIso3(X);
      return {};
    }
    gp_Trsf rotation = X;
    rotation.SetTranslationPart(gp_Vec(0, 0, 0));
    const Iso3 L = ToIso3(rotation);  // linear part with scale and mirror (translation zero)
    const StepSolid& shared = out_.solids[static_cast<size_t>(inst.solid)];
    StepSolid own = shared;
    own.name = UniqueSolidName(shared.name + "@" + inst.name);
    own.mesh = Transformed(shared.mesh, L);
    if (L.linear().determinant() < 0.0) {
      for (auto& t : own.mesh.triangles) std::swap(t[1], t[2]);
    }
    const std::optional<Rgba4> color = solid_colors_[static_cast<size_t>(inst.solid)];
    solid_colors_.push_back(color);
    out_.solids.push_back(std::move(own));
    inst.solid = static_cast<int>(out_.solids.size()) - 1;
    inst.X_AS = Iso3::Identity();
    const gp_XYZ p = X.TranslationPart();
    inst.X_AS.translation() = kMetresPerMm * Vec3(p.X(), p.Y(), p.Z());
    return {};
  }

  /// The solids of a leaf product, tessellated once however many instances it has.
  Result<std::vector<int>> SolidsOf(const TDF_Label& product) {
    const std::string key = LabelKey(product);
    if (const auto it = product_solids_.find(key); it != product_solids_.end()) return it->second;
    std::vector<int>& indices = product_solids_[key];
    const TopoDS_Shape shape = XCAFDoc_ShapeTool::GetShape(product);
    std::string product_name = LabelName(product);
    if (product_name.empty()) product_name = "solid";
    std::vector<TopoDS_Shape> bodies;
    for (TopExp_Explorer e(shape, TopAbs_SOLID); e.More(); e.Next()) bodies.push_back(e.Current());
    // A surface model: its shells (those not inside a solid) count as solids when they mesh
    // closed. An OPEN_SHELL that does not is skipped with a warning; a CLOSED_SHELL (what
    // OpenCASCADE leaves of a damaged MANIFOLD_SOLID_BREP) that does not fails like a solid.
    const size_t first_shell = bodies.size();
    for (TopExp_Explorer e(shape, TopAbs_SHELL, TopAbs_SOLID); e.More(); e.Next()) {
      bodies.push_back(e.Current());
    }
    if (bodies.empty()) {
      out_.warnings.push_back("product " + Quote(product_name) + Entity(shape, " (", ")") +
                              " has no solid: skipped");
      return indices;
    }
    // Deflections in the document's millimetres; one mesher for the whole product.
    const double linear_mm = tess_.linear_deflection_m / kMetresPerMm;
    BRepMesh_IncrementalMesh mesher(shape, linear_mm, Standard_False, tess_.angular_deflection_rad,
                                    Standard_False);
    if (!mesher.IsDone()) {
      return Fail(ErrorCode::kInvalidInput, "STEP file " + Quote(file_) + ": product " +
                                                Quote(product_name) + Entity(shape, " (", ")") +
                                                " could not be tessellated");
    }
    for (size_t k = 0; k < bodies.size(); ++k) {
      StepSolid solid;
      solid.product = LabelName(product);
      std::string name = product_name;
      if (bodies.size() > 1) {
        TDF_Label sub;
        const std::string own =
            shapes_->FindSubShape(product, bodies[k], sub) ? LabelName(sub) : "";
        name = own.empty() ? product_name + "." + std::to_string(k + 1) : own;
      }
      solid.name = UniqueSolidName(name);
      solid.entity = Entity(bodies[k], "");
      auto mesh = MeshOf(bodies[k], solid);
      if (!mesh && k >= first_shell && solid.entity.find("OPEN_SHELL") != std::string::npos) {
        solid_names_.erase(solid.name);
        out_.warnings.push_back("shell " + Quote(solid.name) +
                                (solid.entity.empty() ? "" : " (" + solid.entity + ")") +
                                " is a surface, not a closed solid: skipped");
        continue;
      }
      if (!mesh) return std::unexpected(mesh.error());
      solid.mesh = std::move(*mesh);
      solid_colors_.push_back(SolidColor(colors_, bodies[k]));
      if (!solid_colors_.back()) solid_colors_.back() = LabelColor(colors_, product);
      indices.push_back(static_cast<int>(out_.solids.size()));
      out_.solids.push_back(std::move(solid));
    }
    return indices;
  }

  /// The triangles of every face of `body`, welded into one closed, outward mesh [m].
  Result<TriangleMesh> MeshOf(const TopoDS_Shape& body, const StepSolid& solid) {
    const std::string what = "STEP file " + Quote(file_) + ": solid " + Quote(solid.name) +
                             (solid.entity.empty() ? "" : " (" + solid.entity + ")");
    // Nodes of neighbouring faces on a shared edge come from one edge discretisation, so they
    // agree to rounding; the weld tolerance only absorbs that.
    detail::VertexWelder welder(1e-9);
    TriangleMesh mesh;
    int faces = 0;
    for (TopExp_Explorer e(body, TopAbs_FACE); e.More(); e.Next()) {
      const TopoDS_Face& face = TopoDS::Face(e.Current());
      ++faces;
      TopLoc_Location loc;
      const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
      if (tri.IsNull()) {
        return Fail(ErrorCode::kInvalidInput,
                    what + ": face " + std::to_string(faces) + Entity(face, " (", ")") +
                        " could not be tessellated; expected a valid B-rep surface");
      }
      const gp_Trsf& T = loc.Transformation();
      const bool flip = (face.Orientation() == TopAbs_REVERSED) != T.IsNegative();
      std::vector<int> index(static_cast<size_t>(tri->NbNodes()) + 1, -1);
      for (int n = 1; n <= tri->NbNodes(); ++n) {
        const gp_Pnt p = tri->Node(n).Transformed(T);
        const Vec3 v = kMetresPerMm * Vec3(p.X(), p.Y(), p.Z());
        if (!v.allFinite()) return Fail(ErrorCode::kInvalidInput, what + ": non-finite vertex");
        index[static_cast<size_t>(n)] = welder.Add(v);
      }
      for (int t = 1; t <= tri->NbTriangles(); ++t) {
        int a = 0, b = 0, c = 0;
        tri->Triangle(t).Get(a, b, c);
        if (a < 1 || b < 1 || c < 1 || a > tri->NbNodes() || b > tri->NbNodes() ||
            c > tri->NbNodes()) {
          continue;
        }
        Eigen::Vector3i ijk(index[static_cast<size_t>(a)], index[static_cast<size_t>(b)],
                            index[static_cast<size_t>(c)]);
        if (flip) std::swap(ijk[1], ijk[2]);
        if (ijk[0] == ijk[1] || ijk[1] == ijk[2] || ijk[0] == ijk[2]) continue;
        mesh.triangles.push_back(ijk);
      }
    }
    mesh.vertices = std::move(welder.vertices());
    return detail::CheckClosedSolid(std::move(mesh), what);
  }

  std::string UniqueSolidName(const std::string& base) {
    std::string name = base;
    for (int k = 2; !solid_names_.insert(name).second; ++k) name = base + "_" + std::to_string(k);
    return name;
  }

  /// "#123 MANIFOLD_SOLID_BREP"-style reference to the STEP entity a shape came from, wrapped
  /// in `before` and `after`; empty when unknown.
  std::string Entity(const TopoDS_Shape& shape, const std::string& before,
                     const std::string& after = "") {
    if (entities_.empty()) IndexEntities();
    const auto it = entities_.find(shape.TShape().get());
    return it == entities_.end() ? "" : before + it->second + after;
  }

  /// The transfer's results, by the shape each entity became (solids, shells and faces).
  void IndexEntities() {
    entities_[nullptr] = "";  // indexed, even when there is nothing to find
    const Handle(XSControl_WorkSession) ws = reader_.ChangeReader().WS();
    if (ws.IsNull() || ws->TransferReader().IsNull()) return;
    const Handle(Transfer_TransientProcess)& tp = ws->TransferReader()->TransientProcess();
    const Handle(StepData_StepModel) model = Handle(StepData_StepModel)::DownCast(ws->Model());
    if (tp.IsNull() || model.IsNull()) return;
    for (int i = 1; i <= tp->NbMapped(); ++i) {
      const TopoDS_Shape shape = TransferBRep::ShapeResult(tp->MapItem(i));
      if (shape.IsNull() ||
          (shape.ShapeType() != TopAbs_SOLID && shape.ShapeType() != TopAbs_SHELL &&
           shape.ShapeType() != TopAbs_FACE)) {
        continue;
      }
      const Handle(Standard_Transient)& entity = tp->Mapped(i);
      entities_.emplace(shape.TShape().get(),
                        "#" + std::to_string(model->IdentLabel(entity)) + " " +
                            detail::StepTypeName(model->TypeName(entity, Standard_False)));
    }
  }

  std::string file_;
  StepTessellation tess_;
  OcctSession& session_;
  STEPCAFControl_Reader& reader_;
  Handle(XCAFDoc_ShapeTool) shapes_;
  Handle(XCAFDoc_ColorTool) colors_;
  StepAssembly out_;
  std::vector<std::optional<Rgba4>> solid_colors_;  // parallel to out_.solids
  std::map<std::string, std::vector<int>> product_solids_;
  std::set<std::string> solid_names_;
  std::map<const TopoDS_TShape*, std::string> entities_;
};

/// Syntax errors OpenCASCADE recorded while parsing (it parses past them, dropping what it could
/// not read): the first few, with their lines. Per-entity semantic complaints are left alone:
/// files from working CAD tools have some, and what matters of them fails later, named.
std::string SyntaxErrors(STEPCAFControl_Reader& reader) {
  const Handle(XSControl_WorkSession) ws = reader.ChangeReader().WS();
  if (ws.IsNull() || ws->Model().IsNull()) return "";
  Interface_CheckIterator checks = ws->ModelCheckList(Standard_True);
  std::string out;
  int shown = 0;
  for (checks.Start(); checks.More() && shown < 3; checks.Next()) {
    if (checks.Number() != 0) continue;  // the parser's own (global) checks only
    const Handle(Interface_Check)& check = checks.Value();
    for (int i = 1; i <= check->NbFails() && shown < 3; ++i, ++shown) {
      std::string fail = check->CFail(i);
      if (fail.starts_with("Undefined Parsing: ")) fail.erase(0, 19);
      out += (out.empty() ? "" : "; ") + fail;
    }
  }
  return out;
}

/// The length unit(s) the file names; fails when a representation has none.
Result<std::string> FileLengthUnit(STEPCAFControl_Reader& reader, const std::string& file) {
  TColStd_SequenceOfAsciiString lengths, angles, solid_angles;
  reader.ChangeReader().FileUnits(lengths, angles, solid_angles);
  std::string unit;
  bool missing = lengths.IsEmpty();
  for (int i = 1; i <= lengths.Length(); ++i) {
    const std::string name = lengths.Value(i).ToCString();
    if (name.empty()) missing = true;
    if (!name.empty() && unit.find(name) == std::string::npos) {
      unit += (unit.empty() ? "" : ", ") + name;
    }
  }
  if (!missing) return unit;
  // Name the first representation context: where the unit should have been.
  std::string where;
  const Handle(StepData_StepModel) model =
      Handle(StepData_StepModel)::DownCast(reader.ChangeReader().WS()->Model());
  for (int i = 1; !model.IsNull() && i <= model->NbEntities(); ++i) {
    if (model->Value(i)->IsKind(STANDARD_TYPE(StepRepr_RepresentationContext))) {
      where = " (representation context #" + std::to_string(model->IdentLabel(model->Value(i))) +
              " has no LENGTH_UNIT in a GLOBAL_UNIT_ASSIGNED_CONTEXT)";
      break;
    }
  }
  return Fail(ErrorCode::kInvalidInput,
              "STEP file " + Quote(file) + " does not state its length unit" + where +
                  "; expected a unit such as millimetre or inch, so that sizes are known");
}

Result<void> CheckTessellation(const StepTessellation& t, const std::string& file) {
  if (!std::isfinite(t.linear_deflection_m) || t.linear_deflection_m < 1e-7 ||
      t.linear_deflection_m > 0.1) {
    return Fail(ErrorCode::kInvalidInput, "STEP import of " + Quote(file) + ": linear deflection " +
                                              std::to_string(t.linear_deflection_m) +
                                              " m is outside [1e-7, 0.1] m");
  }
  if (!std::isfinite(t.angular_deflection_rad) || t.angular_deflection_rad < 1e-3 ||
      t.angular_deflection_rad > std::numbers::pi / 2) {
    return Fail(ErrorCode::kInvalidInput,
                "STEP import of " + Quote(file) + ": angular deflection " +
                    std::to_string(t.angular_deflection_rad) + " rad is outside [0.001, pi/2]");
  }
  return {};
}

Result<StepAssembly> ReadStep(const fs::path& path, const StepTessellation& tessellation,
                              Locking locking) {
  const std::string file = path.string();
  OcctSession session(locking);
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  // Off: with it on, OpenCASCADE 7.6's ExpandSubShapes dereferences a null representation item
  // of a damaged file (found by fuzz_step; tests/fuzz/regressions/step). Parts are named by their
  // products and instances, which this does not touch.
  Interface_Static::SetIVal("read.stepcaf.subshapes.name", 0);
  XCAFDoc_DocumentTool::SetLengthUnit(session.doc(), kMetresPerMm);
  STEPCAFControl_Reader reader;
  reader.SetColorMode(Standard_True);
  reader.SetNameMode(Standard_True);
  reader.SetLayerMode(Standard_False);
  reader.SetPropsMode(Standard_False);
  reader.SetGDTMode(Standard_False);
  reader.SetMatMode(Standard_False);
  reader.SetViewMode(Standard_False);
  reader.SetSHUOMode(Standard_False);
  // Before OpenCASCADE reads it: its reader follows an oriented edge's missing or circular edge
  // until the stack overflows.
  if (const std::string broken = detail::FindBrokenReference(path); !broken.empty()) {
    return Fail(ErrorCode::kInvalidInput, "STEP file " + Quote(file) + " is damaged: " + broken);
  }
  if (reader.ReadFile(file.c_str()) != IFSelect_RetDone) {
    const std::string why = OcctSession::Messages("OpenCASCADE's reader failed");
    return Fail(ErrorCode::kInvalidInput, "cannot parse STEP file " + Quote(file) + ": " +
                                              detail::WithEntityOfLine(path, why) +
                                              "; expected an ISO 10303-21 file");
  }
  if (const std::string errors = SyntaxErrors(reader); !errors.empty()) {
    return Fail(ErrorCode::kInvalidInput, "STEP file " + Quote(file) + " is damaged: " +
                                              detail::WithEntityOfLine(path, errors));
  }
  if (reader.NbRootsForTransfer() == 0) {
    return Fail(ErrorCode::kInvalidInput,
                "STEP file " + Quote(file) +
                    " contains no solid (no product or shape representation to read); expected a "
                    "part or an assembly exported as solids");
  }
  auto unit = FileLengthUnit(reader, file);
  if (!unit) return std::unexpected(unit.error());
  if (!reader.Transfer(session.doc())) {
    return Fail(ErrorCode::kInvalidInput,
                "STEP file " + Quote(file) + ": no shape could be read (" +
                    OcctSession::Messages("OpenCASCADE's transfer failed") + ")");
  }
  double metres = 0.0;
  if (!XCAFDoc_DocumentTool::GetLengthUnit(session.doc(), metres) ||
      std::abs(metres - kMetresPerMm) > 1e-12) {
    return Fail(ErrorCode::kInternal,
                "STEP file " + Quote(file) + ": OpenCASCADE did not read it in millimetres");
  }
  StepReader read(file, tessellation, session, reader);
  auto out = read.Run();
  if (out) out->unit = *unit;
  return out;
}

/// The checks that need no OpenCASCADE: the deflections, and the file's start and end.
Result<void> CheckBeforeReading(const fs::path& path, const StepTessellation& tessellation) {
  if (auto ok = CheckTessellation(tessellation, path.string()); !ok) return ok;
  return detail::CheckStepFile(path);
}

/// ReadStep with OpenCASCADE's exceptions made errors.
Result<StepAssembly> ReadStepGuarded(const fs::path& path, const StepTessellation& tessellation,
                                     Locking locking) {
  try {
    return ReadStep(path, tessellation, locking);
  } catch (const Standard_Failure& e) {
    return Fail(ErrorCode::kInvalidInput, "cannot read STEP file " + Quote(path.string()) +
                                              ": OpenCASCADE failed (" + e.DynamicType()->Name() +
                                              ": " + e.GetMessageString() + ")");
  } catch (const std::exception& e) {
    return Fail(ErrorCode::kInvalidInput,
                "cannot read STEP file " + Quote(path.string()) + ": " + e.what());
  }
}

// ---- Writing ----------------------------------------------------------------------------------

gp_Trsf ToTrsf(const Iso3& X) {
  const Mat3 R = X.linear();
  const Vec3 t = X.translation() / kMetresPerMm;
  gp_Trsf T;
  T.SetValues(R(0, 0), R(0, 1), R(0, 2), t.x(), R(1, 0), R(1, 1), R(1, 2), t.y(), R(2, 0), R(2, 1),
              R(2, 2), t.z());
  return T;
}

Result<TopoDS_Shape> BuildSolid(const std::vector<StepPrimitive>& primitives,
                                const std::string& what) {
  TopoDS_Shape solid;
  for (size_t i = 0; i < primitives.size(); ++i) {
    const StepPrimitive& p = primitives[i];
    const Vec3 o = p.origin / kMetresPerMm;
    TopoDS_Shape shape;
    if (p.kind == StepPrimitive::Kind::kBox) {
      const Vec3 s = p.size / kMetresPerMm;
      if (!(s.minCoeff() > 0.0)) return Fail(ErrorCode::kInvalidInput, what + ": empty box");
      shape = BRepPrimAPI_MakeBox(gp_Pnt(o.x(), o.y(), o.z()), s.x(), s.y(), s.z()).Shape();
    } else if (p.kind == StepPrimitive::Kind::kSphere) {
      if (!(p.radius > 0.0)) return Fail(ErrorCode::kInvalidInput, what + ": empty sphere");
      shape = BRepPrimAPI_MakeSphere(gp_Pnt(o.x(), o.y(), o.z()), p.radius / kMetresPerMm).Shape();
    } else {
      const Vec3 a = p.axis.normalized();
      if (!(p.radius > 0.0 && p.height > 0.0) || !a.allFinite()) {
        return Fail(ErrorCode::kInvalidInput, what + ": empty cylinder");
      }
      const gp_Ax2 axes(gp_Pnt(o.x(), o.y(), o.z()), gp_Dir(a.x(), a.y(), a.z()));
      shape =
          BRepPrimAPI_MakeCylinder(axes, p.radius / kMetresPerMm, p.height / kMetresPerMm).Shape();
    }
    if (i == 0) {
      if (p.subtract) return Fail(ErrorCode::kInvalidInput, what + ": starts with a cut");
      solid = shape;
      continue;
    }
    if (p.subtract) {
      BRepAlgoAPI_Cut cut(solid, shape);
      if (!cut.IsDone() || cut.HasErrors())
        return Fail(ErrorCode::kInvalidInput, what + ": cut failed");
      solid = cut.Shape();
    } else {
      BRepAlgoAPI_Fuse fuse(solid, shape);
      if (!fuse.IsDone() || fuse.HasErrors())
        return Fail(ErrorCode::kInvalidInput, what + ": fuse failed");
      solid = fuse.Shape();
    }
  }
  if (solid.IsNull()) return Fail(ErrorCode::kInvalidInput, what + ": no primitives");
  return solid;
}

Result<void> WriteStepLocked(const StepDocumentSpec& spec, const fs::path& path) {
  const std::string file = path.string();
  if (spec.unit != "MM" && spec.unit != "M" && spec.unit != "CM" && spec.unit != "INCH") {
    return Fail(ErrorCode::kInvalidInput,
                "STEP writer: unit " + Quote(spec.unit) + " is not one of MM, M, CM, INCH");
  }
  OcctSession session;
  XCAFDoc_DocumentTool::SetLengthUnit(session.doc(), kMetresPerMm);
  const Handle(XCAFDoc_ShapeTool) shapes = session.shapes();
  const Handle(XCAFDoc_ColorTool) colors = session.colors();
  std::vector<TDF_Label> labels;
  for (const StepProductSpec& product : spec.products) {
    TopoDS_Compound compound;
    BRep_Builder builder;
    builder.MakeCompound(compound);
    TopoDS_Shape shape;
    for (const auto& prims : product.solids) {
      auto solid = BuildSolid(prims, "STEP writer: product " + Quote(product.name));
      if (!solid) return std::unexpected(solid.error());
      builder.Add(compound, *solid);
      shape = *solid;
    }
    if (product.solids.size() != 1) shape = compound;
    const TDF_Label label = shapes->AddShape(shape, Standard_False);
    TDataStd_Name::Set(label, TCollection_ExtendedString(product.name.c_str(), Standard_True));
    if (product.color) {
      const auto& c = *product.color;
      const Quantity_ColorRGBA rgba(Quantity_Color(c[0], c[1], c[2], Quantity_TOC_sRGB),
                                    static_cast<float>(c[3]));
      colors->SetColor(label, rgba, XCAFDoc_ColorSurf);
    }
    labels.push_back(label);
  }
  if (!spec.instances.empty()) {
    const TDF_Label assembly = shapes->NewShape();
    TDataStd_Name::Set(assembly, TCollection_ExtendedString(spec.name.c_str(), Standard_True));
    for (const StepInstanceSpec& inst : spec.instances) {
      if (inst.product < 0 || static_cast<size_t>(inst.product) >= labels.size()) {
        return Fail(ErrorCode::kInvalidInput,
                    "STEP writer: instance " + Quote(inst.name) + " names no product");
      }
      const TDF_Label component = shapes->AddComponent(
          assembly, labels[static_cast<size_t>(inst.product)], TopLoc_Location(ToTrsf(inst.X_AP)));
      if (!inst.name.empty()) {
        TDataStd_Name::Set(component, TCollection_ExtendedString(inst.name.c_str(), Standard_True));
      }
    }
    shapes->UpdateAssemblies();
  }
  Interface_Static::SetCVal("write.step.unit", spec.unit.c_str());
  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  STEPCAFControl_Writer writer;
  writer.SetColorMode(Standard_True);
  writer.SetNameMode(Standard_True);
  if (!writer.Transfer(session.doc(), STEPControl_AsIs)) {
    return Fail(ErrorCode::kInvalidInput,
                "STEP writer: " + OcctSession::Messages("the transfer of the shapes failed"));
  }
  // Instance ids numbered from 1 (OpenCASCADE counts on across writes in one process) and a
  // fixed header, so that the same spec writes the same bytes.
  const Handle(StepData_StepModel) model = writer.ChangeWriter().Model();
  for (int i = 1, id = 1; i <= model->NbEntities(); ++i) {
    const auto nauo = Handle(StepRepr_NextAssemblyUsageOccurrence)::DownCast(model->Value(i));
    if (!nauo.IsNull()) nauo->SetId(new TCollection_HAsciiString(std::to_string(id++).c_str()));
  }
  APIHeaderSection_MakeHeader header(model);
  header.SetName(new TCollection_HAsciiString(spec.name.c_str()));
  header.SetTimeStamp(new TCollection_HAsciiString("2000-01-01T00:00:00"));
  header.SetAuthorValue(1, new TCollection_HAsciiString("Wrap"));
  header.SetOrganizationValue(1, new TCollection_HAsciiString("Wrap"));
  header.SetOriginatingSystem(new TCollection_HAsciiString("Wrap (OpenCASCADE)"));
  header.SetPreprocessorVersion(new TCollection_HAsciiString("OpenCASCADE"));
  // OpenCASCADE writes to a named file only: a private temporary one, whose text is then saved
  // atomically (readers of `path` never see a partial file).
  static int counter = 0;
  const fs::path temp = fs::temp_directory_path() / ("wrap_step_" + std::to_string(::getpid()) +
                                                     "_" + std::to_string(++counter) + ".step");
  const IFSelect_ReturnStatus status = writer.Write(temp.string().c_str());
  auto text = status == IFSelect_RetDone ? ReadFile(temp) : Result<std::string>(std::string());
  std::error_code ec;
  fs::remove(temp, ec);
  if (status != IFSelect_RetDone || !text) {
    return Fail(ErrorCode::kIo, "cannot write STEP file " + Quote(file) + ": " +
                                    (text ? OcctSession::Messages("OpenCASCADE's writer failed")
                                          : text.error().message));
  }
  if (auto ok = WriteFileAtomic(path, *text); !ok) return ok;
  return {};
}

}  // namespace

bool StepImportAvailable() { return true; }

Result<StepAssembly> ImportStepInProcess(const fs::path& path,
                                         const StepTessellation& tessellation) {
  if (auto ok = CheckBeforeReading(path, tessellation); !ok) return std::unexpected(ok.error());
  return ReadStepGuarded(path, tessellation, Locking::kLock);
}

Result<StepAssembly> ImportStep(const fs::path& path, const StepTessellation& tessellation) {
  // The checks here, so that their errors need no child process.
  if (auto ok = CheckBeforeReading(path, tessellation); !ok) return std::unexpected(ok.error());
  return detail::ImportInChild(
      path.string(), [&] { return ReadStepGuarded(path, tessellation, Locking::kInheritedLock); },
      OcctMutex());
}

Result<void> WriteStep(const StepDocumentSpec& spec, const fs::path& path) {
  try {
    return WriteStepLocked(spec, path);
  } catch (const Standard_Failure& e) {
    return Fail(ErrorCode::kInvalidInput, "STEP writer: OpenCASCADE failed (" +
                                              std::string(e.DynamicType()->Name()) + ": " +
                                              e.GetMessageString() + ")");
  } catch (const std::exception& e) {
    return Fail(ErrorCode::kInvalidInput, std::string("STEP writer: ") + e.what());
  }
}

}  // namespace wrap
