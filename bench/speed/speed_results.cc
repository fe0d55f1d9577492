#include "bench/speed/speed_results.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/json_fields.h"
#include "bench/base/json_reader.h"
#include "bench/base/resources.h"
#include "bench/results/results.h"
#include "bench/speed/depth_image.h"

namespace depthbench {

using nlohmann::json;

const char* RegimeName(Regime regime) { return regime == Regime::kMemory ? "memory" : "alu"; }

Expected<Regime> ParseRegime(std::string_view name) {
  if (name == "memory") return Regime::kMemory;
  if (name == "alu") return Regime::kAlu;
  return InvalidArgument(fmt::format("unknown regime '{}'; allowed: memory, alu", name));
}

bool SameGroup(const GpuTiming& a, const GpuTiming& b) {
  return a.cell.convention == b.cell.convention && a.cell.format == b.cell.format && a.resolution == b.resolution &&
         a.regime == b.regime && a.taps == b.taps;
}

void RankGpuTimings(std::vector<GpuTiming>& timings) {
  std::vector<bool> done(timings.size(), false);
  for (std::size_t i = 0; i < timings.size(); ++i) {
    if (done[i]) continue;
    std::vector<std::size_t> members;
    std::vector<TimingSummary> summaries;
    for (std::size_t j = i; j < timings.size(); ++j) {
      if (!done[j] && SameGroup(timings[i], timings[j])) {
        members.push_back(j);
        summaries.push_back(timings[j].ns_per_pass);
        done[j] = true;
      }
    }
    const std::vector<std::uint32_t> ranks = RankByTiming(summaries);
    for (std::size_t k = 0; k < members.size(); ++k) {
      GpuTiming& timing = timings[members[k]];
      timing.rank = ranks[k];
      timing.indistinguishable_from.clear();
      for (std::size_t other : members) {
        if (other != members[k] &&
            Compare(timing.ns_per_pass, timings[other].ns_per_pass) == Ordering::kIndistinguishable) {
          timing.indistinguishable_from.push_back(timings[other].cell.variant);
        }
      }
    }
  }
}

const GpuTiming* SpeedResults::FindGpu(const Cell& cell, Resolution resolution, Regime regime) const {
  for (const GpuTiming& t : gpu)
    if (t.cell == cell && t.resolution == resolution && t.regime == regime) return &t;
  return nullptr;
}

const StageRate* StageProbe::compute() const {
  for (const StageRate& stage : stages) {
    if (stage.stage == "compute") return &stage;
  }
  return nullptr;
}

std::optional<double> StageProbe::drawn_share() const {
  const StageRate* const base = compute();
  std::optional<double> share;
  for (const StageRate& stage : stages) {
    if (&stage == base || base == nullptr) continue;
    const double s = fma_per_second(stage) / fma_per_second(*base);
    share = share ? std::min(*share, s) : s;
  }
  return share;
}

std::vector<MemoryFloor> MemoryFloors(const BandwidthProbe& probe, const std::vector<GpuTiming>& timings) {
  std::vector<MemoryFloor> floors;
  const double bytes_per_ns = probe.bytes_per_second() * 1e-9;
  if (!(bytes_per_ns > 0.0) || !std::isfinite(bytes_per_ns)) return floors;
  for (const GpuTiming& t : timings) {
    const bool known = std::any_of(floors.begin(), floors.end(), [&](const MemoryFloor& f) {
      return f.format == t.cell.format && f.resolution == t.resolution;
    });
    if (known) continue;
    MemoryFloor floor;
    floor.format = t.cell.format;
    floor.resolution = t.resolution;
    // One reconstruction per pixel: its texel read (as Vulkan stores the
    // format), one float32 written (shaders/speed/speed_pass.glsl).
    floor.bytes_read_per_pixel = TexelBytes(t.cell.format);
    floor.bytes_written_per_pixel = sizeof(float);
    floor.ns_per_pass = t.pixels() * (floor.bytes_read_per_pixel + floor.bytes_written_per_pixel) / bytes_per_ns;
    floors.push_back(floor);
  }
  return floors;
}

std::optional<PassCostSplit> SplitPassCost(const std::vector<GpuTiming>& timings) {
  std::map<Cell, std::pair<const GpuTiming*, const GpuTiming*>> extremes;  // smallest, largest
  for (const GpuTiming& t : timings) {
    if (t.regime != Regime::kMemory || !(t.ns_per_pass.median > 0.0)) continue;
    auto [it, added] = extremes.try_emplace(t.cell, &t, &t);
    if (t.pixels() < it->second.first->pixels()) it->second.first = &t;
    if (t.pixels() > it->second.second->pixels()) it->second.second = &t;
  }
  std::vector<double> fixed, per_pixel;
  PassCostSplit split;
  for (const auto& [cell, pair] : extremes) {
    const auto [small, large] = pair;
    if (small->pixels() == large->pixels()) continue;
    const double slope = (large->ns_per_pass.median - small->ns_per_pass.median) / (large->pixels() - small->pixels());
    per_pixel.push_back(slope);
    fixed.push_back(small->ns_per_pass.median - slope * small->pixels());
    split.smallest = small->resolution;
    split.largest = large->resolution;
  }
  if (fixed.empty()) return std::nullopt;
  const auto median = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  split.cells = fixed.size();
  split.fixed_ns = median(fixed);
  split.ns_per_pixel = median(per_pixel);
  return split;
}

const MemoryFloor* SpeedResults::FindFloor(Format format, Resolution resolution) const {
  for (const MemoryFloor& f : floors)
    if (f.format == format && f.resolution == resolution) return &f;
  return nullptr;
}

std::optional<double> SpeedResults::TimesFloor(const GpuTiming& timing) const {
  if (timing.regime != Regime::kMemory) return std::nullopt;
  const MemoryFloor* floor = FindFloor(timing.cell.format, timing.resolution);
  if (floor == nullptr || !(floor->ns_per_pass > 0.0)) return std::nullopt;
  return timing.ns_per_pass.median / floor->ns_per_pass;
}

const CpuCost* SpeedResults::FindCpu(const Cell& cell) const {
  for (const CpuCost& c : cpu)
    if (c.cell == cell) return &c;
  return nullptr;
}

const Catalogue& SpeedResults::variant_catalogue() const {
  return catalogue != nullptr ? *catalogue : Catalogue::BuiltIn();
}

const VariantInfo& SpeedResults::variant_info(Variant v) const { return variant_catalogue().Info(v); }

// ---------------------------------------------------------------- fields

namespace {

// "1920x1080".
JsonNamed<Resolution> JsonResolutionName() {
  return {ResolutionName, [](std::string_view text) { return ParseResolution(text, "resolution"); }};
}

const JsonFields<TimingSummary>& SummaryFields() {
  static const JsonFields<TimingSummary> fields{
      {
          JsonMember("count", &TimingSummary::count, JsonInteger<std::uint32_t>{1}),
          JsonMember("median", &TimingSummary::median),
          JsonMember("q1", &TimingSummary::q1),
          JsonMember("q3", &TimingSummary::q3),
          JsonMember("min", &TimingSummary::min),
          JsonMember("max", &TimingSummary::max),
          JsonDerived<TimingSummary>("spread", [](const TimingSummary& s) { return s.spread(); }),
      },
      [](const JsonReader& r, const TimingSummary& s) {
        if (s.min <= s.q1 && s.q1 <= s.median && s.median <= s.q3 && s.q3 <= s.max) return Status::Ok();
        return r.Error("expected min <= q1 <= median <= q3 <= max");
      }};
  return fields;
}

const JsonFields<OpCount>& CountFields() {
  static const JsonFields<OpCount> fields{{
      JsonMember("instructions", &OpCount::instructions),
      JsonMember("lanes", &OpCount::lanes),
  }};
  return fields;
}

const JsonFields<InstructionMix>& MixFields() {
  const JsonObject count{CountFields()};
  static const JsonFields<InstructionMix> fields{{
      JsonMember("fdiv", &InstructionMix::fdiv, count),
      JsonMember("fmul", &InstructionMix::fmul, count),
      JsonMember("fadd", &InstructionMix::fadd, count),
      JsonMember("fneg", &InstructionMix::fneg, count),
      JsonMember("fma", &InstructionMix::fma, count),
      JsonMember("dot", &InstructionMix::dot, count),
      JsonMember("matrix_vector", &InstructionMix::matrix_vector, count),
      JsonMember("matrix_matrix", &InstructionMix::matrix_matrix, count),
      JsonMember("extended", &InstructionMix::extended, count),
      JsonMember("extended_by_name", &InstructionMix::extended_by_name, JsonMap{count}),
      JsonMember("function_calls", &InstructionMix::function_calls),
      JsonMember("total_instructions", &InstructionMix::total_instructions),
  }};
  return fields;
}

const JsonFields<SpeedRunInfo>& RunFields() {
  static const JsonFields<SpeedRunInfo> fields{{
      JsonMember("version", &SpeedRunInfo::version),
      JsonMember("commit", &SpeedRunInfo::commit),
      JsonMember("started_at", &SpeedRunInfo::started_at),
      JsonMember("host", &SpeedRunInfo::host),
      JsonMember("device", &SpeedRunInfo::device, JsonObject{DeviceFields()}),
      JsonMember("device_type", &SpeedRunInfo::device_type),
      JsonMember("timestamp_period_ns", &SpeedRunInfo::timestamp_period_ns),
      JsonMember("timestamp_valid_bits", &SpeedRunInfo::timestamp_valid_bits),
      JsonMember("note", &SpeedRunInfo::note),
      JsonMember("warmup", &SpeedRunInfo::warmup),
      JsonMember("repetitions", &SpeedRunInfo::repetitions),
      JsonMember("alu_taps", &SpeedRunInfo::alu_taps),
      JsonMember("resolutions", &SpeedRunInfo::resolutions, JsonArray{JsonResolutionName()}),
      JsonMember("trade_resolution", &SpeedRunInfo::trade_resolution, JsonResolutionName()),
      JsonMember("accuracy_source", &SpeedRunInfo::accuracy_source),
      JsonMember("accuracy_backend", &SpeedRunInfo::accuracy_backend),
      JsonMember("accuracy_device", &SpeedRunInfo::accuracy_device),
      JsonMember("cpu_compiler", &SpeedRunInfo::cpu_compiler),
      JsonMember("seconds", &SpeedRunInfo::seconds),
  }};
  return fields;
}

// Against its floor (times_floor, bandwidth_bound), a memory-bound timing
// is written by ToJson below: the floor is the file's, not the timing's.
JsonFields<GpuTiming> GpuTimingFields(const Catalogue& catalogue) {
  return {{
      JsonMember("cell", &GpuTiming::cell, JsonCellName(catalogue)),
      JsonMember("resolution", &GpuTiming::resolution, JsonResolutionName()),
      JsonMember("regime", &GpuTiming::regime,
                 JsonNamed<Regime>{[](const Regime& r) -> std::string { return RegimeName(r); }, ParseRegime}),
      JsonMember("taps", &GpuTiming::taps, JsonInteger<std::uint32_t>{1}),
      JsonMember("ns_per_pass", &GpuTiming::ns_per_pass, JsonObject{SummaryFields()}),
      JsonDerived<GpuTiming>("ns_per_pixel", [](const GpuTiming& t) { return t.ns_per_pixel(); }),
      JsonDerived<GpuTiming>("spread_ns_per_pixel", [](const GpuTiming& t) { return t.spread_ns_per_pixel(); }),
      JsonDerived<GpuTiming>("ns_per_reconstruction", [](const GpuTiming& t) { return t.ns_per_reconstruction(); }),
      JsonMember("repetitions_ns", &GpuTiming::repetitions_ns, JsonArray{JsonReal()}),
      JsonMember("passes_per_repetition", &GpuTiming::passes_per_repetition),
      JsonMember("warmup_passes", &GpuTiming::warmup_passes),
      JsonMember("rank", &GpuTiming::rank),
      JsonMember("indistinguishable_from", &GpuTiming::indistinguishable_from, JsonArray{JsonVariantName(catalogue)}),
  }};
}

const JsonFields<BandwidthProbe>& BandwidthFields() {
  static const JsonFields<BandwidthProbe> fields{
      {
          JsonMember("method", &BandwidthProbe::method),
          JsonMember("bytes_read", &BandwidthProbe::bytes_read),
          JsonMember("bytes_written", &BandwidthProbe::bytes_written),
          JsonMember("ns_per_pass", &BandwidthProbe::ns_per_pass, JsonObject{SummaryFields()}),
          JsonMember("repetitions_ns", &BandwidthProbe::repetitions_ns, JsonArray{JsonReal()}),
          JsonMember("passes_per_repetition", &BandwidthProbe::passes_per_repetition),
          JsonMember("warmup_passes", &BandwidthProbe::warmup_passes),
          JsonDerived<BandwidthProbe>("bytes_per_second", [](const BandwidthProbe& b) { return b.bytes_per_second(); }),
      },
      [](const JsonReader& r, const BandwidthProbe& b) -> Status {
        if (b.bytes_read + b.bytes_written == 0) return r.Error("a bandwidth probe that moved no bytes");
        if (!(b.ns_per_pass.median > 0.0)) {
          DB_ASSIGN_OR_RETURN(const JsonReader summary, r.Field("ns_per_pass"));
          return summary.Error("the median must be above 0 ns");
        }
        return Status::Ok();
      }};
  return fields;
}

const JsonFields<StageRate>& StageRateFields() {
  static const JsonFields<StageRate> fields{
      {
          JsonMember("stage", &StageRate::stage),
          JsonMember("ns_per_pass", &StageRate::ns_per_pass, JsonObject{SummaryFields()}),
          JsonMember("repetitions_ns", &StageRate::repetitions_ns, JsonArray{JsonReal()}),
          JsonMember("passes_per_repetition", &StageRate::passes_per_repetition),
          JsonMember("warmup_passes", &StageRate::warmup_passes),
          JsonMember("processors_used", &StageRate::processors_used),
      },
      [](const JsonReader& r, const StageRate& rate) -> Status {
        if (rate.stage != "compute" && rate.stage != "vertex" && rate.stage != "fragment") {
          DB_ASSIGN_OR_RETURN(const JsonReader stage, r.Field("stage"));
          return stage.Error(fmt::format("'{}' is not a stage: compute, vertex or fragment", rate.stage));
        }
        if (!(rate.ns_per_pass.median > 0.0)) {
          DB_ASSIGN_OR_RETURN(const JsonReader summary, r.Field("ns_per_pass"));
          return summary.Error("the median must be above 0 ns");
        }
        return Status::Ok();
      }};
  return fields;
}

const JsonFields<StageProbe>& StageProbeFields() {
  static const JsonFields<StageProbe> fields{
      {
          JsonMember("method", &StageProbe::method),
          JsonMember("invocations", &StageProbe::invocations),
          JsonMember("fma_per_invocation", &StageProbe::fma_per_invocation),
          JsonMember("processors", &StageProbe::processors),
          JsonMember("stages", &StageProbe::stages, JsonArray{JsonObject{StageRateFields()}}),
          JsonMember("left_out", &StageProbe::left_out, JsonArray{JsonText()}),
      },
      [](const JsonReader& r, const StageProbe& probe) -> Status {
        if (probe.invocations == 0 || probe.fma_per_invocation == 0) {
          return r.Error("a stage probe needs invocations and multiply-adds");
        }
        if (probe.compute() == nullptr) {
          DB_ASSIGN_OR_RETURN(const JsonReader stages, r.Field("stages"));
          return stages.Error("the compute stage is missing: the others are compared with it");
        }
        return Status::Ok();
      }};
  return fields;
}

const JsonFields<MemoryFloor>& FloorFields() {
  static const JsonFields<MemoryFloor> fields{
      {
          JsonMember("format", &MemoryFloor::format, JsonFormatName()),
          JsonMember("resolution", &MemoryFloor::resolution, JsonResolutionName()),
          JsonMember("bytes_read_per_pixel", &MemoryFloor::bytes_read_per_pixel),
          JsonMember("bytes_written_per_pixel", &MemoryFloor::bytes_written_per_pixel),
          JsonMember("ns_per_pass", &MemoryFloor::ns_per_pass),
      },
      [](const JsonReader& r, const MemoryFloor& f) {
        if (f.ns_per_pass > 0.0 && std::isfinite(f.ns_per_pass)) return Status::Ok();
        return r.Error("ns_per_pass must be above 0");
      }};
  return fields;
}

JsonFields<StaticCost> StaticCostFields(const Catalogue& catalogue) {
  return {{
      JsonMember("variant", &StaticCost::variant, JsonVariantName(catalogue)),
      JsonMember("function", &StaticCost::function),
      JsonMember("mix", &StaticCost::mix, JsonObject{MixFields()}),
  }};
}

JsonFields<CpuCost> CpuCostFields(const Catalogue& catalogue) {
  return {{
      JsonMember("cell", &CpuCost::cell, JsonCellName(catalogue)),
      JsonMember("ns_per_reconstruction", &CpuCost::ns_per_reconstruction, JsonObject{SummaryFields()}),
      JsonMember("runs_per_repetition", &CpuCost::runs_per_repetition),
      JsonMember("samples_per_run", &CpuCost::samples_per_run),
  }};
}

JsonFields<TradePoint> TradePointFields(const Catalogue& catalogue) {
  return {{
      JsonMember("variant", &TradePoint::variant, JsonVariantName(catalogue)),
      JsonMember("gpu_ns_per_reconstruction", &TradePoint::gpu_ns_per_reconstruction),
      JsonMember("gpu_spread_ns", &TradePoint::gpu_spread_ns),
      JsonMember("gpu_memory_ns_per_pixel", &TradePoint::gpu_memory_ns_per_pixel),
      JsonMember("cpu_ns_per_reconstruction", &TradePoint::cpu_ns_per_reconstruction),
      JsonMember("cpu_spread_ns", &TradePoint::cpu_spread_ns),
      JsonMember("p999_bits_lost", &TradePoint::p999_bits_lost),
      JsonMember("nonfinite", &TradePoint::nonfinite),
      JsonMember("on_gpu_front", &TradePoint::on_gpu_front),
      JsonMember("on_cpu_front", &TradePoint::on_cpu_front),
  }};
}

JsonFields<TradeFront> TradeFrontFields(const Catalogue& catalogue) {
  return {
      {
          JsonMember("convention", &TradeFront::convention, JsonConventionName()),
          JsonMember("format", &TradeFront::format, JsonFormatName()),
          JsonMember("points", &TradeFront::points, JsonArray{JsonObject{TradePointFields(catalogue)}}),
      },
      // Every point is of a cell that exists.
      [&catalogue](const JsonReader& r, const TradeFront& front) -> Status {
        for (std::size_t i = 0; i < front.points.size(); ++i) {
          const Variant variant = front.points[i].variant;
          if (catalogue.Reads(variant, front.convention, front.format)) continue;
          DB_ASSIGN_OR_RETURN(const JsonReader points, r.Field("points"));
          DB_ASSIGN_OR_RETURN(const JsonReader point, points.Element(i));
          return point.Error(fmt::format("{} does not read {} under the {} convention", catalogue.Info(variant).name,
                                         Info(front.format).name, Info(front.convention).name));
        }
        return Status::Ok();
      }};
}

bool HasBandwidth(const SpeedResults& results) { return results.bandwidth.has_value(); }

JsonFields<SpeedResults> SpeedResultsFields(const Catalogue& catalogue) {
  // Files made before the bandwidth probe have neither it nor the floors
  // made from it.
  return {{
      JsonMember("run", &SpeedResults::run, JsonObject{RunFields()}),
      JsonOptionalMember("bandwidth", &SpeedResults::bandwidth, JsonObject{BandwidthFields()}),
      JsonOnlyIf(JsonMember("memory_floor", &SpeedResults::floors, JsonArray{JsonObject{FloorFields()}}), HasBandwidth),
      JsonOnlyIf(JsonDerived<SpeedResults>("bandwidth_bound_factor",
                                           [](const SpeedResults&) { return kBandwidthBoundFactor; }),
                 HasBandwidth),
      JsonOptionalMember("stage_probe", &SpeedResults::stages, JsonObject{StageProbeFields()}),
      JsonMember("gpu", &SpeedResults::gpu, JsonArray{JsonObject{GpuTimingFields(catalogue)}}),
      JsonMember("static", &SpeedResults::static_costs, JsonArray{JsonObject{StaticCostFields(catalogue)}}),
      JsonMember("cpu", &SpeedResults::cpu, JsonArray{JsonObject{CpuCostFields(catalogue)}}),
      JsonMember("trade", &SpeedResults::trade, JsonArray{JsonObject{TradeFrontFields(catalogue)}}),
      JsonMember("skipped", &SpeedResults::skipped, JsonArray{JsonText()}),
  }};
}

}  // namespace

json ToJson(const SpeedResults& results) {
  json document = WriteDocument(kSpeedSchema, SpeedResultsFields(results.variant_catalogue()), results);
  // Memory-bound timings against their floor, and the split of a pass's
  // cost (derived; not read back).
  for (std::size_t i = 0; i < results.gpu.size(); ++i) {
    if (const std::optional<double> times = results.TimesFloor(results.gpu[i])) {
      document["gpu"][i]["times_floor"] = *times;
      document["gpu"][i]["bandwidth_bound"] = *times <= kBandwidthBoundFactor;
    }
  }
  if (const std::optional<PassCostSplit> split = SplitPassCost(results.gpu)) {
    document["pass_cost_split"] = {{"cells", split->cells},
                                   {"fixed_ns", split->fixed_ns},
                                   // Below 0, the intercept is not a cost (speed_table.cc).
                                   {"fixed_cost_measurable", split->fixed_ns >= 0.0},
                                   {"ns_per_pixel", split->ns_per_pixel},
                                   {"smallest", ResolutionName(split->smallest)},
                                   {"largest", ResolutionName(split->largest)}};
  }
  return document;
}

Expected<std::vector<std::filesystem::path>> CommittedSpeedFiles() {
  DB_ASSIGN_OR_RETURN(const std::filesystem::path folder, DataPath("reports/speed"));
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".json" && name.find(".repeat.") == std::string::npos) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

bool SpeedFileApplies(const SpeedResults& speed, bool named, std::span<const DeviceInfo> devices) {
  return named || std::any_of(devices.begin(), devices.end(),
                              [&](const DeviceInfo& d) { return d.name == speed.run.device.name; });
}

Status WriteSpeedResults(const std::filesystem::path& path, const SpeedResults& results) {
  return WriteFileAtomically(path, ToJson(results).dump(1) + "\n");
}

Expected<SpeedResults> SpeedResultsFromJson(const json& j, const std::string& source, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(SpeedResults results, ReadDocument(kSpeedSchema, SpeedResultsFields(catalogue), j, source));
  results.catalogue = &catalogue;
  return results;
}

Expected<SpeedResults> ReadSpeedResults(const std::filesystem::path& path, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(const json j, ReadJsonFile(path));
  return SpeedResultsFromJson(j, path.string(), catalogue);
}

// ---------------------------------------------------------------- comparing

Expected<RankingComparison> CompareRankings(const SpeedResults& first, const SpeedResults& second) {
  if (first.run.device.name != second.run.device.name || first.run.device.driver != second.run.device.driver) {
    return InvalidArgument(
        fmt::format("rankings are kept per device: one run is of '{}' ({}), the other of '{}' "
                    "({})",
                    first.run.device.name, first.run.device.driver, second.run.device.name, second.run.device.driver));
  }
  RankingComparison comparison;
  for (std::size_t i = 0; i < first.gpu.size(); ++i) {
    for (std::size_t j = i + 1; j < first.gpu.size(); ++j) {
      const GpuTiming& a1 = first.gpu[i];
      const GpuTiming& b1 = first.gpu[j];
      if (!SameGroup(a1, b1)) continue;
      const GpuTiming* a2 = second.FindGpu(a1.cell, a1.resolution, a1.regime);
      const GpuTiming* b2 = second.FindGpu(b1.cell, b1.resolution, b1.regime);
      if (a2 == nullptr || b2 == nullptr || a2->taps != a1.taps || b2->taps != b1.taps) continue;
      ++comparison.pairs;
      const Ordering in_first = Compare(a1.ns_per_pass, b1.ns_per_pass);
      const Ordering in_second = Compare(a2->ns_per_pass, b2->ns_per_pass);
      const bool tie_first = in_first == Ordering::kIndistinguishable;
      const bool tie_second = in_second == Ordering::kIndistinguishable;
      if (tie_first && tie_second) {
        ++comparison.both_ties;
      } else if (tie_first || tie_second) {
        ++comparison.one_sided;
      } else if (in_first == in_second) {
        ++comparison.agree;
      } else {
        comparison.contradictions.push_back(fmt::format(
            "{} {} {}: {} is {} than {} in the first run ({:.4g} vs {:.4g} ns per pass) but {} in the second "
            "({:.4g} vs {:.4g})",
            Info(a1.cell.convention).name, Info(a1.cell.format).name,
            fmt::format("{} {}", ResolutionName(a1.resolution), RegimeName(a1.regime)), a1.cell.variant_info().name,
            OrderingName(in_first), b1.cell.variant_info().name, a1.ns_per_pass.median, b1.ns_per_pass.median,
            OrderingName(in_second), a2->ns_per_pass.median, b2->ns_per_pass.median));
      }
    }
  }
  return comparison;
}

}  // namespace depthbench
