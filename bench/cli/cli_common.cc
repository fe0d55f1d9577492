#include "bench/cli/cli_common.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "bench/backends/factory.h"
#include "bench/base/environment.h"
#include "bench/base/files.h"
#include "bench/base/interrupt.h"
#include "bench/base/resources.h"
#include "bench/choose/scene.h"
#include "bench/pipeline/projection_matrix.h"

namespace depthbench::cli {

void DomainFlags::Add(CLI::App& app) {
  app.add_option("--domain", domain, std::string(kDomainHelp) + ". The flags below narrow it")
      ->type_name("NAME|FILE")
      ->group("Domain");
  app.add_option("--near", near, "near plane: VALUE or MIN:MAX (log-uniform)")->type_name("RANGE")->group("Domain");
  app.add_option("--far", far, "far plane: VALUE or MIN:MAX, instead of --ratio")->type_name("RANGE")->group("Domain");
  app.add_option("--ratio", ratio,
                 "far/near ratio: VALUE, MIN:MAX, inf, or MIN:MAX,inf (log-uniform). Infinite-far conventions run "
                 "when inf is allowed")
      ->type_name("RANGE")
      ->group("Domain");
  app.add_option("--fov", fov, "vertical field of view in degrees: VALUE or MIN:MAX, in (0, 180) (uniform)")
      ->type_name("RANGE")
      ->group("Domain");
  app.add_option("--aspect", aspect, "aspect ratio width/height: VALUE or MIN:MAX (log-uniform)")
      ->type_name("RANGE")
      ->group("Domain");
  app.add_option("--eye-fov", eye_fov,
                 "an off-centre frustum, as a VR runtime gives each eye's (OpenXR's XrFovf): LEFT,RIGHT,UP,DOWN "
                 "angles in degrees from the view axis, left and down negative; replaces --fov and --aspect")
      ->type_name("L,R,U,D")
      ->group("Domain");
  app.add_option("--ortho", ortho,
                 "an orthographic projection (a directional light's shadow map, a CAD view): its view volume "
                 "LEFT,RIGHT,BOTTOM,TOP in view units, with --near and --far (or a finite --ratio) for its depth; "
                 "replaces --fov and --aspect, and runs the ortho-* conventions only")
      ->type_name("L,R,B,T")
      ->group("Domain");
  app.add_option("--jitter", jitter,
                 "TAA jitter: every frame's projection shifted by up to this many pixels in x and y (uniform), as "
                 "temporal anti-aliasing does (0 to 4; e.g. 0.5)")
      ->type_name("PIXELS")
      ->group("Domain");
  app.add_option("--projection", projection,
                 "the engine's projection matrix, API:LAYOUT:N0,...,N15 with API d3d, vulkan, metal, opengl "
                 "(clip depth [-1, 1]) or opengl-clip-control, LAYOUT column-major (GLM, GLSL, a D3D matrix in "
                 "memory) or row-major (as written on paper). Sets near, far, the field of view and its "
                 "off-centre terms, and runs only the depth convention the matrix stores (with the linear cells)")
      ->type_name("MATRIX")
      ->group("Domain");
  app.add_option("--camera-distance", camera_distance,
                 "camera distance from the world origin: VALUE or MIN:MAX (log-uniform; 0 puts the camera at the "
                 "origin; 0:MAX puts a quarter of the frames there)")
      ->type_name("RANGE")
      ->group("Domain");
  app.add_option("--depth", eye_depth, "eye-depth range of interest in world units: VALUE or MIN:MAX")
      ->type_name("RANGE")
      ->group("Domain");
  app.add_option("--resolution", resolution, "render targets WIDTHxHEIGHT, several comma-separated")
      ->type_name("WxH")
      ->group("Domain");
  app.add_option("--production", production,
                 "how the stored depth is produced: float32 (default: as a GPU does, from the float32 constants "
                 "an engine uploads) or exact (the exact depth rounded once: the formats and variants alone)")
      ->type_name("MODEL")
      ->group("Domain");
  app.add_option("--pipeline", pipeline,
                 "compute (default: a compute shader reads the stored depths the host produced, and computes the "
                 "interpolated rays per pixel) or raster (a graphics pipeline draws geometry through every sample's "
                 "point into a real depth or G-buffer target with the float32 view-projection matrix, then a "
                 "full-screen or light-volume pass fetches the texel and gets its rays from the vertex stage; on "
                 "the CPU backend, the host's model of the same)")
      ->type_name("PIPELINE")
      ->group("Domain");
  app.add_option("--constants", constants,
                 "how the per-frame shader constants are computed: exact (default: exactly, rounded once to "
                 "float32) or float32 (as an engine does: float32 view and projection matrices, their product and "
                 "its 4x4 inverse in float32, every other constant derived from them in float32; the projection's "
                 "A and B also produce the depth)")
      ->type_name("MODEL")
      ->group("Domain");
}

bool IsSceneFile(const std::string& name_or_file) {
  return name_or_file.find('/') != std::string::npos || name_or_file.ends_with(".toml");
}

Expected<Domain> DomainByName(const std::string& name_or_file, const Catalogue& catalogue) {
  if (!IsSceneFile(name_or_file)) {
    Expected<Domain> named = NamedDomain(name_or_file);
    if (!named.ok()) return named.status().WithContext("--domain");
    return named;
  }
  DB_ASSIGN_OR_RETURN(const Scene scene, LoadScene(name_or_file, catalogue));
  return scene.domain;
}

Expected<Domain> DomainFlags::Apply(Domain d, const Catalogue& catalogue) const {
  if (!domain.empty()) DB_RETURN_IF_ERROR(StoreInto(DomainByName(domain, catalogue), d));
  const bool narrowed =
      !(near.empty() && far.empty() && ratio.empty() && fov.empty() && aspect.empty() && camera_distance.empty() &&
        eye_depth.empty() && resolution.empty() && production.empty() && constants.empty() && pipeline.empty() &&
        eye_fov.empty() && ortho.empty() && jitter.empty() && projection.empty());
  if (narrowed) d.name += " (narrowed)";
  if (!production.empty()) {
    DB_RETURN_IF_ERROR(StoreInto(ParseProductionModel(production), d.production).WithContext("--production"));
  }
  if (!constants.empty()) {
    DB_RETURN_IF_ERROR(StoreInto(ParseConstantsModel(constants), d.constants).WithContext("--constants"));
  }
  if (pipeline == "raster") {
    if (!production.empty() && d.production != ProductionModel::kRaster) {
      return InvalidArgument("--pipeline raster produces depth as the rasterizer does; it takes no --production");
    }
    d.production = ProductionModel::kRaster;
  } else if (pipeline == "compute") {
    if (d.production == ProductionModel::kRaster) d.production = ProductionModel::kFloat32;
  } else if (!pipeline.empty()) {
    return InvalidArgument(fmt::format("--pipeline: '{}' is not one of compute, raster", pipeline));
  }
  if (!projection.empty()) {
    if (!fov.empty() || !aspect.empty() || !eye_fov.empty() || !ortho.empty() || !near.empty() || !far.empty() ||
        !ratio.empty()) {
      return InvalidArgument("--projection sets near, far and the field of view or view volume; it takes no --fov, "
                             "--aspect, --eye-fov, --ortho, --near, --far or --ratio");
    }
    DB_ASSIGN_OR_RETURN(const ProjectionMatrix matrix, ParseProjectionFlag(projection));
    DB_ASSIGN_OR_RETURN(const ProjectionFacts facts, ReadProjectionMatrix(matrix));
    DB_RETURN_IF_ERROR(ApplyProjection(facts, d).WithContext("--projection"));
    d.depth_convention = facts.convention;
  }
  if (!eye_fov.empty()) {
    if (!fov.empty() || !aspect.empty()) return InvalidArgument("--eye-fov replaces --fov and --aspect");
    DB_RETURN_IF_ERROR(StoreInto(ParseEyeFov(eye_fov, "--eye-fov"), d.eye_fov.emplace()));
  }
  if (!ortho.empty()) {
    if (!fov.empty() || !aspect.empty() || !eye_fov.empty()) {
      return InvalidArgument("--ortho replaces --fov, --aspect and --eye-fov");
    }
    DB_RETURN_IF_ERROR(StoreInto(ParseViewVolume(ortho, "--ortho"), d.orthographic.emplace()));
    d.eye_fov.reset();
    // An orthographic projection has no infinite far plane: an unset far
    // keeps the domain's finite ratios.
    if (far.empty() && ratio.empty()) d.infinite_far = false;
  }
  if (!jitter.empty()) {
    DB_RETURN_IF_ERROR(StoreInto(ParseNumber(jitter, "--jitter"), d.jitter));
    if (!(d.jitter >= 0.0 && d.jitter <= kMostJitterPixels)) {
      return InvalidArgument(fmt::format("--jitter: {} pixels is out of range; allowed [0, {:g}] pixels", jitter,
                                         kMostJitterPixels));
    }
  }
  if (!near.empty()) DB_RETURN_IF_ERROR(StoreInto(ParseRange(near, "--near", kNearLimits), d.near));
  if (!far.empty() && !ratio.empty()) return InvalidArgument("--far and --ratio cannot be used together");
  if (!far.empty()) {
    DB_ASSIGN_OR_RETURN(Range f, ParseRange(far, "--far", kFarLimits));
    d.far = f;
    d.finite_far = true;
    d.infinite_far = false;
  }
  if (!ratio.empty()) DB_RETURN_IF_ERROR(ParseRatioInto(ratio, d));
  if (!fov.empty()) DB_RETURN_IF_ERROR(StoreInto(ParseRange(fov, "--fov", kFovLimits), d.fov_degrees));
  if (!aspect.empty()) DB_RETURN_IF_ERROR(StoreInto(ParseRange(aspect, "--aspect", kAspectLimits), d.aspect));
  if (!camera_distance.empty()) {
    DB_RETURN_IF_ERROR(
        StoreInto(ParseRange(camera_distance, "--camera-distance", kCameraDistanceLimits), d.camera_distance));
  }
  if (!eye_depth.empty()) {
    DB_ASSIGN_OR_RETURN(Range z, ParseRange(eye_depth, "--depth", kEyeDepthLimits));
    d.eye_depth = z;
  }
  if (!resolution.empty()) {
    DB_ASSIGN_OR_RETURN(d.resolutions, ParseResolutions(resolution, "--resolution"));
  }
  Status valid = d.Validate();
  if (!valid.ok()) return valid;
  return d;
}

Expected<std::vector<std::string>> DomainFlags::DescribeProjection() const {
  if (projection.empty()) return std::vector<std::string>{};
  DB_ASSIGN_OR_RETURN(const ProjectionMatrix matrix, ParseProjectionFlag(projection));
  DB_ASSIGN_OR_RETURN(const ProjectionFacts facts, ReadProjectionMatrix(matrix));
  return facts.Describe();
}

void CellFlags::Add(CLI::App& app) {
  app.add_option("--variant", variants, "variants to run (several, or comma-separated; default all)")
      ->delimiter(',')
      ->group("Cells");
  app.add_option("--convention", conventions,
                 "depth conventions to run (default all): standard and reversed (and -inf) are what Direct3D, "
                 "Vulkan and Metal store, and OpenGL after glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE); the -gl ones "
                 "are OpenGL's default [-1, 1] clip depth; linear is a shader's G-buffer write ('depthbench list' "
                 "says what each API must do)")
      ->delimiter(',')
      ->group("Cells");
  app.add_option("--format", formats, "storage formats to run (default all)")->delimiter(',')->group("Cells");
}

Expected<std::vector<Cell>> CellFlags::Select(const Catalogue& catalogue) const {
  CellFilter filter;
  for (const auto& v : variants) {
    DB_RETURN_IF_ERROR(StoreInto(catalogue.ParseVariant(v), filter.variants.emplace_back()));
  }
  for (const auto& c : conventions) {
    DB_RETURN_IF_ERROR(StoreInto(ParseConvention(c), filter.conventions.emplace_back()));
  }
  for (const auto& f : formats) DB_RETURN_IF_ERROR(StoreInto(ParseFormat(f), filter.formats.emplace_back()));
  std::vector<Cell> cells = filter.CellsOf(catalogue);
  if (cells.empty()) {
    return InvalidArgument(
        "no cell matches these filters: hardware-depth variants (inverse_vp, divide, reciprocal, pq) read "
        "d16_unorm/x8_d24_unorm/d32_sfloat under the eight projective conventions; frustum_ray, volume_ray "
        "and tan_aspect read r32_sfloat/r16_sfloat/r16_unorm under 'linear'; eye_ray reads r32_sfloat_viewz "
        "under 'linear' (see 'depthbench list')");
  }
  return cells;
}

void BackendFlags::Add(CLI::App& app, bool allow_several) {
  auto* option = app.add_option(
      "--backend", backends,
      allow_several ? "backends to run: cpu, vulkan (default both); vulkan:no-contraction, vulkan:exact-division "
                      "or vulkan:no-contraction+exact-division run the Vulkan backend with fused "
                      "multiply-adds forbidden or divisions correctly rounded (reports/gpu-probes); "
                      "vulkan:worst-division with every division 2 to 2.5 ulp off, as far as Vulkan allows "
                      "(docs/bounds.md)"
                    : "backend to run: cpu or vulkan");
  option->delimiter(',')->group("Backends");
  if (!allow_several) option->expected(1);
  backend_option = option;
  app.add_option("--device", device,
                 "Vulkan device: a case-insensitive part of its name (default: Mesa lavapipe, 'llvmpipe'); "
                 "'depthbench list' shows the devices")
      ->group("Backends");
  app.add_option("--shaders", shaders,
                 "directory of the reconstruction shaders, compiled at run time (default: the source tree's "
                 "shaders/); an edited copy runs with no rebuild")
      ->group("Backends");
  app.add_flag("--validate", validate, "enable the Vulkan validation layer and fail on its messages")
      ->group("Backends");
}

BackendSet::BackendSet(std::vector<std::unique_ptr<Backend>> owned) : owned_(std::move(owned)) {
  for (const auto& backend : owned_) pointers_.push_back(backend.get());
}

Expected<BackendSet> BackendFlags::Make(const Catalogue& catalogue) const {
  std::vector<std::unique_ptr<Backend>> out;
  BackendOptions options{device, shaders, validate};
  std::vector<std::string> names = backends;
  if (catalogue.has_user_variants() && backend_option != nullptr && backend_option->count() == 0 && names.size() > 1) {
    names = {"vulkan"};
    std::cerr << "note: --variant-file: running on the vulkan backend alone (the cpu backend cannot run a "
                 "shader file; --backend chooses)\n";
  }
  for (const std::string& name : names) {
    for (const auto& existing : out) {
      if (existing->name() == name) return InvalidArgument(fmt::format("--backend {} is given twice", name));
    }
    DB_ASSIGN_OR_RETURN(auto backend, MakeBackend(name, options));
    out.push_back(std::move(backend));
  }
  if (out.empty()) return InvalidArgument("--backend: no backend given; allowed: cpu, vulkan");
  return BackendSet(std::move(out));
}

Expected<std::uint64_t> ParseCount(const std::string& text, const std::string& what) {
  char* end = nullptr;
  double value = std::strtod(text.c_str(), &end);
  // Decimal only: strtod also reads hexadecimal (0x10), "inf" and "nan".
  const bool decimal = text.find_first_not_of("0123456789.eE+") == std::string::npos;
  if (text.empty() || !decimal || end != text.c_str() + text.size() || !(value >= 1.0) || value > 1e15 ||
      value != std::floor(value)) {
    return InvalidArgument(fmt::format("{}: '{}' is not a whole number from 1 to 1e15", what, text));
  }
  return static_cast<std::uint64_t>(value);
}

Status WriteSummary(const std::string& path, const std::string& markdown) {
  if (!path.empty()) DB_RETURN_IF_ERROR(WriteFileAtomically(path, markdown).WithContext("--summary"));
  const std::string job_summary = StepSummaryFile();
  if (!job_summary.empty()) {
    DB_RETURN_IF_ERROR(AppendToFile(job_summary, markdown + "\n").WithContext("GITHUB_STEP_SUMMARY"));
  }
  return Status::Ok();
}

namespace {

// Whether two paths name one file: the same inode where both exist, else
// the same place once links and relative parts are resolved.
bool SameFile(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec) && !ec;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  if (ec) return false;
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return !ec && ca == cb;
}

}  // namespace

FileRoles& FileRoles::Input(const std::string& path, std::string flag) {
  if (!path.empty() && path != kStandardOutputName) inputs_.push_back({path, std::move(flag)});
  return *this;
}

FileRoles& FileRoles::Output(const std::string& path, std::string flag) {
  if (!path.empty() && path != kStandardOutputName) outputs_.push_back({path, std::move(flag)});
  return *this;
}

Status FileRoles::Check() const {
  for (std::size_t k = 0; k < outputs_.size(); ++k) {
    const Named& out = outputs_[k];
    for (const Named& in : inputs_) {
      if (SameFile(out.path, in.path)) {
        return InvalidArgument(fmt::format("{} '{}' names the file read as {} '{}': writing it would replace it; "
                                           "write somewhere else",
                                           out.flag, out.path, in.flag, in.path));
      }
    }
    for (std::size_t j = 0; j < k; ++j) {
      if (SameFile(out.path, outputs_[j].path)) {
        return InvalidArgument(fmt::format("{} '{}' and {} '{}' are one file: one would be lost; give each its own",
                                           outputs_[j].flag, outputs_[j].path, out.flag, out.path));
      }
    }
  }
  return Status::Ok();
}

Status CheckWritable(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  const bool to_standard_output_allowed = what == "--json";
  if (to_standard_output_allowed && path == kStandardOutputName) return Status::Ok();
  Expected<fs::path> target = OutputTarget(path);
  if (!target.ok()) {
    const Status refused = target.status().WithContext(what);
    if (!to_standard_output_allowed) return refused;
    return Status(refused.code(), refused.message() + " (give - to write to standard output)");
  }
  const fs::path dir = target->parent_path();
  DB_RETURN_IF_ERROR(CheckDirectory(dir, "directory").WithContext(fmt::format("{}: cannot write '{}'", what, path)));
  // Create (and remove) a file beside the target: the only test that holds
  // for every case, including root (for whom access() says yes to any
  // directory) and pseudo or read-only file systems. The name is the one
  // WriteFileAtomically uses for its temporary file, with another suffix;
  // like that file, a second signal removes it.
  const fs::path probe = dir / ("." + target->filename().string() + ".probe." + std::to_string(::getpid()));
  const TemporaryFileGuard guard(probe);
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    return IoError(fmt::format("{}: cannot write '{}': cannot create a file in directory '{}': {}", what, path,
                               dir.string(), std::strerror(errno)));
  }
  ::close(fd);
  std::error_code ec;
  fs::remove(probe, ec);
  return Status::Ok();
}

std::function<void(std::size_t, std::size_t)> CellsBoundProgress(Progress& progress) {
  return [&progress](std::size_t done, std::size_t total) {
    progress.Update(static_cast<double>(done) / static_cast<double>(total),
                    fmt::format("{} of {} cells bounded", done, total));
  };
}

Expected<std::vector<bound::CellBound>> ProveCells(const Domain& domain, const std::vector<Cell>& cells,
                                                   const std::string& shaders, int splits, bool quiet,
                                                   const char* label) {
  std::filesystem::path shader_dir = shaders;
  if (shader_dir.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("shaders"), shader_dir));
  bound::BoundOptions options;
  options.splits = splits;
  Progress progress(label, StderrIsTerminal(), quiet);
  DB_ASSIGN_OR_RETURN(std::vector<bound::CellBound> bounds,
                      bound::BoundCells(domain, cells, shader_dir, options, CellsBoundProgress(progress)));
  progress.Finish(fmt::format("{} cells bounded", bounds.size()));
  return bounds;
}

bool StderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

int ReportError(const Status& status) {
  if (status.code() == StatusCode::kInterrupted) {
    std::cerr << "depthbench: " << status.message() << "\n";
    return 128 + InterruptSignal();
  }
  std::cerr << "depthbench: error: " << status.message() << "\n";
  return kExitCannotRun;
}

}  // namespace depthbench::cli
