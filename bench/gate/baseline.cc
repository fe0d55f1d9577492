#include "bench/gate/baseline.h"

#include <algorithm>

#include "bench/base/environment.h"
#include "bench/base/files.h"
#include "bench/base/json_fields.h"
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
  f.arith_worst_index = arith.worst_index;
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

namespace {

const JsonFields<SamplePlan>& SamplePlanFields() {
  static const JsonFields<SamplePlan> fields{{
      JsonMember("seed", &SamplePlan::seed),
      JsonMember("samples", &SamplePlan::samples),
      JsonMember("samples_per_frame", &SamplePlan::samples_per_frame),
      JsonMember("domain", &SamplePlan::domain, JsonObject{DomainFields()}),
  }};
  return fields;
}

const JsonFields<BandFigures>& BandFiguresFields() {
  static constexpr JsonRealIn kBits{0.0, kAllBitsLost};
  static const JsonFields<BandFigures> fields{{
      // Bits lost lie in [0, 24]: a value outside, or "nan", is a damaged
      // file that would make a false "worse" or a band that never fails.
      JsonMember("total_p999_bits", &BandFigures::total_p999, kBits),
      JsonMember("total_max_bits", &BandFigures::total_max, kBits),
      JsonMember("arith_p999_bits", &BandFigures::arith_p999, kBits),
      JsonMember("arith_max_bits", &BandFigures::arith_max, kBits),
      // (absent from baselines made before the interval was kept)
      JsonMemberOr("p999_interval_bits", &BandFigures::p999_interval_bits, kBits, 0.0),
      JsonMember("judged", &BandFigures::judged),
      JsonMember("nan", &BandFigures::nan),
      JsonMember("inf", &BandFigures::inf),
      JsonMember("worst_index", &BandFigures::worst_index, JsonIndexOrNull()),
      // (absent from baselines made before it was kept)
      JsonOptionalMember("arith_worst_index", &BandFigures::arith_worst_index, JsonIndexOrNull()),
      JsonMember("first_nonfinite_index", &BandFigures::first_nonfinite_index, JsonIndexOrNull()),
  }};
  return fields;
}

// Built for the catalogue whose cells the names are read as.
JsonFields<Baseline> BaselineFields(const Catalogue& catalogue) {
  // Cells by their own spelling, as the gate looks them up; bands by name.
  const JsonMap<JsonMap<JsonObject<BandFigures>>> cells{
      JsonMap<JsonObject<BandFigures>>{JsonObject{BandFiguresFields()}},
      [&catalogue](std::string_view name) -> Expected<std::string> {
        DB_ASSIGN_OR_RETURN(const Cell cell, catalogue.ParseCell(name));
        return cell.Name();
      }};
  return {{
      JsonMember("backend", &Baseline::backend),
      JsonMember("device", &Baseline::device, JsonObject{DeviceFields()}),
      JsonMember("version", &Baseline::version),
      JsonMember("commit", &Baseline::commit),
      JsonMember("made_at", &Baseline::made_at),
      JsonMember("plan", &Baseline::plan, JsonObject{SamplePlanFields()}),
      JsonMember("cells", &Baseline::cells, cells),
  }};
}

}  // namespace

json SamplePlanToJson(const SamplePlan& plan) { return WriteFields(SamplePlanFields(), plan); }

json BaselineToJson(const Baseline& baseline) {
  return WriteDocument(kBaselineSchema, BaselineFields(Catalogue::BuiltIn()), baseline);
}

Expected<Baseline> BaselineFromJson(const json& j, const std::string& source, const Catalogue& catalogue) {
  return ReadDocument(kBaselineSchema, BaselineFields(catalogue), j, source);
}

Status WriteBaseline(const std::filesystem::path& path, const Baseline& baseline) {
  return WriteFileAtomically(path, BaselineToJson(baseline).dump(1) + "\n");
}

Expected<Baseline> ReadBaseline(const std::filesystem::path& path, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(const nlohmann::json j, ReadJsonFile(path));
  return BaselineFromJson(j, path.string(), catalogue);
}

}  // namespace depthbench
