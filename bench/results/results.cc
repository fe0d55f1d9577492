#include "bench/results/results.h"

#include <algorithm>
#include <charconv>
#include <map>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/json_reader.h"

namespace depthbench {

using nlohmann::json;

std::uint64_t Shard::Begin(std::uint64_t total) const {
  return static_cast<std::uint64_t>(static_cast<unsigned __int128>(total) * (index - 1) / count);
}
std::uint64_t Shard::End(std::uint64_t total) const {
  return static_cast<std::uint64_t>(static_cast<unsigned __int128>(total) * index / count);
}
std::string Shard::ToString() const { return fmt::format("{}/{}", index, count); }

Expected<Shard> ParseShard(std::string_view text) {
  auto slash = text.find('/');
  Shard shard;
  auto parse = [](std::string_view s, std::uint32_t& out) {
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && end == s.data() + s.size();
  };
  if (slash == std::string_view::npos || !parse(text.substr(0, slash), shard.index) ||
      !parse(text.substr(slash + 1), shard.count) || shard.count == 0 || shard.index == 0 ||
      shard.index > shard.count) {
    return InvalidArgument(fmt::format("--shard: '{}' is not K/N with 1 <= K <= N (shard K of N, e.g. 2/4)", text));
  }
  return shard;
}

std::vector<Shard> MissingShards(const std::vector<Shard>& held) {
  if (held.empty()) return {};
  const std::uint32_t count = held.front().count;
  std::vector<Shard> missing;
  for (const Shard& s : held)
    if (s.count != count) return {};
  for (std::uint32_t index = 1; index <= count; ++index) {
    const Shard shard{index, count};
    if (std::find(held.begin(), held.end(), shard) == held.end()) missing.push_back(shard);
  }
  return missing;
}

std::string ShardList(const std::vector<Shard>& shards) {
  // A shard of a sweep split a thousand ways lacks 999 others: its header
  // and merge's message name the first few and count the rest.
  constexpr std::size_t kNamed = 10;
  std::string out;
  for (std::size_t i = 0; i < shards.size() && i < kNamed; ++i) out += (i == 0 ? "" : ", ") + shards[i].ToString();
  if (shards.size() > kNamed) out += fmt::format(" and {} more", shards.size() - kNamed);
  return out;
}

const CellResult* Results::Find(const Cell& cell, const std::string& backend) const {
  for (const CellResult& c : cells)
    if (c.cell == cell && c.backend == backend) return &c;
  return nullptr;
}

void StageSeconds::AddDevicePass(const std::string& name, double seconds) {
  auto it = std::find_if(device_passes.begin(), device_passes.end(), [&](const auto& p) { return p.first == name; });
  if (it == device_passes.end()) {
    device_passes.emplace_back(name, seconds);
  } else {
    it->second += seconds;
  }
}

// ---------------------------------------------------------------- writing

namespace {

json RangeToJson(const Range& r) { return json::array({r.min, r.max}); }

json MetricToJson(const MetricStats& m) {
  json bins = json::array();
  for (const auto& [slot, count] : m.bins) bins.push_back(json::array({slot, count}));
  return {{"max_square", JsonNumber(m.max_square)},
          {"max", JsonNumber(m.max())},  // for readers; max_square is the exact record
          {"worst_index", JsonIndex(m.worst_index)},
          {"bins", bins}};
}

json BandToJson(const BandStats& b) {
  json metrics = json::object();
  for (int m = 0; m < kMetricCount; ++m) metrics[MetricName(static_cast<Metric>(m))] = MetricToJson(b.metrics[m]);
  return {{"finite", b.finite},
          {"nan", b.nan},
          {"inf", b.inf},
          {"stored_nonfinite", b.stored_nonfinite},
          {"degenerate", b.degenerate},
          {"outside", b.outside},
          {"first_nonfinite_index", JsonIndex(b.first_nonfinite_index)},
          {"metrics", metrics}};
}

json SummaryToJson(const BandStats& all) {
  json out = json::object();
  for (int m = 0; m < kMetricCount; ++m) {
    Metric metric = static_cast<Metric>(m);
    Summary s = Summarize(all, metric);
    json entry = {{"p50", JsonNumber(s.p50)},
                  {"p99", JsonNumber(s.p99)},
                  {"p999", JsonNumber(s.p999)},
                  {"max", JsonNumber(s.max)},
                  {"worst_index", JsonIndex(s.worst_index)}};
    entry["p999_low"] = JsonNumber(s.p999_interval.low);
    entry["p999_high"] = JsonNumber(s.p999_interval.high);
    entry["p999_supported"] = s.p999_supported;
    if (metric != Metric::kAbsolute) {
      entry["p50_bits"] = BitsLost(s.p50);
      entry["p99_bits"] = BitsLost(s.p99);
      entry["p999_bits"] = BitsLost(s.p999);
      entry["p999_low_bits"] = BitsLost(s.p999_interval.low);
      entry["p999_high_bits"] = BitsLost(s.p999_interval.high);
      entry["max_bits"] = JsonNumber(BitsLost(s.max));
    }
    out[MetricName(metric)] = entry;
  }
  return out;
}

}  // namespace

json DeviceToJson(const DeviceInfo& d) {
  return {{"name", d.name}, {"driver", d.driver}, {"api", d.api}, {"kind", DeviceKindName(d.kind)}, {"compiler", d.compiler}};
}

Expected<DeviceInfo> DeviceFromJson(const JsonReader& r) {
  DeviceInfo d;
  DB_ASSIGN_OR_RETURN(d.name, r.String("name"));
  DB_ASSIGN_OR_RETURN(d.driver, r.String("driver"));
  DB_ASSIGN_OR_RETURN(d.api, r.String("api"));
  DB_ASSIGN_OR_RETURN(const JsonReader kind_field, r.Field("kind"));
  DB_ASSIGN_OR_RETURN(const std::string kind, kind_field.String());
  const std::optional<DeviceKind> parsed = ParseDeviceKind(kind);
  if (!parsed) return kind_field.Error(fmt::format("'{}' is not a device kind; allowed: cpu, gpu", kind));
  d.kind = *parsed;
  DB_ASSIGN_OR_RETURN(d.compiler, r.String("compiler"));
  return d;
}

json DomainToJson(const Domain& d) {
  json resolutions = json::array();
  for (const auto& r : d.resolutions) resolutions.push_back(json::array({r.width, r.height}));
  json out = {{"fov_degrees", RangeToJson(d.fov_degrees)},
              {"aspect", RangeToJson(d.aspect)},
              {"near", RangeToJson(d.near)},
              {"ratio", RangeToJson(d.ratio)},
              {"finite_far", d.finite_far},
              {"infinite_far", d.infinite_far},
              {"far", d.far ? RangeToJson(*d.far) : json(nullptr)},
              {"camera_distance", RangeToJson(d.camera_distance)},
              {"eye_depth", d.eye_depth ? RangeToJson(*d.eye_depth) : json(nullptr)},
              {"resolutions", resolutions},
              {"name", d.name},
              {"production", ProductionModelName(d.production)},
              {"constants", ConstantsModelName(d.constants)}};
  return out;
}

json ToJson(const Results& results) {
  const RunInfo& run = results.run;
  json shards = json::array();
  for (const Shard& s : run.shards) shards.push_back(s.ToString());
  json backends = json::array();
  for (const auto& b : run.backends) {
    backends.push_back({{"name", b.name},
                        {"device", DeviceToJson(b.device)},
                        {"shaders", b.program.shaders},
                        {"program_hash", b.program.hash},
                        {"judge", b.judge}});
  }
  json run_cells = json::array();
  for (const Cell& c : run.cells) run_cells.push_back(c.Name());
  json device_passes = json::array();
  for (const auto& [name, seconds] : run.stages.device_passes) {
    device_passes.push_back({{"pass", name}, {"seconds", seconds}});
  }

  json cells = json::array();
  for (const CellResult& c : results.cells) {
    BandStats all = c.stats.All();
    json joint = json::array();
    for (const auto& [band, stats] : c.stats.joint) {
      json entry = BandToJson(stats);
      entry["ratio_band"] = RatioOfJoint(band);
      entry["depth_band"] = DepthOfJoint(band);
      entry["ratio"] = RatioBandName(RatioOfJoint(band));
      entry["depth"] = DepthBandName(DepthOfJoint(band));
      joint.push_back(entry);
    }
    json distance = json::array();
    for (const auto& [band, stats] : c.stats.distance) {
      json entry = BandToJson(stats);
      entry["distance_band"] = band;
      entry["distance"] = DistanceBandName(band);
      distance.push_back(entry);
    }
    json coverage = json::array();
    for (const auto& [band, stats] : c.stats.coverage) {
      json entry = BandToJson(stats);
      entry["coverage_band"] = band;
      entry["coverage"] = CoverageBandName(band);
      coverage.push_back(entry);
    }
    cells.push_back({{"cell", c.cell.Name()},
                     {"variant", Info(c.cell.variant).name},
                     {"convention", Info(c.cell.convention).name},
                     {"format", Info(c.cell.format).name},
                     {"backend", c.backend},
                     {"counts",
                      {{"finite", all.finite},
                       {"nan", all.nan},
                       {"inf", all.inf},
                       {"stored_nonfinite", all.stored_nonfinite},
                       {"degenerate", all.degenerate},
                       {"outside", all.outside},
                       {"first_nonfinite_index", JsonIndex(all.first_nonfinite_index)}}},
                     {"summary", SummaryToJson(all)},
                     {"bands", {{"joint", joint}, {"distance", distance}, {"coverage", coverage}}}});
  }

  return WithSchema(kResultsSchema, {{"run",
                                      {{"version", run.version},
                                       {"commit", run.commit},
                                       {"started_at", run.started_at},
                                       {"host", run.host},
                                       {"seed", run.seed},
                                       {"samples", run.samples},
                                       {"samples_per_frame", run.samples_per_frame},
                                       {"shards", shards},
                                       {"partial", run.partial},
                                       {"samples_judged", run.samples_judged},
                                       {"cells", run_cells},
                                       {"domain", DomainToJson(run.domain)},
                                       {"backends", backends},
                                       {"seconds", run.seconds},
                                       {"stage_seconds",
                                        {{"setup", run.stages.setup},
                                         {"build", run.stages.build},
                                         {"judging", run.stages.judging},
                                         {"build_waited", run.stages.build_waited},
                                         {"device_waited", run.stages.device_waited},
                                         {"device_passes", device_passes}}},
                                       {"reconstructions", run.reconstructions}}},
                                     {"cells", cells}});
}

Status WriteResults(const std::filesystem::path& path, const Results& results) {
  return WriteFileAtomically(path, ToJson(results).dump(1) + "\n");
}

// ---------------------------------------------------------------- reading

namespace {

Expected<Range> RangeFrom(const JsonReader& r) {
  DB_ASSIGN_OR_RETURN(std::size_t n, r.ArraySize());
  if (n != 2) return r.Error("expected [min, max]");
  DB_ASSIGN_OR_RETURN(JsonReader lo, r.Element(0));
  DB_ASSIGN_OR_RETURN(JsonReader hi, r.Element(1));
  DB_ASSIGN_OR_RETURN(double min, lo.Number());
  DB_ASSIGN_OR_RETURN(double max, hi.Number());
  return Range{min, max};
}

Expected<MetricStats> MetricFrom(const JsonReader& r) {
  MetricStats m;
  DB_ASSIGN_OR_RETURN(m.max_square, r.Number("max_square"));
  DB_ASSIGN_OR_RETURN(m.worst_index, r.Unsigned("worst_index"));
  DB_RETURN_IF_ERROR(r.ForEach("bins", [&](const JsonReader& pair) -> Status {
    DB_ASSIGN_OR_RETURN(JsonReader slot, pair.Element(0));
    DB_ASSIGN_OR_RETURN(JsonReader count, pair.Element(1));
    DB_ASSIGN_OR_RETURN(std::int64_t s, slot.Integer());
    DB_ASSIGN_OR_RETURN(std::uint64_t c, count.Unsigned());
    if (s < 0 || s >= kDenseBins) return slot.Error(fmt::format("bin {} outside [0, {})", s, kDenseBins));
    m.bins[static_cast<int>(s)] += c;
    return Status::Ok();
  }));
  return m;
}

Expected<BandStats> BandFrom(const JsonReader& r) {
  BandStats b;
  DB_ASSIGN_OR_RETURN(b.finite, r.Unsigned("finite"));
  DB_ASSIGN_OR_RETURN(b.nan, r.Unsigned("nan"));
  DB_ASSIGN_OR_RETURN(b.inf, r.Unsigned("inf"));
  DB_ASSIGN_OR_RETURN(b.stored_nonfinite, r.Unsigned("stored_nonfinite"));
  DB_ASSIGN_OR_RETURN(b.degenerate, r.Unsigned("degenerate"));
  DB_ASSIGN_OR_RETURN(b.outside, r.Unsigned("outside"));
  DB_ASSIGN_OR_RETURN(b.first_nonfinite_index, r.Unsigned("first_nonfinite_index"));
  DB_ASSIGN_OR_RETURN(JsonReader metrics, r.Field("metrics"));
  for (int m = 0; m < kMetricCount; ++m) {
    DB_ASSIGN_OR_RETURN(JsonReader metric, metrics.Field(MetricName(static_cast<Metric>(m))));
    DB_ASSIGN_OR_RETURN(b.metrics[m], MetricFrom(metric));
  }
  return b;
}

Expected<int> BandIndex(const JsonReader& r, const std::string& key, int count) {
  DB_ASSIGN_OR_RETURN(std::int64_t v, r.Integer(key));
  if (v < 0 || v >= count) return r.Error(fmt::format("{} {} outside [0, {})", key, v, count));
  return static_cast<int>(v);
}

// An optional field naming a model (ProductionModel, ConstantsModel):
// `missing` for files written before the field existed.
template <class Model>
Status ReadModel(const JsonReader& r, const char* field, Expected<Model> (*parse)(std::string_view), Model missing,
                 Model& out) {
  out = missing;
  if (!r.Has(field)) return Status::Ok();
  DB_ASSIGN_OR_RETURN(const JsonReader value, r.Field(field));
  DB_ASSIGN_OR_RETURN(const std::string name, value.String());
  const Expected<Model> model = parse(name);
  if (!model.ok()) return value.Error(model.status().message());
  out = *model;
  return Status::Ok();
}

}  // namespace

Expected<Domain> DomainFromJson(const json& j, const std::string& source) {
  JsonReader r(j, source, "run.domain");
  Domain d;
  auto range = [&](const std::string& key) -> Expected<Range> {
    DB_ASSIGN_OR_RETURN(JsonReader f, r.Field(key));
    return RangeFrom(f);
  };
  auto optional_range = [&](const std::string& key, std::optional<Range>& out) -> Status {
    DB_ASSIGN_OR_RETURN(JsonReader f, r.Field(key));
    if (f.json().is_null()) return Status::Ok();
    DB_ASSIGN_OR_RETURN(Range value, RangeFrom(f));
    out = value;
    return Status::Ok();
  };
  DB_ASSIGN_OR_RETURN(d.fov_degrees, range("fov_degrees"));
  DB_ASSIGN_OR_RETURN(d.aspect, range("aspect"));
  DB_ASSIGN_OR_RETURN(d.near, range("near"));
  DB_ASSIGN_OR_RETURN(d.ratio, range("ratio"));
  DB_ASSIGN_OR_RETURN(d.finite_far, r.Bool("finite_far"));
  DB_ASSIGN_OR_RETURN(d.infinite_far, r.Bool("infinite_far"));
  DB_RETURN_IF_ERROR(optional_range("far", d.far));
  DB_ASSIGN_OR_RETURN(d.camera_distance, range("camera_distance"));
  DB_RETURN_IF_ERROR(optional_range("eye_depth", d.eye_depth));
  d.resolutions.clear();
  DB_RETURN_IF_ERROR(r.ForEach("resolutions", [&](const JsonReader& pair) -> Status {
    DB_ASSIGN_OR_RETURN(JsonReader w, pair.Element(0));
    DB_ASSIGN_OR_RETURN(JsonReader h, pair.Element(1));
    DB_ASSIGN_OR_RETURN(std::uint64_t width, w.Unsigned());
    DB_ASSIGN_OR_RETURN(std::uint64_t height, h.Unsigned());
    d.resolutions.push_back({static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)});
    return Status::Ok();
  }));
  // Files written before these fields existed: their depth was produced
  // exactly, and their domain had no name.
  d.name = "custom";
  if (r.Has("name")) DB_RETURN_IF_ERROR(StoreInto(r.String("name"), d.name));
  DB_RETURN_IF_ERROR(ReadModel(r, "production", ParseProductionModel, ProductionModel::kExact, d.production));
  // Files written before --constants existed had exact constants.
  DB_RETURN_IF_ERROR(ReadModel(r, "constants", ParseConstantsModel, ConstantsModel::kExact, d.constants));
  Status valid = d.Validate();
  if (!valid.ok()) return r.Error(valid.message());
  return d;
}

Expected<Results> ResultsFromJson(const json& j, const std::string& source) {
  JsonReader top(j, source);
  DB_RETURN_IF_ERROR(top.CheckSchema(kResultsSchema));
  Results results;
  RunInfo& run = results.run;
  DB_ASSIGN_OR_RETURN(JsonReader r, top.Field("run"));
  DB_ASSIGN_OR_RETURN(run.version, r.String("version"));
  DB_ASSIGN_OR_RETURN(run.commit, r.String("commit"));
  DB_ASSIGN_OR_RETURN(run.started_at, r.String("started_at"));
  DB_ASSIGN_OR_RETURN(run.host, r.String("host"));
  DB_ASSIGN_OR_RETURN(run.seed, r.Unsigned("seed"));
  DB_ASSIGN_OR_RETURN(run.samples, r.Unsigned("samples"));
  DB_ASSIGN_OR_RETURN(std::uint64_t per_frame, r.Unsigned("samples_per_frame"));
  run.samples_per_frame = static_cast<std::uint32_t>(per_frame);
  DB_ASSIGN_OR_RETURN(run.seconds, r.Number("seconds"));
  DB_ASSIGN_OR_RETURN(run.reconstructions, r.Unsigned("reconstructions"));
  if (r.Has("stage_seconds")) {
    DB_ASSIGN_OR_RETURN(JsonReader stages, r.Field("stage_seconds"));
    DB_ASSIGN_OR_RETURN(run.stages.setup, stages.Number("setup"));
    DB_ASSIGN_OR_RETURN(run.stages.build, stages.Number("build"));
    DB_ASSIGN_OR_RETURN(run.stages.judging, stages.Number("judging"));
    DB_ASSIGN_OR_RETURN(run.stages.build_waited, stages.Number("build_waited"));
    DB_ASSIGN_OR_RETURN(run.stages.device_waited, stages.Number("device_waited"));
    if (stages.Has("device_passes")) {
      DB_RETURN_IF_ERROR(stages.ForEach("device_passes", [&](const JsonReader& pass) -> Status {
        DB_ASSIGN_OR_RETURN(std::string name, pass.String("pass"));
        DB_ASSIGN_OR_RETURN(double seconds, pass.Number("seconds"));
        run.stages.AddDevicePass(name, seconds);
        return Status::Ok();
      }));
    }
  }
  DB_RETURN_IF_ERROR(r.ForEach("shards", [&](const JsonReader& s) -> Status {
    DB_ASSIGN_OR_RETURN(std::string text, s.String());
    Expected<Shard> shard = ParseShard(text);
    if (!shard.ok()) return s.Error(shard.status().message());
    run.shards.push_back(*shard);
    return Status::Ok();
  }));
  DB_ASSIGN_OR_RETURN(run.partial, r.Bool("partial"));
  DB_ASSIGN_OR_RETURN(run.samples_judged, r.Unsigned("samples_judged"));
  DB_RETURN_IF_ERROR(r.ForEach("cells", [&](const JsonReader& c) -> Status {
    DB_ASSIGN_OR_RETURN(std::string name, c.String());
    Expected<Cell> cell = ParseCell(name);
    if (!cell.ok()) return c.Error(cell.status().message());
    run.cells.push_back(*cell);
    return Status::Ok();
  }));
  DB_ASSIGN_OR_RETURN(JsonReader domain, r.Field("domain"));
  DB_ASSIGN_OR_RETURN(run.domain, DomainFromJson(domain.json(), source));
  DB_RETURN_IF_ERROR(r.ForEach("backends", [&](const JsonReader& b) -> Status {
    BackendRecord record;
    DB_ASSIGN_OR_RETURN(record.name, b.String("name"));
    DB_ASSIGN_OR_RETURN(JsonReader device, b.Field("device"));
    DB_ASSIGN_OR_RETURN(record.device, DeviceFromJson(device));
    DB_ASSIGN_OR_RETURN(record.program.shaders, b.String("shaders"));
    DB_ASSIGN_OR_RETURN(record.program.hash, b.String("program_hash"));
    if (b.Has("judge")) {  // (older files lack it: judged on the host)
      DB_RETURN_IF_ERROR(StoreInto(b.String("judge"), record.judge));
      if (record.judge != "host" && record.judge != "device") {
        return b.Error("judge must be \"host\" or \"device\", not \"" + record.judge + "\"");
      }
    }
    run.backends.push_back(record);
    return Status::Ok();
  }));

  DB_RETURN_IF_ERROR(top.ForEach("cells", [&](const JsonReader& c) -> Status {
    CellResult result;
    DB_ASSIGN_OR_RETURN(std::string name, c.String("cell"));
    Expected<Cell> cell = ParseCell(name);
    if (!cell.ok()) return c.Error(cell.status().message());
    result.cell = *cell;
    DB_ASSIGN_OR_RETURN(result.backend, c.String("backend"));
    DB_ASSIGN_OR_RETURN(JsonReader bands, c.Field("bands"));
    DB_RETURN_IF_ERROR(bands.ForEach("joint", [&](const JsonReader& b) -> Status {
      DB_ASSIGN_OR_RETURN(int ratio, BandIndex(b, "ratio_band", kRatioBands));
      DB_ASSIGN_OR_RETURN(int depth, BandIndex(b, "depth_band", kDepthBands));
      DB_ASSIGN_OR_RETURN(BandStats stats, BandFrom(b));
      result.stats.joint[JointBand(ratio, depth)].Merge(stats);
      return Status::Ok();
    }));
    DB_RETURN_IF_ERROR(bands.ForEach("distance", [&](const JsonReader& b) -> Status {
      DB_ASSIGN_OR_RETURN(int band, BandIndex(b, "distance_band", kDistanceBands));
      DB_ASSIGN_OR_RETURN(BandStats stats, BandFrom(b));
      result.stats.distance[band].Merge(stats);
      return Status::Ok();
    }));
    DB_RETURN_IF_ERROR(bands.ForEach("coverage", [&](const JsonReader& b) -> Status {
      DB_ASSIGN_OR_RETURN(int band, BandIndex(b, "coverage_band", kCoverageBands));
      DB_ASSIGN_OR_RETURN(BandStats stats, BandFrom(b));
      result.stats.coverage[band].Merge(stats);
      return Status::Ok();
    }));
    results.cells.push_back(std::move(result));
    return Status::Ok();
  }));
  return results;
}

Expected<Results> ReadResults(const std::filesystem::path& path) {
  DB_ASSIGN_OR_RETURN(const json j, ReadJsonFile(path));
  return ResultsFromJson(j, path.string());
}

// ---------------------------------------------------------------- merging

namespace {

std::string Join(const std::vector<std::string>& parts) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : ",") + p;
  return out;
}

std::string CellList(const std::vector<Cell>& cells) {
  std::vector<std::string> names;
  for (const Cell& c : cells) names.push_back(c.Name());
  return Join(names);
}

std::string BackendList(const std::vector<BackendRecord>& backends, std::string (*what)(const BackendRecord&)) {
  std::vector<std::string> out;
  for (const BackendRecord& b : backends) out.push_back(b.name + "=" + what(b));
  return Join(out);
}

// What defines a sweep, field by field, as text: two parts merge only when
// every field reads the same. Names are those of the JSON (run.FIELD).
std::vector<std::pair<std::string, std::string>> SweepIdentity(const RunInfo& run) {
  std::vector<std::string> names;
  for (const BackendRecord& b : run.backends) names.push_back(b.name);
  return {
      {"version", run.version},
      {"seed", std::to_string(run.seed)},
      {"samples", std::to_string(run.samples)},
      {"samples_per_frame", std::to_string(run.samples_per_frame)},
      {"domain", DomainToJson(run.domain).dump()},
      {"cells", CellList(run.cells)},
      {"backends", Join(names)},
      {"backends.device", BackendList(run.backends,
                                      [](const BackendRecord& b) {
                                        return b.device.name + " [" + b.device.driver + "; " + b.device.compiler + "]";
                                      })},
      {"backends.shaders", BackendList(run.backends, [](const BackendRecord& b) { return b.program.shaders; })},
      {"backends.program_hash", BackendList(run.backends, [](const BackendRecord& b) { return b.program.hash; })},
  };
}

// A value in a message: long ones (the domain, every cell) cut short.
std::string Quoted(const std::string& value) {
  constexpr std::size_t kShown = 160;
  return "'" + (value.size() <= kShown ? value : value.substr(0, kShown) + "...") + "'";
}

}  // namespace

Expected<Results> MergeResults(const std::vector<Results>& parts, const std::vector<std::string>& sources,
                               bool allow_partial) {
  if (parts.empty()) return InvalidArgument("nothing to merge");
  const auto name = [&](std::size_t p) {
    return p < sources.size() ? fmt::format("'{}'", sources[p]) : fmt::format("part {}", p + 1);
  };
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const RunInfo& run = parts[p].run;
    if (run.partial && !allow_partial) {
      return InvalidArgument(fmt::format(
          "{} is partial: its sweep was interrupted after {} of its shards' samples; run it again, or merge with "
          "--allow-partial to add up what it judged",
          name(p), run.samples_judged));
    }
  }
  const auto identity = SweepIdentity(parts.front().run);
  Results merged = parts.front();
  for (std::size_t p = 1; p < parts.size(); ++p) {
    const Results& part = parts[p];
    const auto other = SweepIdentity(part.run);
    for (std::size_t f = 0; f < identity.size(); ++f) {
      if (identity[f].second != other[f].second) {
        return InvalidArgument(fmt::format(
            "{} is not a shard of the same sweep as {}: run.{} differs: {} in {}, {} in {}", name(p), name(0),
            identity[f].first, Quoted(identity[f].second), name(0), Quoted(other[f].second), name(p)));
      }
    }
    for (const Shard& s : part.run.shards) {
      for (const Shard& held : merged.run.shards) {
        if (s.count != held.count) {
          return InvalidArgument(fmt::format(
              "shards {} and {} are of different splits (into {} and into {} shards): merge the shards of one "
              "--shard K/N split",
              held.ToString(), s.ToString(), held.count, s.count));
        }
        if (s == held) return InvalidArgument(fmt::format("shard {} is given twice ({})", s.ToString(), name(p)));
      }
      merged.run.shards.push_back(s);
    }
    merged.run.seconds += part.run.seconds;
    StageSeconds& stages = merged.run.stages;
    stages.setup += part.run.stages.setup;
    stages.build += part.run.stages.build;
    stages.judging += part.run.stages.judging;
    stages.build_waited += part.run.stages.build_waited;
    stages.device_waited += part.run.stages.device_waited;
    for (const auto& [name, seconds] : part.run.stages.device_passes) stages.AddDevicePass(name, seconds);
    merged.run.reconstructions += part.run.reconstructions;
    merged.run.samples_judged += part.run.samples_judged;
    merged.run.partial = merged.run.partial || part.run.partial;
    for (const CellResult& c : part.cells) {
      auto it = std::find_if(merged.cells.begin(), merged.cells.end(),
                             [&](const CellResult& m) { return m.cell == c.cell && m.backend == c.backend; });
      if (it == merged.cells.end()) {
        merged.cells.push_back(c);
      } else {
        it->stats.Merge(c.stats);
      }
    }
  }
  std::sort(merged.run.shards.begin(), merged.run.shards.end());
  return merged;
}

}  // namespace depthbench
