#include "bench/sweep/repro.h"

#include <cmath>

#include <fmt/format.h>

#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/captured.h"
#include "bench/pipeline/judge.h"
#include "bench/pipeline/stats.h"
#include "bench/pipeline/user_variant.h"
#include "bench/sweep/sweep.h"

namespace depthbench {
namespace {

const char* StatusName(ReferenceStatus s) {
  switch (s) {
    case ReferenceStatus::kJudged: return "judged";
    case ReferenceStatus::kDegenerate: return "degenerate (the point is the camera or at infinity)";
    case ReferenceStatus::kOutside: return "outside the frustum (only NaN/Inf count)";
    case ReferenceStatus::kUndrawn: return "undrawn (the rasterizer left the texel as cleared; not judged)";
  }
  return "?";
}

const char* PickName(DepthPick p) {
  switch (p) {
    case DepthPick::kEyeDepth: return "eye depth";
    case DepthPick::kStoredZero: return "stored value 0";
    case DepthPick::kStoredOne: return "stored value 1";
    case DepthPick::kStoredAfterZero: return "first stored value above 0";
    case DepthPick::kStoredBeforeOne: return "last stored value below 1";
  }
  return "?";
}

}  // namespace

Expected<Repro> Reproduce(std::uint64_t seed, std::uint64_t index, const Domain& domain, std::span<const Cell> cells,
                          std::span<Backend* const> backends) {
  DB_RETURN_IF_ERROR(domain.Validate());
  const std::unique_ptr<const SampleSource> source = SourceFor(seed, domain);
  if (index >= SamplesFor(index + 1, *source)) {
    return InvalidArgument(fmt::format("--index {}: the capture has {} samples", index, SamplesFor(0, *source)));
  }
  DB_ASSIGN_OR_RETURN(Repro repro, ReproduceFrom(*source, index, cells, backends));
  repro.seed = seed;
  repro.domain = domain;
  repro.origin = fmt::format("sample {} of seed {}", index, seed);
  return repro;
}

Expected<Repro> ReproduceFrom(const SampleSource& sampler, std::uint64_t index, std::span<const Cell> cells,
                              std::span<Backend* const> backends) {
  if (cells.empty()) return InvalidArgument("no cell to reproduce");
  const RunLayout layout = MakeRunLayout(cells);
  const BatchBuilder builder(sampler, layout.encodings);
  ThreadPool pool(1);
  Batch batch;
  builder.Build(index, 1, batch, pool);
  for (Backend* backend : backends) {
    DB_RETURN_IF_ERROR(backend->Prepare(layout.cells, PassKindOf(sampler.production())));
  }
  if (Backend* renderer = DepthRenderer(sampler.production(), backends)) {
    DB_RETURN_IF_ERROR(AdoptRenderedDepths(*renderer, builder, batch, pool));
  }
  const Frame& frame = batch.frames[0];
  const PixelSample sample = sampler.SampleAt(index, frame);

  Repro repro;
  repro.index = index;
  const std::string lens =
      frame.orthographic
          ? fmt::format("orthographic, half extents {:.9g} x {:.9g}", frame.aspect * frame.tan_half_fov_y,
                        frame.tan_half_fov_y)
          : fmt::format("fov {:.9g} deg, aspect {:.9g}", frame.fov_y_degrees, frame.aspect);
  repro.frame = fmt::format(
      "frame {}: {}, near {:.9g}, far {:.9g} (far/near {:.4g}), camera ({:.9g}, {:.9g}, {:.9g}) at {:.4g} from the "
      "origin, render target {}x{}",
      frame.index, lens, frame.near, frame.far, frame.ratio(), frame.camera_position.x, frame.camera_position.y,
      frame.camera_position.z, frame.camera_distance(), frame.width, frame.height);
  if (frame.centre_x != 0.0 || frame.centre_y != 0.0) {
    repro.frame += fmt::format(", lens centre ({:.9g}, {:.9g})", frame.centre_x, frame.centre_y);
  }
  repro.sample = sample.pick == DepthPick::kEyeDepth
                     ? fmt::format("pixel ({}, {}), eye depth {:.17g}", sample.x, sample.y, sample.eye_depth)
                     : fmt::format("pixel ({}, {}), {}", sample.x, sample.y, PickName(sample.pick));

  std::vector<std::vector<float>> outputs(backends.size());
  std::vector<std::uint32_t> every(layout.cells.size());
  for (std::uint32_t c = 0; c < every.size(); ++c) every[c] = c;
  std::vector<float> scratch;
  for (std::size_t b = 0; b < backends.size(); ++b) {
    DB_ASSIGN_OR_RETURN(std::span<const float> out, backends[b]->Run(batch, every, scratch));
    outputs[b].assign(out.begin(), out.end());
  }
  for (std::size_t c = 0; c < layout.cells.size(); ++c) {
    const CellPlan& plan = layout.cells[c];
    const ReferenceSample r = batch.reference.Get(plan.depth_slot);
    ReproCell cell;
    cell.cell = plan.cell;
    cell.code = batch.codes[plan.depth_slot];
    cell.fetched = batch.depths[plan.depth_slot];
    cell.true_depth = r.true_depth;
    cell.denoted_depth = r.denoted_depth;
    cell.storage = std::sqrt(batch.reference.storage_square[plan.depth_slot]);
    cell.production = std::sqrt(batch.reference.production_square[plan.depth_slot]);
    cell.stored_holdable = r.stored_holdable;
    cell.status = StatusName(r.status);
    for (std::size_t b = 0; b < backends.size(); ++b) {
      ReproCellOutput o;
      o.backend = backends[b]->name();
      for (int k = 0; k < 3; ++k) o.position[k] = outputs[b][c * 3 + k];  // one sample: components are adjacent
      o.nan = std::isnan(o.position[0]) || std::isnan(o.position[1]) || std::isnan(o.position[2]);
      o.inf = !o.nan && !(std::isfinite(o.position[0]) && std::isfinite(o.position[1]) && std::isfinite(o.position[2]));
      const SampleErrors e = ErrorsOf(r, batch.Ray(0), batch.Offset(0), frame.camera_position, o.position);
      o.total = std::sqrt(e.total_sq);
      o.arith = std::sqrt(e.arith_sq);
      o.absolute = std::sqrt(e.absolute_sq);
      cell.outputs.push_back(o);
    }
    repro.cells.push_back(std::move(cell));
  }
  return repro;
}

void PrintRepro(const Repro& repro, std::ostream& out) {
  out << fmt::format("{}\n{}\n{}\n", repro.origin, repro.frame, repro.sample);
  for (const ReproCell& c : repro.cells) {
    out << fmt::format(
        "\n{}: stored 0x{:08x} (fetched as {:.9g}); true eye depth {:.17g}, stored value denotes "
        "{:.17g} (production error {:.3g}, storage error {:.3g}); {}\n",
        c.cell.Name(), c.code, c.fetched, c.true_depth, c.denoted_depth, c.production, c.storage, c.status);
    for (const ReproCellOutput& o : c.outputs) {
      out << fmt::format("  {:>6}: ({:.9g}, {:.9g}, {:.9g})", o.backend, o.position[0], o.position[1], o.position[2]);
      if (o.nan || o.inf) {
        out << (o.nan ? "  NaN" : "  Inf")
            << (c.stored_holdable ? " (a finding: exact arithmetic on these inputs is finite)\n"
                                  : " (expected: the stored value denotes no point float32 can hold)\n");
      } else {
        out << fmt::format("  error {:.3g} ({:.1f} bits lost; shader {:.3g}), {:.3g} world units\n", o.total,
                           BitsLost(o.total), o.arith, o.absolute);
      }
    }
  }
}

nlohmann::json ReproToJson(const Repro& repro) {
  nlohmann::json cells = nlohmann::json::array();
  for (const ReproCell& c : repro.cells) {
    nlohmann::json outputs = nlohmann::json::array();
    for (const ReproCellOutput& o : c.outputs) {
      outputs.push_back({{"backend", o.backend},
                         {"position", {o.position[0], o.position[1], o.position[2]}},
                         {"nan", o.nan},
                         {"inf", o.inf},
                         {"relative_error", o.total},
                         {"bits_lost", BitsLost(o.total)},
                         {"arith_error", o.arith},
                         {"absolute_error", o.absolute}});
    }
    cells.push_back({{"cell", c.cell.Name()},
                     {"code", c.code},
                     {"fetched", c.fetched},
                     {"true_depth", c.true_depth},
                     {"denoted_depth", c.denoted_depth},
                     {"storage_error", c.storage},
                     {"production_error", c.production},
                     {"stored_holdable", c.stored_holdable},
                     {"status", c.status},
                     {"outputs", outputs}});
  }
  return {
      {"seed", repro.seed}, {"index", repro.index}, {"frame", repro.frame}, {"sample", repro.sample}, {"cells", cells}};
}

std::string ReproCommand(std::uint64_t seed, std::uint64_t index, const Domain& domain, const Cell& cell,
                         const std::string& backend) {
  const UserShader* user = cell.variant_info().user;
  return fmt::format("depthbench run --seed {} --index {} --backend {} {}--variant {} --convention {} --format {} {}",
                     seed, index, backend, user != nullptr ? "--variant-file " + user->path.string() + " " : "",
                     cell.variant_info().name, Info(cell.convention).name, Info(cell.format).name, domain.ToFlags());
}

}  // namespace depthbench
