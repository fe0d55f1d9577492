#include "bench/speed/speed_results.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/json_reader.h"
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

std::string ResolutionName(Resolution resolution) { return fmt::format("{}x{}", resolution.width, resolution.height); }

Expected<Resolution> ParseResolution(std::string_view text, std::string_view what) {
  const auto x = text.find_first_of("xX");
  Resolution r{0, 0};
  auto parse = [](std::string_view s, std::uint32_t& out) {
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return !s.empty() && ec == std::errc() && end == s.data() + s.size();
  };
  if (x == std::string_view::npos || !parse(text.substr(0, x), r.width) || !parse(text.substr(x + 1), r.height) ||
      r.width == 0 || r.height == 0) {
    return InvalidArgument(
        fmt::format("{}: '{}' is not WIDTHxHEIGHT with both at least 1 (e.g. 1920x1080)", what, text));
  }
  return r;
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

const VariantInfo& SpeedResults::variant_info(Variant v) const {
  return (catalogue != nullptr ? *catalogue : Catalogue::BuiltIn()).Info(v);
}

// ---------------------------------------------------------------- writing

namespace {

json SummaryToJson(const TimingSummary& s) {
  return {{"count", s.count},     {"median", s.median}, {"q1", s.q1},  {"q3", s.q3},
          {"spread", s.spread()}, {"min", s.min},       {"max", s.max}};
}

json CountToJson(const OpCount& c) { return {{"instructions", c.instructions}, {"lanes", c.lanes}}; }

json MixToJson(const InstructionMix& mix) {
  json extended_by_name = json::object();
  for (const auto& [name, count] : mix.extended_by_name) extended_by_name[name] = CountToJson(count);
  return {{"fdiv", CountToJson(mix.fdiv)},
          {"fmul", CountToJson(mix.fmul)},
          {"fadd", CountToJson(mix.fadd)},
          {"fneg", CountToJson(mix.fneg)},
          {"fma", CountToJson(mix.fma)},
          {"dot", CountToJson(mix.dot)},
          {"matrix_vector", CountToJson(mix.matrix_vector)},
          {"matrix_matrix", CountToJson(mix.matrix_matrix)},
          {"extended", CountToJson(mix.extended)},
          {"extended_by_name", extended_by_name},
          {"function_calls", mix.function_calls},
          {"total_instructions", mix.total_instructions}};
}

json VariantNames(const SpeedResults& results, const std::vector<Variant>& variants) {
  json names = json::array();
  for (Variant v : variants) names.push_back(results.variant_info(v).name);
  return names;
}

json RunToJson(const SpeedRunInfo& run) {
  json resolutions = json::array();
  for (const Resolution& r : run.resolutions) resolutions.push_back(ResolutionName(r));
  return {{"version", run.version},
          {"commit", run.commit},
          {"started_at", run.started_at},
          {"host", run.host},
          {"device", DeviceToJson(run.device)},
          {"device_type", run.device_type},
          {"timestamp_period_ns", run.timestamp_period_ns},
          {"timestamp_valid_bits", run.timestamp_valid_bits},
          {"note", run.note},
          {"warmup", run.warmup},
          {"repetitions", run.repetitions},
          {"alu_taps", run.alu_taps},
          {"resolutions", resolutions},
          {"trade_resolution", ResolutionName(run.trade_resolution)},
          {"accuracy_source", run.accuracy_source},
          {"accuracy_backend", run.accuracy_backend},
          {"accuracy_device", run.accuracy_device},
          {"cpu_compiler", run.cpu_compiler},
          {"seconds", run.seconds}};
}

json BandwidthToJson(const BandwidthProbe& b) {
  return {{"method", b.method},
          {"bytes_read", b.bytes_read},
          {"bytes_written", b.bytes_written},
          {"ns_per_pass", SummaryToJson(b.ns_per_pass)},
          {"repetitions_ns", b.repetitions_ns},
          {"passes_per_repetition", b.passes_per_repetition},
          {"warmup_passes", b.warmup_passes},
          {"bytes_per_second", b.bytes_per_second()}};
}

}  // namespace

json ToJson(const SpeedResults& results) {
  json gpu = json::array();
  for (const GpuTiming& t : results.gpu) {
    json timing = {{"cell", t.cell.Name()},
                   {"resolution", ResolutionName(t.resolution)},
                   {"regime", RegimeName(t.regime)},
                   {"taps", t.taps},
                   {"ns_per_pass", SummaryToJson(t.ns_per_pass)},
                   {"ns_per_pixel", t.ns_per_pixel()},
                   {"spread_ns_per_pixel", t.spread_ns_per_pixel()},
                   {"ns_per_reconstruction", t.ns_per_reconstruction()},
                   {"repetitions_ns", t.repetitions_ns},
                   {"passes_per_repetition", t.passes_per_repetition},
                   {"warmup_passes", t.warmup_passes},
                   {"rank", t.rank},
                   {"indistinguishable_from", VariantNames(results, t.indistinguishable_from)}};
    // Memory-bound timings against their floor (derived; not read back).
    if (const std::optional<double> times = results.TimesFloor(t)) {
      timing["times_floor"] = *times;
      timing["bandwidth_bound"] = *times <= kBandwidthBoundFactor;
    }
    gpu.push_back(std::move(timing));
  }
  json floors = json::array();
  for (const MemoryFloor& f : results.floors) {
    floors.push_back({{"format", Info(f.format).name},
                      {"resolution", ResolutionName(f.resolution)},
                      {"bytes_read_per_pixel", f.bytes_read_per_pixel},
                      {"bytes_written_per_pixel", f.bytes_written_per_pixel},
                      {"ns_per_pass", f.ns_per_pass}});
  }
  json static_costs = json::array();
  for (const StaticCost& s : results.static_costs) {
    static_costs.push_back(
        {{"variant", results.variant_info(s.variant).name}, {"function", s.function}, {"mix", MixToJson(s.mix)}});
  }
  json cpu = json::array();
  for (const CpuCost& c : results.cpu) {
    cpu.push_back({{"cell", c.cell.Name()},
                   {"ns_per_reconstruction", SummaryToJson(c.ns_per_reconstruction)},
                   {"runs_per_repetition", c.runs_per_repetition},
                   {"samples_per_run", c.samples_per_run}});
  }
  json trade = json::array();
  for (const TradeFront& front : results.trade) {
    json points = json::array();
    for (const TradePoint& p : front.points) {
      points.push_back({{"variant", results.variant_info(p.variant).name},
                        {"gpu_ns_per_reconstruction", p.gpu_ns_per_reconstruction},
                        {"gpu_spread_ns", p.gpu_spread_ns},
                        {"gpu_memory_ns_per_pixel", p.gpu_memory_ns_per_pixel},
                        {"cpu_ns_per_reconstruction", JsonNumber(p.cpu_ns_per_reconstruction)},
                        {"cpu_spread_ns", p.cpu_spread_ns},
                        {"p999_bits_lost", p.p999_bits_lost},
                        {"nonfinite", p.nonfinite},
                        {"on_gpu_front", p.on_gpu_front},
                        {"on_cpu_front", p.on_cpu_front}});
    }
    trade.push_back(
        {{"convention", Info(front.convention).name}, {"format", Info(front.format).name}, {"points", points}});
  }
  json document = {
      {"run", RunToJson(results.run)}, {"gpu", gpu}, {"static", static_costs}, {"cpu", cpu}, {"trade", trade},
      {"skipped", results.skipped}};
  // Absent where no probe ran (files made before it), as a reader expects.
  if (results.bandwidth) {
    document["bandwidth"] = BandwidthToJson(*results.bandwidth);
    document["memory_floor"] = floors;
    document["bandwidth_bound_factor"] = kBandwidthBoundFactor;
  }
  return WithSchema(kSpeedSchema, std::move(document));
}

Status WriteSpeedResults(const std::filesystem::path& path, const SpeedResults& results) {
  return WriteFileAtomically(path, ToJson(results).dump(1) + "\n");
}

// ---------------------------------------------------------------- reading

namespace {

Expected<std::uint32_t> ReadU32(const JsonReader& r, const std::string& key) {
  DB_ASSIGN_OR_RETURN(const std::uint64_t value, r.Unsigned(key));
  if (value > std::numeric_limits<std::uint32_t>::max()) {
    DB_ASSIGN_OR_RETURN(JsonReader field, r.Field(key));
    return field.Error(fmt::format("{} is above {}", value, std::numeric_limits<std::uint32_t>::max()));
  }
  return static_cast<std::uint32_t>(value);
}

Expected<Cell> ReadCell(const JsonReader& r, const std::string& key, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(JsonReader field, r.Field(key));
  DB_ASSIGN_OR_RETURN(const std::string name, field.String());
  Expected<Cell> cell = catalogue.ParseCell(name);
  if (!cell.ok()) return field.Error(cell.status().message());
  return cell;
}

Expected<Variant> ReadVariant(const JsonReader& r, const std::string& key, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(JsonReader field, r.Field(key));
  DB_ASSIGN_OR_RETURN(const std::string name, field.String());
  Expected<Variant> variant = catalogue.ParseVariant(name);
  if (!variant.ok()) return field.Error(variant.status().message());
  return variant;
}

Expected<Resolution> ReadResolution(const JsonReader& field) {
  DB_ASSIGN_OR_RETURN(const std::string text, field.String());
  Expected<Resolution> resolution = ParseResolution(text, "resolution");
  if (!resolution.ok()) return field.Error(resolution.status().message());
  return resolution;
}

Expected<TimingSummary> ReadSummary(const JsonReader& r) {
  TimingSummary s;
  DB_ASSIGN_OR_RETURN(s.count, ReadU32(r, "count"));
  DB_ASSIGN_OR_RETURN(s.median, r.Number("median"));
  DB_ASSIGN_OR_RETURN(s.q1, r.Number("q1"));
  DB_ASSIGN_OR_RETURN(s.q3, r.Number("q3"));
  DB_ASSIGN_OR_RETURN(s.min, r.Number("min"));
  DB_ASSIGN_OR_RETURN(s.max, r.Number("max"));
  if (!(s.min <= s.q1 && s.q1 <= s.median && s.median <= s.q3 && s.q3 <= s.max) || s.count == 0) {
    return r.Error("expected count >= 1 and min <= q1 <= median <= q3 <= max");
  }
  return s;
}

Expected<OpCount> ReadCount(const JsonReader& r, const std::string& key) {
  DB_ASSIGN_OR_RETURN(JsonReader field, r.Field(key));
  OpCount c;
  DB_ASSIGN_OR_RETURN(c.instructions, ReadU32(field, "instructions"));
  DB_ASSIGN_OR_RETURN(c.lanes, ReadU32(field, "lanes"));
  return c;
}

Expected<InstructionMix> ReadMix(const JsonReader& r) {
  InstructionMix mix;
  DB_ASSIGN_OR_RETURN(mix.fdiv, ReadCount(r, "fdiv"));
  DB_ASSIGN_OR_RETURN(mix.fmul, ReadCount(r, "fmul"));
  DB_ASSIGN_OR_RETURN(mix.fadd, ReadCount(r, "fadd"));
  DB_ASSIGN_OR_RETURN(mix.fneg, ReadCount(r, "fneg"));
  DB_ASSIGN_OR_RETURN(mix.fma, ReadCount(r, "fma"));
  DB_ASSIGN_OR_RETURN(mix.dot, ReadCount(r, "dot"));
  DB_ASSIGN_OR_RETURN(mix.matrix_vector, ReadCount(r, "matrix_vector"));
  DB_ASSIGN_OR_RETURN(mix.matrix_matrix, ReadCount(r, "matrix_matrix"));
  DB_ASSIGN_OR_RETURN(mix.extended, ReadCount(r, "extended"));
  DB_ASSIGN_OR_RETURN(JsonReader by_name, r.Field("extended_by_name"));
  if (!by_name.json().is_object()) return by_name.Error("expected an object");
  for (const auto& [name, value] : by_name.json().items()) {
    DB_ASSIGN_OR_RETURN(mix.extended_by_name[name], ReadCount(by_name, name));
  }
  DB_ASSIGN_OR_RETURN(mix.function_calls, ReadU32(r, "function_calls"));
  DB_ASSIGN_OR_RETURN(mix.total_instructions, ReadU32(r, "total_instructions"));
  return mix;
}

Expected<SpeedRunInfo> ReadRun(const JsonReader& r) {
  SpeedRunInfo run;
  DB_ASSIGN_OR_RETURN(run.version, r.String("version"));
  DB_ASSIGN_OR_RETURN(run.commit, r.String("commit"));
  DB_ASSIGN_OR_RETURN(run.started_at, r.String("started_at"));
  DB_ASSIGN_OR_RETURN(run.host, r.String("host"));
  DB_ASSIGN_OR_RETURN(const JsonReader device, r.Field("device"));
  DB_ASSIGN_OR_RETURN(run.device, DeviceFromJson(device));
  DB_ASSIGN_OR_RETURN(run.device_type, r.String("device_type"));
  DB_ASSIGN_OR_RETURN(run.timestamp_period_ns, r.Number("timestamp_period_ns"));
  DB_ASSIGN_OR_RETURN(run.timestamp_valid_bits, ReadU32(r, "timestamp_valid_bits"));
  DB_ASSIGN_OR_RETURN(run.note, r.String("note"));
  DB_ASSIGN_OR_RETURN(run.warmup, ReadU32(r, "warmup"));
  DB_ASSIGN_OR_RETURN(run.repetitions, ReadU32(r, "repetitions"));
  DB_ASSIGN_OR_RETURN(run.alu_taps, ReadU32(r, "alu_taps"));
  DB_RETURN_IF_ERROR(r.ForEach("resolutions", [&](const JsonReader& element) -> Status {
    DB_ASSIGN_OR_RETURN(Resolution resolution, ReadResolution(element));
    run.resolutions.push_back(resolution);
    return Status::Ok();
  }));
  DB_ASSIGN_OR_RETURN(JsonReader trade_resolution, r.Field("trade_resolution"));
  DB_ASSIGN_OR_RETURN(run.trade_resolution, ReadResolution(trade_resolution));
  DB_ASSIGN_OR_RETURN(run.accuracy_source, r.String("accuracy_source"));
  DB_ASSIGN_OR_RETURN(run.accuracy_backend, r.String("accuracy_backend"));
  DB_ASSIGN_OR_RETURN(run.accuracy_device, r.String("accuracy_device"));
  DB_ASSIGN_OR_RETURN(run.cpu_compiler, r.String("cpu_compiler"));
  DB_ASSIGN_OR_RETURN(run.seconds, r.Number("seconds"));
  return run;
}

Expected<GpuTiming> ReadGpuTiming(const JsonReader& r, const Catalogue& catalogue) {
  GpuTiming t;
  DB_ASSIGN_OR_RETURN(t.cell, ReadCell(r, "cell", catalogue));
  DB_ASSIGN_OR_RETURN(JsonReader resolution, r.Field("resolution"));
  DB_ASSIGN_OR_RETURN(t.resolution, ReadResolution(resolution));
  DB_ASSIGN_OR_RETURN(JsonReader regime_field, r.Field("regime"));
  DB_ASSIGN_OR_RETURN(const std::string regime, regime_field.String());
  Expected<Regime> parsed = ParseRegime(regime);
  if (!parsed.ok()) return regime_field.Error(parsed.status().message());
  t.regime = *parsed;
  DB_ASSIGN_OR_RETURN(t.taps, ReadU32(r, "taps"));
  if (t.taps == 0) return r.Error("taps must be at least 1");
  DB_ASSIGN_OR_RETURN(JsonReader summary, r.Field("ns_per_pass"));
  DB_ASSIGN_OR_RETURN(t.ns_per_pass, ReadSummary(summary));
  DB_RETURN_IF_ERROR(r.ForEach("repetitions_ns", [&](const JsonReader& element) -> Status {
    DB_ASSIGN_OR_RETURN(const double ns, element.Number());
    t.repetitions_ns.push_back(ns);
    return Status::Ok();
  }));
  DB_ASSIGN_OR_RETURN(t.passes_per_repetition, ReadU32(r, "passes_per_repetition"));
  DB_ASSIGN_OR_RETURN(t.warmup_passes, ReadU32(r, "warmup_passes"));
  DB_ASSIGN_OR_RETURN(t.rank, ReadU32(r, "rank"));
  DB_RETURN_IF_ERROR(r.ForEach("indistinguishable_from", [&](const JsonReader& element) -> Status {
    DB_ASSIGN_OR_RETURN(const std::string name, element.String());
    Expected<Variant> variant = catalogue.ParseVariant(name);
    if (!variant.ok()) return element.Error(variant.status().message());
    t.indistinguishable_from.push_back(*variant);
    return Status::Ok();
  }));
  return t;
}

Expected<BandwidthProbe> ReadBandwidth(const JsonReader& r) {
  BandwidthProbe b;
  DB_ASSIGN_OR_RETURN(b.method, r.String("method"));
  DB_ASSIGN_OR_RETURN(b.bytes_read, r.Unsigned("bytes_read"));
  DB_ASSIGN_OR_RETURN(b.bytes_written, r.Unsigned("bytes_written"));
  if (b.bytes_read + b.bytes_written == 0) return r.Error("a bandwidth probe that moved no bytes");
  DB_ASSIGN_OR_RETURN(JsonReader summary, r.Field("ns_per_pass"));
  DB_ASSIGN_OR_RETURN(b.ns_per_pass, ReadSummary(summary));
  if (!(b.ns_per_pass.median > 0.0)) return summary.Error("the median must be above 0 ns");
  DB_RETURN_IF_ERROR(r.ForEach("repetitions_ns", [&](const JsonReader& element) -> Status {
    DB_ASSIGN_OR_RETURN(const double ns, element.Number());
    b.repetitions_ns.push_back(ns);
    return Status::Ok();
  }));
  DB_ASSIGN_OR_RETURN(b.passes_per_repetition, ReadU32(r, "passes_per_repetition"));
  DB_ASSIGN_OR_RETURN(b.warmup_passes, ReadU32(r, "warmup_passes"));
  return b;
}

Expected<MemoryFloor> ReadFloor(const JsonReader& r) {
  MemoryFloor f;
  DB_ASSIGN_OR_RETURN(JsonReader format_field, r.Field("format"));
  DB_ASSIGN_OR_RETURN(const std::string format, format_field.String());
  Expected<Format> parsed = ParseFormat(format);
  if (!parsed.ok()) return format_field.Error(parsed.status().message());
  f.format = *parsed;
  DB_ASSIGN_OR_RETURN(JsonReader resolution, r.Field("resolution"));
  DB_ASSIGN_OR_RETURN(f.resolution, ReadResolution(resolution));
  DB_ASSIGN_OR_RETURN(f.bytes_read_per_pixel, ReadU32(r, "bytes_read_per_pixel"));
  DB_ASSIGN_OR_RETURN(f.bytes_written_per_pixel, ReadU32(r, "bytes_written_per_pixel"));
  DB_ASSIGN_OR_RETURN(f.ns_per_pass, r.Number("ns_per_pass"));
  if (!(f.ns_per_pass > 0.0) || !std::isfinite(f.ns_per_pass)) return r.Error("ns_per_pass must be above 0");
  return f;
}

Expected<TradeFront> ReadFront(const JsonReader& r, const Catalogue& catalogue) {
  TradeFront front;
  DB_ASSIGN_OR_RETURN(JsonReader convention_field, r.Field("convention"));
  DB_ASSIGN_OR_RETURN(const std::string convention, convention_field.String());
  Expected<Convention> c = ParseConvention(convention);
  if (!c.ok()) return convention_field.Error(c.status().message());
  DB_ASSIGN_OR_RETURN(JsonReader format_field, r.Field("format"));
  DB_ASSIGN_OR_RETURN(const std::string format, format_field.String());
  Expected<Format> f = ParseFormat(format);
  if (!f.ok()) return format_field.Error(f.status().message());
  front.convention = *c;
  front.format = *f;
  DB_RETURN_IF_ERROR(r.ForEach("points", [&](const JsonReader& p) -> Status {
    TradePoint point;
    DB_ASSIGN_OR_RETURN(point.variant, ReadVariant(p, "variant", catalogue));
    if (!catalogue.Reads(point.variant, front.convention, front.format)) {
      return p.Error(fmt::format("{} does not read {} under the {} convention", catalogue.Info(point.variant).name,
                                 Info(front.format).name, Info(front.convention).name));
    }
    DB_ASSIGN_OR_RETURN(point.gpu_ns_per_reconstruction, p.Number("gpu_ns_per_reconstruction"));
    DB_ASSIGN_OR_RETURN(point.gpu_spread_ns, p.Number("gpu_spread_ns"));
    DB_ASSIGN_OR_RETURN(point.gpu_memory_ns_per_pixel, p.Number("gpu_memory_ns_per_pixel"));
    DB_ASSIGN_OR_RETURN(point.cpu_ns_per_reconstruction, p.Number("cpu_ns_per_reconstruction"));
    DB_ASSIGN_OR_RETURN(point.cpu_spread_ns, p.Number("cpu_spread_ns"));
    DB_ASSIGN_OR_RETURN(point.p999_bits_lost, p.Number("p999_bits_lost"));
    DB_ASSIGN_OR_RETURN(point.nonfinite, p.Unsigned("nonfinite"));
    DB_ASSIGN_OR_RETURN(point.on_gpu_front, p.Bool("on_gpu_front"));
    DB_ASSIGN_OR_RETURN(point.on_cpu_front, p.Bool("on_cpu_front"));
    front.points.push_back(point);
    return Status::Ok();
  }));
  return front;
}

}  // namespace

Expected<SpeedResults> SpeedResultsFromJson(const json& j, const std::string& source, const Catalogue& catalogue) {
  const JsonReader top(j, source);
  DB_RETURN_IF_ERROR(top.CheckSchema(kSpeedSchema));
  SpeedResults results;
  results.catalogue = &catalogue;
  DB_ASSIGN_OR_RETURN(JsonReader run, top.Field("run"));
  DB_ASSIGN_OR_RETURN(results.run, ReadRun(run));
  // Files made before the bandwidth probe have neither part.
  if (top.Has("bandwidth")) {
    DB_ASSIGN_OR_RETURN(JsonReader bandwidth, top.Field("bandwidth"));
    DB_ASSIGN_OR_RETURN(results.bandwidth, ReadBandwidth(bandwidth));
    DB_RETURN_IF_ERROR(top.ForEach("memory_floor", [&](const JsonReader& r) -> Status {
      DB_ASSIGN_OR_RETURN(MemoryFloor floor, ReadFloor(r));
      results.floors.push_back(floor);
      return Status::Ok();
    }));
  }
  DB_RETURN_IF_ERROR(top.ForEach("gpu", [&](const JsonReader& r) -> Status {
    DB_ASSIGN_OR_RETURN(GpuTiming timing, ReadGpuTiming(r, catalogue));
    results.gpu.push_back(std::move(timing));
    return Status::Ok();
  }));
  DB_RETURN_IF_ERROR(top.ForEach("static", [&](const JsonReader& r) -> Status {
    StaticCost cost;
    DB_ASSIGN_OR_RETURN(cost.variant, ReadVariant(r, "variant", catalogue));
    DB_ASSIGN_OR_RETURN(cost.function, r.String("function"));
    DB_ASSIGN_OR_RETURN(JsonReader mix, r.Field("mix"));
    DB_ASSIGN_OR_RETURN(cost.mix, ReadMix(mix));
    results.static_costs.push_back(std::move(cost));
    return Status::Ok();
  }));
  DB_RETURN_IF_ERROR(top.ForEach("cpu", [&](const JsonReader& r) -> Status {
    CpuCost cost;
    DB_ASSIGN_OR_RETURN(cost.cell, ReadCell(r, "cell", catalogue));
    DB_ASSIGN_OR_RETURN(JsonReader summary, r.Field("ns_per_reconstruction"));
    DB_ASSIGN_OR_RETURN(cost.ns_per_reconstruction, ReadSummary(summary));
    DB_ASSIGN_OR_RETURN(cost.runs_per_repetition, ReadU32(r, "runs_per_repetition"));
    DB_ASSIGN_OR_RETURN(cost.samples_per_run, ReadU32(r, "samples_per_run"));
    results.cpu.push_back(cost);
    return Status::Ok();
  }));
  DB_RETURN_IF_ERROR(top.ForEach("trade", [&](const JsonReader& r) -> Status {
    DB_ASSIGN_OR_RETURN(TradeFront front, ReadFront(r, catalogue));
    results.trade.push_back(std::move(front));
    return Status::Ok();
  }));
  DB_RETURN_IF_ERROR(top.ForEach("skipped", [&](const JsonReader& r) -> Status {
    DB_ASSIGN_OR_RETURN(std::string text, r.String());
    results.skipped.push_back(std::move(text));
    return Status::Ok();
  }));
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
