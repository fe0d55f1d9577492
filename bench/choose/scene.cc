#include "bench/choose/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include "bench/base/files.h"
#include "bench/capture/depth_capture.h"
#include "bench/pipeline/projection_matrix.h"
#include "bench/sweep/sweep.h"

namespace depthbench {
namespace {

// Reads typed fields out of a TOML table; every error names the file,
// line and column, the field, and what is allowed.
class SceneReader {
 public:
  explicit SceneReader(std::string source) : source_(std::move(source)) {}

  Status Error(const toml::node* node, const std::string& field, const std::string& message) const {
    if (node != nullptr && node->source().begin.line > 0) {
      return InvalidArgument(fmt::format("{}:{}:{}: {}: {}", source_, node->source().begin.line,
                                         node->source().begin.column, field, message));
    }
    return InvalidArgument(fmt::format("{}: {}: {}", source_, field, message));
  }

  // Refuses keys a table does not know (most often a typo).
  Status OnlyKeys(const toml::table& table, const std::string& where, std::initializer_list<std::string_view> keys) {
    for (const auto& [key, node] : table) {
      if (std::find(keys.begin(), keys.end(), key.str()) == keys.end()) {
        std::string allowed;
        for (auto k : keys) allowed += (allowed.empty() ? "" : ", ") + std::string(k);
        return Error(&node, where.empty() ? std::string(key.str()) : where + "." + std::string(key.str()),
                     "unknown field; allowed here: " + allowed);
      }
    }
    return Status::Ok();
  }

  Expected<const toml::table*> Table(const toml::table& parent, const std::string& key, bool required) {
    const toml::node* node = parent.get(key);
    if (node == nullptr) {
      if (required) return Error(&parent, "[" + key + "]", "missing table");
      return static_cast<const toml::table*>(nullptr);
    }
    if (!node->is_table()) return Error(node, key, "expected a table [" + key + "]");
    return node->as_table();
  }

  Expected<double> Number(const toml::node* node, const std::string& field) {
    if (node == nullptr) return Error(nullptr, field, "missing");
    if (auto v = node->value<double>()) return *v;
    return Error(node, field, "expected a number");
  }

  Expected<bool> Boolean(const toml::node* node, const std::string& field) {
    if (auto v = node->value<bool>()) return *v;
    return Error(node, field, "expected true or false");
  }

  // A number, or [min, max].
  Expected<Range> NumberOrRange(const toml::node* node, const std::string& field) {
    if (node == nullptr) return Error(nullptr, field, "missing");
    if (const toml::array* a = node->as_array()) {
      if (a->size() != 2) return Error(node, field, "expected a number or [min, max]");
      DB_ASSIGN_OR_RETURN(double lo, Number(a->get(0), field + "[0]"));
      DB_ASSIGN_OR_RETURN(double hi, Number(a->get(1), field + "[1]"));
      return Range{lo, hi};
    }
    DB_ASSIGN_OR_RETURN(double v, Number(node, field));
    return Range{v, v};
  }

  Status Check(const Range& range, const toml::node* node, const std::string& field, const RangeLimits& limits) {
    Status s = CheckRange(range, field, limits);
    if (s.ok()) return s;
    // CheckRange starts with the field's name; keep its explanation.
    std::string message = s.message().substr(field.size() + 2);
    return Error(node, field, message);
  }

  // "any", or a list of names each `parse` accepts.
  template <class T, class Parse>
  Status Names(const toml::table& table, const std::string& key, const std::string& field, Parse parse,
               std::vector<T>& out) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return Status::Ok();  // any
    if (auto s = node->value<std::string>()) {
      if (*s == "any") return Status::Ok();
      return Error(node, field, "expected \"any\" or a list of names");
    }
    const toml::array* a = node->as_array();
    if (a == nullptr || a->empty()) return Error(node, field, "expected \"any\" or a non-empty list of names");
    for (const toml::node& item : *a) {
      auto name = item.value<std::string>();
      if (!name) return Error(&item, field, "expected a name (a string)");
      Expected<T> parsed = parse(*name);
      if (!parsed.ok()) return Error(&item, field, parsed.status().message());
      out.push_back(*parsed);
    }
    return Status::Ok();
  }

 private:
  std::string source_;
};

}  // namespace

double Requirement::RelativeLimit() const {
  switch (kind) {
    case Kind::kAbsolute: return value / at_depth.value_or(1.0);
    case Kind::kRelative: return value;
    case Kind::kBitsLost: return std::ldexp(1.0, -24) * std::exp2(value);
  }
  return 0.0;
}

std::string Requirement::Describe() const {
  std::string what;
  switch (kind) {
    case Kind::kAbsolute: what = fmt::format("absolute error <= {:g} world units", value); break;
    case Kind::kRelative: what = fmt::format("relative error <= {:g}", value); break;
    case Kind::kBitsLost: what = fmt::format("bits lost <= {:g}", value); break;
  }
  if (at_depth) what += fmt::format(" at eye depth {:g}", *at_depth);
  return what + (proven ? std::string(" (proven, on any conformant Vulkan device)") : fmt::format(" ({})", LevelName(level)));
}

std::vector<Cell> Scene::CellsWith(std::vector<Convention> conventions, std::vector<Format> formats) const {
  const CellFilter filter{variants, std::move(conventions), std::move(formats)};
  return filter.CellsOf(catalogue != nullptr ? *catalogue : Catalogue::BuiltIn());
}

std::vector<Cell> Scene::Candidates() const { return CellsForDomain(CellsWith(conventions, formats), domain); }

std::vector<std::string> Scene::UnusableFormats() const {
  const std::vector<Cell> candidates = Candidates();
  std::vector<std::string> unusable;
  for (const Format format : formats) {
    if (std::any_of(candidates.begin(), candidates.end(), [&](const Cell& c) { return c.format == format; })) continue;
    // The conventions that would read it, with the engine's variants, in this domain.
    std::vector<std::string> needed;
    for (const Cell& c : CellsForDomain(CellsWith({}, {format}), domain)) {
      const std::string name(Info(c.convention).name);
      if (std::find(needed.begin(), needed.end(), name) == needed.end()) needed.push_back(name);
    }
    unusable.push_back(
        needed.empty()
            ? fmt::format("{}: no convention can read it in this scene's ranges (a linear or view-z format needs a "
                          "finite far plane)",
                          Info(format).name)
            : fmt::format("{}: read only under {}, which engine.conventions does not list", Info(format).name,
                          fmt::join(needed, ", ")));
  }
  return unusable;
}

namespace {

// The deepest eye depth a scene's domain holds: its far plane, or the span
// an infinite far plane is sampled over.
double DeepestEyeDepth(const Domain& d) {
  return d.finite_far ? d.far->max : d.near.min * Domain::kInfiniteDepthSpan;
}

// projection.resolution: the render target a frame is costed at.
Status ReadResolution(SceneReader& r, const toml::table& projection, Domain& d) {
  if (const toml::node* res = projection.get("resolution")) {
    const toml::array* a = res->as_array();
    // value_exact: whole numbers only. toml++'s value<int64_t>() converts a
    // float such as 1e300 to an integer before it checks the range, which is
    // undefined behaviour (found by fuzz_scene).
    auto w = a && a->size() == 2 ? a->get(0)->value_exact<std::int64_t>() : std::nullopt;
    auto h = a && a->size() == 2 ? a->get(1)->value_exact<std::int64_t>() : std::nullopt;
    if (!w || !h || *w < 1 || *h < 1 || *w > kMaxResolutionSide || *h > kMaxResolutionSide) {
      return r.Error(res, "projection.resolution",
                     fmt::format("expected [width, height] in pixels, 1 to {} each", kMaxResolutionSide));
    }
    d.resolutions = {{static_cast<std::uint32_t>(*w), static_cast<std::uint32_t>(*h)}};
  }
  return Status::Ok();
}

// projection.matrix, .api and .layout: the engine's own matrix, which
// fixes the planes, the lens and the depth convention.
Status ReadMatrix(SceneReader& r, const toml::table& projection, Scene& scene) {
  const toml::node* node = projection.get("matrix");
  for (const char* key : {"near", "far", "fov_degrees", "aspect", "eye_fov", "ortho"}) {
    if (const toml::node* other = projection.get(key)) {
      return r.Error(other, std::string("projection.") + key, "the matrix sets it; give one or the other");
    }
  }
  const toml::array* numbers = node->as_array();
  if (numbers == nullptr || numbers->size() != 16) {
    return r.Error(node, "projection.matrix", "expected 16 numbers, in the order projection.layout names");
  }
  ProjectionMatrix m;
  for (int k = 0; k < 16; ++k) {
    DB_ASSIGN_OR_RETURN(m.numbers[k], r.Number(numbers->get(k), fmt::format("projection.matrix[{}]", k)));
  }
  const auto name = [&](const char* key, std::string_view allowed) -> Expected<std::string> {
    const toml::node* n = projection.get(key);
    auto s = n != nullptr ? n->value<std::string>() : std::nullopt;
    if (!s) return r.Error(n != nullptr ? n : node, std::string("projection.") + key, fmt::format("expected one of {}", allowed));
    return *s;
  };
  DB_ASSIGN_OR_RETURN(const std::string api, name("api", kGraphicsApiNames));
  DB_ASSIGN_OR_RETURN(const std::string layout, name("layout", "column-major, row-major"));
  Expected<GraphicsApi> parsed_api = ParseGraphicsApi(api);
  if (!parsed_api.ok()) return r.Error(projection.get("api"), "projection.api", parsed_api.status().message());
  Expected<MatrixLayout> parsed_layout = ParseMatrixLayout(layout);
  if (!parsed_layout.ok()) {
    return r.Error(projection.get("layout"), "projection.layout", parsed_layout.status().message());
  }
  m.api = *parsed_api;
  m.layout = *parsed_layout;
  Expected<ProjectionFacts> facts = ReadProjectionMatrix(m);
  if (!facts.ok()) return r.Error(node, "projection.matrix", facts.status().message());
  const Status applied = ApplyProjection(*facts, scene.domain);
  if (!applied.ok()) return r.Error(node, "projection.matrix", applied.message());
  scene.domain.depth_convention = facts->convention;
  scene.api = m.api;
  scene.projection_facts = facts->Describe();
  return Status::Ok();
}

// projection.KEY as four numbers, `shape` saying what they are.
Expected<std::array<double, 4>> ReadFour(SceneReader& r, const toml::node* node, const std::string& key,
                                         std::string_view shape) {
  const toml::array* a = node->as_array();
  if (a == nullptr || a->size() != 4) return r.Error(node, key, fmt::format("expected {}", shape));
  std::array<double, 4> numbers;
  for (int k = 0; k < 4; ++k) {
    DB_ASSIGN_OR_RETURN(numbers[k], r.Number(a->get(k), fmt::format("{}[{}]", key, k)));
  }
  return numbers;
}

// projection.eye_fov, projection.ortho, or fov_degrees and aspect: the lens.
Status ReadLens(SceneReader& r, const toml::table& projection, Domain& d) {
  for (const char* lens : {"eye_fov", "ortho"}) {
    const toml::node* node = projection.get(lens);
    if (node == nullptr) continue;
    for (const char* key : {"fov_degrees", "aspect", "eye_fov"}) {
      const toml::node* other = projection.get(key);
      if (other != nullptr && key != std::string_view(lens)) {
        return r.Error(other, std::string("projection.") + key,
                       fmt::format("{} sets the lens; give one or the other", lens));
      }
    }
    const std::string key = std::string("projection.") + lens;
    if (lens == std::string_view("eye_fov")) {
      DB_ASSIGN_OR_RETURN(const auto angles,
                          ReadFour(r, node, key, "[left, right, up, down] in degrees (left and down negative)"));
      d.eye_fov = EyeFov{angles[0], angles[1], angles[2], angles[3]};
      const Status valid = CheckEyeFov(*d.eye_fov, "eye_fov");
      if (!valid.ok()) return r.Error(node, key, valid.message());
      return Status::Ok();
    }
    DB_ASSIGN_OR_RETURN(const auto sides, ReadFour(r, node, key, "[left, right, bottom, top] in view units"));
    d.orthographic = ViewVolume{sides[0], sides[1], sides[2], sides[3]};
    const Status valid = CheckViewVolume(*d.orthographic, "ortho");
    if (!valid.ok()) return r.Error(node, key, valid.message());
    if (d.infinite_far) {
      return r.Error(projection.get("far"), "projection.far", "an orthographic projection needs a finite far plane");
    }
    return Status::Ok();
  }
  DB_ASSIGN_OR_RETURN(d.fov_degrees, r.NumberOrRange(projection.get("fov_degrees"), "projection.fov_degrees"));
  DB_RETURN_IF_ERROR(r.Check(d.fov_degrees, projection.get("fov_degrees"), "projection.fov_degrees", kFovLimits));
  DB_ASSIGN_OR_RETURN(d.aspect, r.NumberOrRange(projection.get("aspect"), "projection.aspect"));
  return r.Check(d.aspect, projection.get("aspect"), "projection.aspect", kAspectLimits);
}

// [projection]: the planes, the lens and the render target.
Status ReadProjection(SceneReader& r, const toml::table& root, Scene& scene) {
  Domain& d = scene.domain;
  DB_ASSIGN_OR_RETURN(const toml::table* projection, r.Table(root, "projection", true));
  DB_RETURN_IF_ERROR(r.OnlyKeys(*projection, "projection",
                                {"near", "far", "fov_degrees", "aspect", "eye_fov", "ortho", "matrix", "api",
                                 "layout", "jitter", "resolution"}));
  if (const toml::node* node = projection->get("jitter")) {
    DB_ASSIGN_OR_RETURN(d.jitter, r.Number(node, "projection.jitter"));
    if (!(d.jitter >= 0.0 && d.jitter <= kMostJitterPixels)) {
      return r.Error(node, "projection.jitter", fmt::format("allowed [0, {:g}] pixels", kMostJitterPixels));
    }
  }
  DB_RETURN_IF_ERROR(ReadResolution(r, *projection, d));
  if (projection->get("matrix") != nullptr) return ReadMatrix(r, *projection, scene);
  for (const char* key : {"api", "layout"}) {
    if (const toml::node* other = projection->get(key)) {
      return r.Error(other, std::string("projection.") + key, "describes projection.matrix, which is not given");
    }
  }
  const toml::node* near_node = projection->get("near");
  DB_ASSIGN_OR_RETURN(double near, r.Number(near_node, "projection.near"));
  if (!(near > 0.0))
    return r.Error(near_node, "projection.near", fmt::format("must be greater than 0 (got {:g})", near));
  d.near = {near, near};
  const toml::node* far_node = projection->get("far");
  if (far_node == nullptr) return r.Error(projection, "projection.far", "missing (a number, or \"inf\")");
  double far = INFINITY;
  if (auto s = far_node->value<std::string>()) {
    if (*s != "inf") return r.Error(far_node, "projection.far", "expected a number or \"inf\"");
    d.finite_far = false;
    d.infinite_far = true;
  } else {
    DB_ASSIGN_OR_RETURN(far, r.Number(far_node, "projection.far"));
    if (!(far > near)) {
      return r.Error(far_node, "projection.far", fmt::format("must be greater than near ({:g}); got {:g}", near, far));
    }
    d.far = Range{far, far};
    d.finite_far = true;
    d.infinite_far = false;
  }
  return ReadLens(r, *projection, d);
}


// [camera] and [depth]: where the camera stands and which eye depths matter.
Status ReadCameraAndDepth(SceneReader& r, const toml::table& root, Domain& d) {
  DB_ASSIGN_OR_RETURN(const toml::table* camera, r.Table(root, "camera", false));
  d.camera_distance = {0.0, 0.0};
  if (camera != nullptr) {
    DB_RETURN_IF_ERROR(r.OnlyKeys(*camera, "camera", {"distance_from_origin"}));
    if (const toml::node* node = camera->get("distance_from_origin")) {
      DB_ASSIGN_OR_RETURN(d.camera_distance, r.NumberOrRange(node, "camera.distance_from_origin"));
      DB_RETURN_IF_ERROR(r.Check(d.camera_distance, node, "camera.distance_from_origin", kCameraDistanceLimits));
    }
  }

  DB_ASSIGN_OR_RETURN(const toml::table* depth, r.Table(root, "depth", false));
  if (depth != nullptr) {
    DB_RETURN_IF_ERROR(r.OnlyKeys(*depth, "depth", {"range"}));
    if (const toml::node* node = depth->get("range")) {
      DB_ASSIGN_OR_RETURN(Range range, r.NumberOrRange(node, "depth.range"));
      const double near = d.near.min, limit = DeepestEyeDepth(d);
      if (range.min < near || range.max > limit || range.min > range.max) {
        return r.Error(
            node, "depth.range",
            fmt::format("must lie within [near, far] = [{:g}, {:g}]; got {}", near, limit, range.ToString()));
      }
      d.eye_depth = range;
    }
  }

  return Status::Ok();
}

// [capture]: a depth buffer saved from a real frame, whose pixels are the
// scene's population (bench/capture/depth_capture.h).
Status ReadCapture(SceneReader& r, const toml::table& root, Scene& scene) {
  DB_ASSIGN_OR_RETURN(const toml::table* capture, r.Table(root, "capture", false));
  if (capture == nullptr) return Status::Ok();
  DB_RETURN_IF_ERROR(r.OnlyKeys(*capture, "capture", {"file", "stores", "channel", "camera_position"}));
  const auto text = [&](const char* key, std::string fallback) -> Expected<std::string> {
    const toml::node* node = capture->get(key);
    if (node == nullptr) return fallback;
    if (auto v = node->value<std::string>()) return *v;
    return r.Error(node, std::string("capture.") + key, "expected a string");
  };
  DB_ASSIGN_OR_RETURN(const std::string file, text("file", ""));
  if (file.empty()) return r.Error(capture, "capture.file", "missing: the OpenEXR file of the frame's depth buffer");
  DB_ASSIGN_OR_RETURN(const std::string stores_name, text("stores", CaptureStoresName(CaptureStores::kWindowDepth)));
  const Expected<CaptureStores> stores = ParseCaptureStores(stores_name);
  if (!stores.ok()) return r.Error(capture->get("stores"), "capture.stores", stores.status().message());
  DB_ASSIGN_OR_RETURN(const std::string channel, text("channel", ""));
  Domain& d = scene.domain;
  if (*stores == CaptureStores::kWindowDepth && !d.depth_convention) {
    return r.Error(capture, "capture.stores",
                   "window depth is decoded through the frame's projection: give projection.matrix (or store "
                   "eye-depth)");
  }
  glm::dvec3 camera(0.0);
  if (const toml::node* node = capture->get("camera_position")) {
    const toml::array* xyz = node->as_array();
    if (xyz == nullptr || xyz->size() != 3) {
      return r.Error(node, "capture.camera_position", "expected [x, y, z], the camera's world position");
    }
    for (int k = 0; k < 3; ++k) {
      DB_ASSIGN_OR_RETURN(camera[k], r.Number(xyz->get(k), fmt::format("capture.camera_position[{}]", k)));
      camera[k] = static_cast<float>(camera[k]);  // as an engine stores it
    }
    if (root.get("camera") != nullptr) {
      return r.Error(node, "capture.camera_position", "[camera] places the camera too; give one or the other");
    }
    if (!(glm::length(camera) <= kCameraDistanceLimits.highest)) {
      return r.Error(node, "capture.camera_position",
                     fmt::format("at most {:g} from the origin", kCameraDistanceLimits.highest));
    }
  }
  // The file is found beside the scene file.
  const std::filesystem::path path = std::filesystem::path(scene.source).parent_path() / file;
  const Expected<CaptureImage> image = ReadDepthExr(path, channel);
  if (!image.ok()) return r.Error(capture->get("file"), "capture.file", image.status().message());
  const Convention convention = d.depth_convention.value_or(Convention::kStandard);
  const double far = d.finite_far ? (d.far ? d.far->min : d.near.min * d.ratio.min) : INFINITY;
  Expected<CapturedPixels> pixels = DecodeCapture(*image, path.string(), *stores, convention, d.near.min, far);
  if (!pixels.ok()) return r.Error(capture->get("file"), "capture.file", pixels.status().message());
  pixels->camera_position = camera;
  pixels->description = fmt::format("{}x{} {} ({} channel {}), {} background", image->width, image->height,
                                    CaptureStoresName(*stores), image->channel_type, image->channel,
                                    pixels->background);
  Expected<Domain> captured = CaptureDomain(d, std::make_shared<const CapturedPixels>(std::move(pixels).value()));
  if (!captured.ok()) return r.Error(capture->get("file"), "capture.file", captured.status().message());
  d = std::move(captured).value();
  return Status::Ok();
}

// [engine]: the variants, conventions and formats the engine allows.
Status ReadEngine(SceneReader& r, const toml::table& root, const Catalogue& catalogue, Scene& scene) {
  DB_ASSIGN_OR_RETURN(const toml::table* engine, r.Table(root, "engine", false));
  if (engine != nullptr) {
    DB_RETURN_IF_ERROR(r.OnlyKeys(*engine, "engine", {"variants", "conventions", "formats", "stencil"}));
    if (const toml::node* stencil = engine->get("stencil")) {
      DB_ASSIGN_OR_RETURN(scene.stencil, r.Boolean(stencil, "engine.stencil"));
    }
    DB_RETURN_IF_ERROR(r.Names<Variant>(
        *engine, "variants", "engine.variants", [&](std::string_view name) { return catalogue.ParseVariant(name); },
        scene.variants));
    DB_RETURN_IF_ERROR(
        r.Names<Convention>(*engine, "conventions", "engine.conventions", ParseConvention, scene.conventions));
    DB_RETURN_IF_ERROR(r.Names<Format>(*engine, "formats", "engine.formats", ParseFormat, scene.formats));
  }

  return Status::Ok();
}

// [requirement]: one error bound, the depth it applies at and its level.
Status ReadRequirement(SceneReader& r, const toml::table& root, const Domain& d, Requirement& req) {
  DB_ASSIGN_OR_RETURN(const toml::table* requirement, r.Table(root, "requirement", true));
  DB_RETURN_IF_ERROR(
      r.OnlyKeys(*requirement, "requirement", {"absolute_error", "relative_error", "bits_lost", "at_depth", "level"}));
  int kinds = 0;
  for (const auto& [key, kind] : {std::pair{"absolute_error", Requirement::Kind::kAbsolute},
                                  std::pair{"relative_error", Requirement::Kind::kRelative},
                                  std::pair{"bits_lost", Requirement::Kind::kBitsLost}}) {
    const toml::node* node = requirement->get(key);
    if (node == nullptr) continue;
    ++kinds;
    req.kind = kind;
    DB_ASSIGN_OR_RETURN(req.value, r.Number(node, std::string("requirement.") + key));
    if (!(req.value > 0.0) && kind != Requirement::Kind::kBitsLost) {
      return r.Error(node, std::string("requirement.") + key, "must be greater than 0");
    }
    if (kind == Requirement::Kind::kBitsLost && !(req.value >= 0.0 && req.value <= 24.0)) {
      return r.Error(node, "requirement.bits_lost", "must lie in [0, 24]");
    }
  }
  if (kinds != 1) {
    return r.Error(requirement, "[requirement]",
                   "needs exactly one of absolute_error (world units), relative_error, bits_lost");
  }
  if (const toml::node* node = requirement->get("at_depth")) {
    DB_ASSIGN_OR_RETURN(double at, r.Number(node, "requirement.at_depth"));
    const double lo = d.eye_depth ? d.eye_depth->min : d.near.min;
    const double hi = d.eye_depth ? d.eye_depth->max : DeepestEyeDepth(d);
    if (!(at >= lo && at <= hi)) {
      return r.Error(node, "requirement.at_depth",
                     fmt::format("must lie in the scene's eye-depth range [{:g}, {:g}]; got {:g}", lo, hi, at));
    }
    req.at_depth = at;
  } else if (req.kind == Requirement::Kind::kAbsolute) {
    return r.Error(requirement, "requirement.at_depth",
                   "an absolute error needs the eye depth it applies at (\"1 cm at 5 km\")");
  }
  if (const toml::node* node = requirement->get("level")) {
    auto name = node->value<std::string>();
    // "bound": the proven bound decides; the measured maximum is shown beside it.
    req.proven = name && *name == "bound";
    auto level = req.proven ? Expected<Level>(Level::kMax)
                 : name     ? ParseLevel(*name)
                            : Expected<Level>(InvalidArgument("expected a string"));
    if (!level.ok() || (*level != Level::kP999 && *level != Level::kMax)) {
      return r.Error(node, "requirement.level", "allowed: \"p99.9\", \"max\", \"bound\"");
    }
    req.level = *level;
  }

  return Status::Ok();
}

// [cost]: the most a candidate may cost.
Status ReadCost(SceneReader& r, const toml::table& root, Scene& scene) {
  DB_ASSIGN_OR_RETURN(const toml::table* cost, r.Table(root, "cost", false));
  if (cost != nullptr) {
    DB_RETURN_IF_ERROR(r.OnlyKeys(*cost, "cost", {"max_cost"}));
    if (const toml::node* node = cost->get("max_cost")) {
      DB_ASSIGN_OR_RETURN(double max_cost, r.Number(node, "cost.max_cost"));
      if (!(max_cost > 0.0)) return r.Error(node, "cost.max_cost", "must be greater than 0");
      scene.max_cost = max_cost;
    }
  }
  return Status::Ok();
}

}  // namespace

Expected<Scene> ParseScene(std::string_view text, const std::string& source, const Catalogue& catalogue) {
  SceneReader r(source);
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    return InvalidArgument(fmt::format("{}:{}:{}: not valid TOML: {}", source, e.source().begin.line,
                                       e.source().begin.column, e.description()));
  }
  DB_RETURN_IF_ERROR(
      r.OnlyKeys(root, "", {"name", "projection", "camera", "depth", "capture", "engine", "requirement", "cost"}));
  Scene scene;
  scene.catalogue = &catalogue;
  scene.source = source;
  scene.name = root["name"].value_or(std::string(std::filesystem::path(source).stem()));
  Domain& d = scene.domain;
  d.name = "scene " + scene.name;

  DB_RETURN_IF_ERROR(ReadProjection(r, root, scene));
  // projection.resolution leaves the one it names; the default domain has several.
  if (d.resolutions.size() == 1) scene.resolution = d.resolutions.front();
  DB_RETURN_IF_ERROR(ReadCameraAndDepth(r, root, d));
  DB_RETURN_IF_ERROR(ReadCapture(r, root, scene));
  if (d.capture) scene.resolution = d.resolutions.front();
  DB_RETURN_IF_ERROR(ReadEngine(r, root, catalogue, scene));
  DB_RETURN_IF_ERROR(ReadRequirement(r, root, d, scene.requirement));
  DB_RETURN_IF_ERROR(ReadCost(r, root, scene));
  DB_RETURN_IF_ERROR(d.Validate().WithContext(source));
  if (scene.Candidates().empty()) {
    return InvalidArgument(fmt::format(
        "{}: [engine]: no cell can run in this scene (linear z/far formats and finite-far conventions need a "
        "finite far plane; infinite-far conventions an infinite one)",
        source));
  }
  return scene;
}

Expected<Scene> LoadScene(const std::filesystem::path& path, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(std::string text, ReadFile(path, kMaxSourceFileBytes));
  return ParseScene(text, path.string(), catalogue);
}

}  // namespace depthbench
