#include "bench/gate/baseline.h"

#include <limits>

#include <fmt/format.h>

#include "bench/base/environment.h"
#include "bench/base/files.h"
#include "bench/base/json_reader.h"

namespace depthbench {
namespace {

using nlohmann::json;

BandFigures FiguresOf(const BandStats& band) {
  BandFigures f;
  const Summary total = Summarize(band, Metric::kTotal);
  const Summary arith = Summarize(band, Metric::kArith);
  f.total_p999 = BitsLost(total.p999);
  f.p999_interval_bits =
      std::max(f.total_p999 - BitsLost(total.p999_interval.low), BitsLost(total.p999_interval.high) - f.total_p999);
  f.total_max = BitsLost(total.max);
  f.arith_p999 = BitsLost(arith.p999);
  f.arith_max = BitsLost(arith.max);
  f.judged = band.finite;
  f.nan = band.nan;
  f.inf = band.inf;
  f.worst_index = total.worst_index;
  f.first_nonfinite_index = band.first_nonfinite_index;
  return f;
}

}  // namespace

Baseline BaselineFromResults(const Results& results, const std::string& backend) {
  Baseline b;
  b.backend = backend;
  for (const BackendRecord& r : results.run.backends)
    if (r.name == backend) b.device = r.device;
  b.version = results.run.version;
  b.commit = results.run.commit;
  b.made_at = results.run.started_at;
  b.plan = {results.run.seed, results.run.samples, results.run.samples_per_frame, results.run.domain};
  for (const CellResult& c : results.cells) {
    if (c.backend != backend) continue;
    CellFigures& figures = b.cells[c.cell.Name()];
    figures["all"] = FiguresOf(c.stats.All());
    for (const auto& [joint, stats] : c.stats.joint) {
      (void)stats;
      const int ratio = RatioOfJoint(joint), depth = DepthOfJoint(joint);
      figures.try_emplace("ratio " + RatioBandName(ratio), FiguresOf(c.stats.ForRatio(ratio)));
      figures.try_emplace("depth " + DepthBandName(depth), FiguresOf(c.stats.ForDepth(depth)));
    }
    for (const auto& [band, stats] : c.stats.distance) {
      figures["distance " + DistanceBandName(band)] = FiguresOf(stats);
    }
    for (const auto& [band, stats] : c.stats.coverage) {
      figures["coverage " + CoverageBandName(band)] = FiguresOf(stats);
    }
  }
  return b;
}

json SamplePlanToJson(const SamplePlan& plan) {
  return {{"seed", plan.seed},
          {"samples", plan.samples},
          {"samples_per_frame", plan.samples_per_frame},
          {"domain", DomainToJson(plan.domain)}};
}

Expected<SamplePlan> SamplePlanFromJson(const JsonReader& plan) {
  SamplePlan p;
  DB_ASSIGN_OR_RETURN(p.seed, plan.Unsigned("seed"));
  DB_ASSIGN_OR_RETURN(p.samples, plan.Unsigned("samples"));
  DB_ASSIGN_OR_RETURN(std::uint64_t per_frame, plan.Unsigned("samples_per_frame"));
  p.samples_per_frame = static_cast<std::uint32_t>(per_frame);
  DB_ASSIGN_OR_RETURN(JsonReader domain, plan.Field("domain"));
  DB_ASSIGN_OR_RETURN(p.domain, DomainFromJson(domain.json(), plan.source()));
  return p;
}

json BaselineToJson(const Baseline& b) {
  json cells = json::object();
  for (const auto& [name, figures] : b.cells) {
    json bands = json::object();
    for (const auto& [band, f] : figures) {
      bands[band] = {{"total_p999_bits", f.total_p999},
                     {"total_max_bits", JsonNumber(f.total_max)},
                     {"arith_p999_bits", f.arith_p999},
                     {"arith_max_bits", JsonNumber(f.arith_max)},
                     {"p999_interval_bits", f.p999_interval_bits},
                     {"judged", f.judged},
                     {"nan", f.nan},
                     {"inf", f.inf},
                     {"worst_index", JsonIndex(f.worst_index)},
                     {"first_nonfinite_index", JsonIndex(f.first_nonfinite_index)}};
    }
    cells[name] = bands;
  }
  return WithSchema(kBaselineSchema, {{"backend", b.backend},
                                      {"device", DeviceToJson(b.device)},
                                      {"version", b.version},
                                      {"commit", b.commit},
                                      {"made_at", b.made_at},
                                      {"plan", SamplePlanToJson(b.plan)},
                                      {"cells", cells}});
}

Expected<Baseline> BaselineFromJson(const json& j, const std::string& source, const Catalogue& catalogue) {
  JsonReader top(j, source);
  DB_RETURN_IF_ERROR(top.CheckSchema(kBaselineSchema));
  Baseline b;
  DB_ASSIGN_OR_RETURN(b.backend, top.String("backend"));
  DB_ASSIGN_OR_RETURN(JsonReader device, top.Field("device"));
  DB_ASSIGN_OR_RETURN(b.device, DeviceFromJson(device));
  DB_ASSIGN_OR_RETURN(b.version, top.String("version"));
  DB_ASSIGN_OR_RETURN(b.commit, top.String("commit"));
  DB_ASSIGN_OR_RETURN(b.made_at, top.String("made_at"));
  DB_ASSIGN_OR_RETURN(JsonReader plan, top.Field("plan"));
  DB_ASSIGN_OR_RETURN(b.plan, SamplePlanFromJson(plan));
  DB_ASSIGN_OR_RETURN(JsonReader cells, top.Field("cells"));
  if (!cells.json().is_object()) return cells.Error("expected an object of cells");
  for (const auto& [name, bands_json] : cells.json().items()) {
    Expected<Cell> cell = catalogue.ParseCell(name);
    if (!cell.ok()) return cells.Error(cell.status().message());
    DB_ASSIGN_OR_RETURN(JsonReader bands, cells.Field(name));
    if (!bands.json().is_object()) return bands.Error("expected an object of bands");
    // Keyed by the cell's own spelling, as the gate looks it up.
    if (b.cells.contains(cell->Name())) return cells.Error(fmt::format("cell '{}' is given twice", cell->Name()));
    CellFigures& figures = b.cells[cell->Name()];
    for (const auto& [band, unused] : bands_json.items()) {
      (void)unused;
      DB_ASSIGN_OR_RETURN(JsonReader r, bands.Field(band));
      BandFigures f;
      DB_ASSIGN_OR_RETURN(f.total_p999, r.Number("total_p999_bits"));
      DB_ASSIGN_OR_RETURN(f.total_max, r.Number("total_max_bits"));
      DB_ASSIGN_OR_RETURN(f.arith_p999, r.Number("arith_p999_bits"));
      DB_ASSIGN_OR_RETURN(f.arith_max, r.Number("arith_max_bits"));
      if (r.Has("p999_interval_bits")) {
        DB_RETURN_IF_ERROR(StoreInto(r.Number("p999_interval_bits"), f.p999_interval_bits));
      }
      DB_ASSIGN_OR_RETURN(f.judged, r.Unsigned("judged"));
      DB_ASSIGN_OR_RETURN(f.nan, r.Unsigned("nan"));
      DB_ASSIGN_OR_RETURN(f.inf, r.Unsigned("inf"));
      DB_ASSIGN_OR_RETURN(f.worst_index, r.Unsigned("worst_index"));
      DB_ASSIGN_OR_RETURN(f.first_nonfinite_index, r.Unsigned("first_nonfinite_index"));
      figures[band] = f;
    }
  }
  return b;
}

Status WriteBaseline(const std::filesystem::path& path, const Baseline& baseline) {
  return WriteFileAtomically(path, BaselineToJson(baseline).dump(1) + "\n");
}

Expected<Baseline> ReadBaseline(const std::filesystem::path& path, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(const nlohmann::json j, ReadJsonFile(path));
  return BaselineFromJson(j, path.string(), catalogue);
}

}  // namespace depthbench
