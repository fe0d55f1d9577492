#include "bench/fuzz/fuzz_case.h"

#include <cmath>
#include <cstring>
#include <type_traits>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/numerics/formulas.h"

namespace depthbench {
namespace {

const char* PickName(DepthPick p) {
  switch (p) {
    case DepthPick::kEyeDepth: return "eye_depth";
    case DepthPick::kStoredZero: return "stored_zero";
    case DepthPick::kStoredOne: return "stored_one";
    case DepthPick::kStoredAfterZero: return "stored_after_zero";
    case DepthPick::kStoredBeforeOne: return "stored_before_one";
  }
  return "?";
}

Expected<DepthPick> ParsePick(const JsonReader& r) {
  DB_ASSIGN_OR_RETURN(std::string name, r.String());
  for (DepthPick p : {DepthPick::kEyeDepth, DepthPick::kStoredZero, DepthPick::kStoredOne, DepthPick::kStoredAfterZero,
                      DepthPick::kStoredBeforeOne}) {
    if (name == PickName(p)) return p;
  }
  return r.Error(
      fmt::format("unknown depth pick '{}'; allowed: eye_depth, stored_zero, stored_one, "
                  "stored_after_zero, stored_before_one",
                  name));
}

// Reads a number that must lie in (lo, hi] or [lo, hi].
Expected<double> NumberIn(const JsonReader& r, const std::string& key, double lo, double hi, bool lo_open,
                          const char* allowed) {
  DB_ASSIGN_OR_RETURN(JsonReader field, r.Field(key));
  DB_ASSIGN_OR_RETURN(double x, field.Number());
  if (!(lo_open ? x > lo : x >= lo) || !(x <= hi)) {
    return field.Error(fmt::format("{} is out of range; allowed {}", x, allowed));
  }
  return x;
}

Expected<std::vector<double>> Numbers(const JsonReader& r, const std::string& key, std::size_t n) {
  DB_ASSIGN_OR_RETURN(JsonReader field, r.Field(key));
  DB_ASSIGN_OR_RETURN(std::size_t size, field.ArraySize());
  if (size != n) return field.Error(fmt::format("expected {} numbers, found {}", n, size));
  std::vector<double> out;
  for (std::size_t i = 0; i < n; ++i) {
    DB_ASSIGN_OR_RETURN(JsonReader e, field.Element(i));
    DB_ASSIGN_OR_RETURN(double x, e.Number());
    if (!std::isfinite(x)) return e.Error("must be a finite number");
    out.push_back(x);
  }
  return out;
}

Expected<FuzzCase> CaseFromJson(const JsonReader& r) {
  FuzzCase c;
  DB_ASSIGN_OR_RETURN(JsonReader frame, r.Field("frame"));
  Frame& f = c.frame;
  DB_ASSIGN_OR_RETURN(f.fov_y_degrees, NumberIn(frame, "fov_degrees", 0.0, 180.0, true, "(0, 180) degrees"));
  if (f.fov_y_degrees >= 180.0) return frame.Error("fov_degrees: must be below 180");
  DB_ASSIGN_OR_RETURN(f.aspect, NumberIn(frame, "aspect", 0.0, 1e6, true, "(0, 1e6]"));
  DB_ASSIGN_OR_RETURN(f.near, NumberIn(frame, "near", 0.0, 1e30, true, "(0, 1e30]"));
  DB_ASSIGN_OR_RETURN(JsonReader far_field, frame.Field("far"));
  DB_ASSIGN_OR_RETURN(f.far, far_field.Number());
  if (!(f.far > f.near)) return far_field.Error(fmt::format("must be greater than near ({}) or \"inf\"", f.near));
  std::optional<Range> interest;
  if (frame.Has("eye_depth_range")) {
    DB_ASSIGN_OR_RETURN(std::vector<double> range, Numbers(frame, "eye_depth_range", 2));
    if (!(range[0] > 0 && range[0] <= range[1])) {
      return frame.Error("eye_depth_range: expected [min, max] with 0 < min <= max");
    }
    interest = Range{range[0], range[1]};
  }
  CompleteFrame(f, interest);
  if (frame.Has("lens_centre")) {
    // An off-centre lens, in tangents at unit depth (sampler.h's Frame).
    DB_ASSIGN_OR_RETURN(std::vector<double> centre, Numbers(frame, "lens_centre", 2));
    if (!(std::abs(centre[0]) < 1e6 && std::abs(centre[1]) < 1e6)) {
      return frame.Error("lens_centre: expected [x, y], each within (-1e6, 1e6)");
    }
    f.centre_x = centre[0];
    f.centre_y = centre[1];
  }
  DB_ASSIGN_OR_RETURN(std::vector<double> rotation, Numbers(frame, "rotation", 9));
  for (int col = 0; col < 3; ++col) {
    for (int row = 0; row < 3; ++row) f.rotation[col][row] = rotation[col * 3 + row];
  }
  const glm::dmat3 gram = glm::transpose(f.rotation) * f.rotation;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      // A rotation stored with 17 digits is orthonormal to about 1e-16.
      if (std::abs(gram[i][j] - (i == j ? 1.0 : 0.0)) > 1e-12) {
        return frame.Error("rotation: the 9 numbers (columns: camera x, y, z axes) are not an orthonormal matrix");
      }
    }
  }
  DB_ASSIGN_OR_RETURN(std::vector<double> camera, Numbers(frame, "camera_position", 3));
  for (int k = 0; k < 3; ++k) {
    if (static_cast<double>(static_cast<float>(camera[k])) != camera[k]) {
      return frame.Error("camera_position: each component must be a float32 value (an engine stores it so)");
    }
    f.camera_position[k] = camera[k];
  }
  DB_ASSIGN_OR_RETURN(std::uint64_t width, frame.Unsigned("width"));
  DB_ASSIGN_OR_RETURN(std::uint64_t height, frame.Unsigned("height"));
  if (width < 1 || width > 65535 || height < 1 || height > 65535) {
    return frame.Error("width, height: allowed 1 to 65535 pixels");
  }
  f.width = static_cast<std::uint32_t>(width);
  f.height = static_cast<std::uint32_t>(height);
  DB_ASSIGN_OR_RETURN(f.volume_depth,
                      NumberIn(frame, "volume_depth", f.near, f.depth_limit, false, "[near, the largest eye depth]"));

  DB_ASSIGN_OR_RETURN(JsonReader sample, r.Field("sample"));
  PixelSample& s = c.sample;
  DB_ASSIGN_OR_RETURN(std::uint64_t x, sample.Unsigned("x"));
  DB_ASSIGN_OR_RETURN(std::uint64_t y, sample.Unsigned("y"));
  if (x >= f.width || y >= f.height) {
    return sample.Error(fmt::format("pixel ({}, {}) is outside the {}x{} render target", x, y, f.width, f.height));
  }
  s.x = static_cast<std::uint32_t>(x);
  s.y = static_cast<std::uint32_t>(y);
  DB_ASSIGN_OR_RETURN(JsonReader pick, sample.Field("pick"));
  DB_ASSIGN_OR_RETURN(s.pick, ParsePick(pick));
  if (s.pick == DepthPick::kEyeDepth) {
    DB_ASSIGN_OR_RETURN(s.eye_depth, NumberIn(sample, "eye_depth", f.near, f.depth_limit, false,
                                              "[near, far] (or near * 1e8 when far is infinite)"));
  }
  return c;
}

nlohmann::json CaseToJson(const FuzzCase& c) {
  const Frame& f = c.frame;
  nlohmann::json rotation = nlohmann::json::array();
  for (int col = 0; col < 3; ++col) {
    for (int row = 0; row < 3; ++row) rotation.push_back(f.rotation[col][row]);
  }
  nlohmann::json frame = {{"fov_degrees", f.fov_y_degrees},
                          {"aspect", f.aspect},
                          {"near", f.near},
                          {"far", JsonNumber(f.far)},
                          {"rotation", rotation},
                          {"camera_position", {f.camera_position.x, f.camera_position.y, f.camera_position.z}},
                          {"width", f.width},
                          {"height", f.height},
                          {"volume_depth", f.volume_depth}};
  if (f.centre_x != 0.0 || f.centre_y != 0.0) frame["lens_centre"] = {f.centre_x, f.centre_y};
  if (f.depth_restricted) frame["eye_depth_range"] = {f.eye_depth_min, f.eye_depth_max};
  nlohmann::json sample = {{"x", c.sample.x}, {"y", c.sample.y}, {"pick", PickName(c.sample.pick)}};
  if (c.sample.pick == DepthPick::kEyeDepth) sample["eye_depth"] = c.sample.eye_depth;
  return {{"frame", frame}, {"sample", sample}};
}

}  // namespace

Domain FuzzDomain() {
  Domain d;
  d.fov_degrees = {0.01, 179.9};
  d.aspect = {1e-3, 1e3};
  d.near = {1e-7, 10.0};
  d.ratio = {10.0, 1e9};
  d.camera_distance = {0.0, 1e7};
  return d;
}

double& UnitOf(FuzzPoint& p, int k) {
  // Both unit structs are plain arrays of doubles in declaration order.
  // The jitter units come last and are left out (the fuzz domain has none).
  static_assert(std::is_standard_layout_v<FrameUnits> && sizeof(FrameUnits) == 15 * sizeof(double));
  static_assert(std::is_standard_layout_v<SampleUnits> && sizeof(SampleUnits) == 5 * sizeof(double));
  return k < 13 ? reinterpret_cast<double*>(&p.frame)[k] : reinterpret_cast<double*>(&p.sample)[k - 13];
}

FuzzPoint DecodePoint(std::span<const std::uint8_t> bytes) {
  FuzzPoint p;
  for (int k = 0; k < kFuzzUnits; ++k) {
    std::uint32_t word = 0;
    for (int b = 0; b < 4; ++b) {
      const std::size_t at = static_cast<std::size_t>(k) * 4 + b;
      if (at < bytes.size()) word |= static_cast<std::uint32_t>(bytes[at]) << (8 * b);
    }
    // Units live in [0, 1); the all-ones word reaches the top of each range.
    UnitOf(p, k) = std::min(word / 4294967295.0, 1.0 - 0x1.0p-53);
  }
  return p;
}

std::vector<std::uint8_t> EncodePoint(const FuzzPoint& point) {
  FuzzPoint p = point;
  std::vector<std::uint8_t> out(kFuzzPointBytes);
  for (int k = 0; k < kFuzzUnits; ++k) {
    const double u = std::clamp(UnitOf(p, k), 0.0, 1.0);
    const auto word = static_cast<std::uint32_t>(std::llround(u * 4294967295.0));
    for (int b = 0; b < 4; ++b) out[k * 4 + b] = static_cast<std::uint8_t>(word >> (8 * b));
  }
  return out;
}

FuzzCase CaseAt(const Domain& domain, const FuzzPoint& point) {
  FuzzCase c;
  c.frame = FrameFromUnits(domain, point.frame, 0);
  c.sample = SampleFromUnits(point.sample, c.frame, 0);
  return c;
}

CaseSource::CaseSource(std::vector<Frame> frames, std::vector<PixelSample> samples)
    : frames_(std::move(frames)), samples_(std::move(samples)) {}

CaseSource::CaseSource(const FuzzCase& single) : frames_{single.frame}, samples_(kSamplesPerFrame, single.sample) {}

Frame CaseSource::FrameAt(std::uint64_t frame_index) const {
  Frame f = frames_.at(frame_index);
  f.index = frame_index;
  return f;
}

PixelSample CaseSource::SampleAt(std::uint64_t index, const Frame&) const {
  PixelSample s = samples_.at(index);
  s.index = index;
  return s;
}

void PointBatch::AddFrame(const FuzzPoint& base, const std::function<FuzzPoint(std::uint32_t)>& sample_point) {
  const auto f = static_cast<std::uint32_t>(frames_.size());
  const Frame frame = FrameFromUnits(domain_, base.frame, f);
  frames_.push_back(frame);
  for (std::uint32_t s = 0; s < kSamplesPerFrame; ++s) {
    const FuzzPoint p = sample_point(s);
    points_.push_back(p);
    samples_.push_back(SampleFromUnits(p.sample, frame, std::uint64_t{f} * kSamplesPerFrame + s));
  }
}

bool CellRunsOn(const Cell& cell, const Frame& frame) {
  const ConventionInfo& c = Info(cell.convention);
  const bool needs_finite =
      (c.hardware && (c.bits & f32::DB_CONVENTION_INFINITE) == 0u) || Info(cell.format).stores == DepthInput::kLinear;
  return frame.finite() || !needs_finite;
}

nlohmann::json ReproFileToJson(const ReproFile& file) {
  nlohmann::json cells = nlohmann::json::array();
  for (const Cell& c : file.cells) cells.push_back(c.Name());
  nlohmann::json out =
      WithSchema(kReproSchema, {{"cells", cells}, {"backends", file.backends}, {"case", CaseToJson(file.fuzz_case)}});
  if (!file.finding.is_null()) out["finding"] = file.finding;
  return out;
}

Expected<ReproFile> ReproFileFromJson(const nlohmann::json& json, const std::string& source) {
  const JsonReader r(json, source);
  DB_RETURN_IF_ERROR(r.CheckSchema(kReproSchema));
  ReproFile file;
  DB_RETURN_IF_ERROR(r.ForEach("cells", [&](const JsonReader& e) -> Status {
    DB_ASSIGN_OR_RETURN(std::string name, e.String());
    auto cell = ParseCell(name);
    if (!cell.ok()) return e.Error(cell.status().message());
    file.cells.push_back(*cell);
    return Status::Ok();
  }));
  if (file.cells.empty()) {
    DB_ASSIGN_OR_RETURN(const JsonReader cells, r.Field("cells"));
    return cells.Error("names no cell");
  }
  if (r.Has("backends")) {
    DB_RETURN_IF_ERROR(r.ForEach("backends", [&](const JsonReader& e) -> Status {
      DB_ASSIGN_OR_RETURN(std::string name, e.String());
      file.backends.push_back(name);
      return Status::Ok();
    }));
  }
  DB_ASSIGN_OR_RETURN(JsonReader fuzz_case, r.Field("case"));
  DB_ASSIGN_OR_RETURN(file.fuzz_case, CaseFromJson(fuzz_case));
  for (const Cell& cell : file.cells) {
    if (!CellRunsOn(cell, file.fuzz_case.frame)) {
      return r.Error(fmt::format("cell {} needs a finite far plane, and the case's far is infinite", cell.Name()));
    }
  }
  if (r.Has("finding")) file.finding = json["finding"];
  return file;
}

Expected<ReproFile> ReadReproFile(const std::filesystem::path& path) {
  DB_ASSIGN_OR_RETURN(const nlohmann::json json, ReadJsonFile(path));
  return ReproFileFromJson(json, path.string());
}

Status WriteReproFile(const std::filesystem::path& path, const ReproFile& file) {
  return WriteFileAtomically(path, ReproFileToJson(file).dump(1) + "\n");
}

}  // namespace depthbench
