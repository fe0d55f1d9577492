#include "bench/results/results.h"

#include <algorithm>
#include <map>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/json_fields.h"
#include "bench/base/json_reader.h"
#include "bench/base/parse_number.h"

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
  const std::size_t slash = text.find('/');
  const auto number = [](std::string_view digits) { return ParseDigits<std::uint32_t>(digits).value_or(0); };
  const Shard shard = slash == std::string_view::npos
                          ? Shard{0, 0}
                          : Shard{number(text.substr(0, slash)), number(text.substr(slash + 1))};
  if (shard.count == 0 || shard.index == 0 || shard.index > shard.count) {
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

namespace {
// Adds `seconds` to the entry called `name`, a new one going last.
void AddNamedSeconds(std::vector<std::pair<std::string, double>>& to, const std::string& name, double seconds) {
  auto it = std::find_if(to.begin(), to.end(), [&](const auto& p) { return p.first == name; });
  if (it == to.end()) {
    to.emplace_back(name, seconds);
  } else {
    it->second += seconds;
  }
}
}  // namespace

void StageSeconds::AddDevicePass(const std::string& name, double seconds) {
  AddNamedSeconds(device_passes, name, seconds);
}
void StageSeconds::AddJudgeHostStep(const std::string& name, double seconds) {
  AddNamedSeconds(judge_host_steps, name, seconds);
}

// ---------------------------------------------------------------- fields

namespace {

// The two elements of an array of exactly two ([min, max], [width, height]).
Expected<std::pair<JsonReader, JsonReader>> TwoElements(const JsonReader& r, const char* spelled) {
  DB_ASSIGN_OR_RETURN(const std::size_t n, r.ArraySize());
  if (n != 2) return r.Error(fmt::format("expected {}", spelled));
  DB_ASSIGN_OR_RETURN(JsonReader first, r.Element(0));
  DB_ASSIGN_OR_RETURN(JsonReader second, r.Element(1));
  return std::pair<JsonReader, JsonReader>(std::move(first), std::move(second));
}

// A range as [min, max].
struct RangeCodec {
  json Write(const Range& r) const { return json::array({JsonReal().Write(r.min), JsonReal().Write(r.max)}); }
  Status Read(const JsonReader& r, Range& out) const {
    DB_ASSIGN_OR_RETURN(const auto elements, TwoElements(r, "[min, max]"));
    DB_RETURN_IF_ERROR(JsonReal().Read(elements.first, out.min));
    return JsonReal().Read(elements.second, out.max);
  }
};

// A resolution as [width, height].
struct ResolutionPairCodec {
  json Write(const Resolution& r) const { return json::array({r.width, r.height}); }
  Status Read(const JsonReader& r, Resolution& out) const {
    DB_ASSIGN_OR_RETURN(const auto elements, TwoElements(r, "[width, height]"));
    DB_RETURN_IF_ERROR(JsonInteger<std::uint32_t>().Read(elements.first, out.width));
    return JsonInteger<std::uint32_t>().Read(elements.second, out.height);
  }
};

// A metric's histogram as [slot, count] pairs, slots within the dense bins.
struct BinsCodec {
  json Write(const std::map<int, std::uint64_t>& bins) const {
    json out = json::array();
    for (const auto& [slot, count] : bins) out.push_back(json::array({slot, count}));
    return out;
  }
  // As written: slots ascending, each once, each count at least 1, and
  // their sum within 64 bits; anything else is a changed or damaged file.
  Status Read(const JsonReader& r, std::map<int, std::uint64_t>& out) const {
    out.clear();
    std::uint64_t sum = 0;
    return r.ForEach([&](const JsonReader& pair) -> Status {
      DB_ASSIGN_OR_RETURN(const auto elements, TwoElements(pair, "[slot, count]"));
      int slot = 0;
      DB_RETURN_IF_ERROR((JsonInteger<int>{0, kDenseBins - 1}.Read(elements.first, slot)));
      if (out.contains(slot)) return elements.first.Error(fmt::format("bin {} is given twice", slot));
      if (!out.empty() && slot < out.rbegin()->first) {
        return elements.first.Error(fmt::format("bin {} follows bin {}: bins are listed in ascending order", slot,
                                                out.rbegin()->first));
      }
      std::uint64_t count = 0;
      DB_RETURN_IF_ERROR((JsonInteger<std::uint64_t>{1}.Read(elements.second, count)));
      if (__builtin_add_overflow(sum, count, &sum)) {
        return elements.second.Error("the bins' counts add up past 2^64");
      }
      out[slot] = count;
      return Status::Ok();
    });
  }
};

const JsonFields<MetricStats>& MetricFields() {
  static const JsonFields<MetricStats> fields{{
      JsonMember("max_square", &MetricStats::max_square),
      JsonDerived<MetricStats>("max", [](const MetricStats& m) { return JsonNumber(m.max()); }),
      JsonMember("worst_index", &MetricStats::worst_index, JsonIndexOrNull()),
      JsonMember("bins", &MetricStats::bins, BinsCodec()),
  }};
  return fields;
}

// Every metric, under its name.
using MetricsArray = std::array<MetricStats, kMetricCount>;
const JsonFields<MetricsArray>& MetricsFields() {
  static const JsonFields<MetricsArray> fields = [] {
    JsonFields<MetricsArray> list;
    for (int m = 0; m < kMetricCount; ++m) {
      list.fields.push_back(JsonAccess<MetricsArray>(
          MetricName(static_cast<Metric>(m)), [m](auto& metrics) -> auto& { return metrics[m]; },
          JsonObject{MetricFields()}));
    }
    return list;
  }();
  return fields;
}

// A band's counts; a cell's "counts" are those of all its natural bands.
const JsonFields<BandStats>& BandCountFields() {
  static const JsonFields<BandStats> fields{{
      JsonMember("finite", &BandStats::finite),
      JsonMember("nan", &BandStats::nan),
      JsonMember("inf", &BandStats::inf),
      JsonMember("stored_nonfinite", &BandStats::stored_nonfinite),
      JsonMember("degenerate", &BandStats::degenerate),
      JsonMember("outside", &BandStats::outside),
      // Only the raster form has undrawn samples: written where there are
      // some, and 0 where a file has none.
      JsonOnlyIf(JsonMemberOr("undrawn", &BandStats::undrawn, JsonDefaultCodec<std::uint64_t>::type{}, 0),
                 [](const BandStats& band) { return band.undrawn != 0; }),
      JsonMember("first_nonfinite_index", &BandStats::first_nonfinite_index, JsonIndexOrNull()),
  }};
  return fields;
}

const JsonFields<BandStats>& BandFields() {
  static const JsonFields<BandStats> fields = [] {
    JsonFields<BandStats> list = BandCountFields();
    list.fields.push_back(JsonMember("metrics", &BandStats::metrics, JsonObject{MetricsFields()}));
    return list;
  }();
  return fields;
}

// A band index in [0, count), as `key`, with its name beside it as `name_key`
// (for readers; not read back).
JsonFields<int> BandKeyFields(const char* key, int count, const char* name_key, std::string (*name)(int)) {
  return {{JsonAccess<int>(
               key, [](auto& band) -> auto& { return band; }, JsonInteger<int>{0, count - 1}),
           JsonDerived<int>(name_key, name)}};
}

// One half of a joint band (ratio or depth), in its own field.
JsonField<int> JointHalf(const char* key, int count, int (*half)(int joint), int (*with)(int joint, int half)) {
  const JsonInteger<int> codec{0, count - 1};
  return {key, [=](const int& joint) { return codec.Write(half(joint)); },
          [=](const JsonReader& value, int& joint) -> Status {
            int read = 0;
            DB_RETURN_IF_ERROR(codec.Read(value, read));
            joint = with(joint, read);
            return Status::Ok();
          }};
}

const JsonFields<int>& JointKeyFields() {
  static const JsonFields<int> fields{{
      JointHalf("ratio_band", kRatioBands, RatioOfJoint,
                [](int joint, int ratio) { return JointBand(ratio, DepthOfJoint(joint)); }),
      JointHalf("depth_band", kDepthBands, DepthOfJoint,
                [](int joint, int depth) { return JointBand(RatioOfJoint(joint), depth); }),
      JsonDerived<int>("ratio", [](int joint) { return RatioBandName(RatioOfJoint(joint)); }),
      JsonDerived<int>("depth", [](int joint) { return DepthBandName(DepthOfJoint(joint)); }),
  }};
  return fields;
}

const JsonFields<CellStats>& CellStatsFields() {
  static const JsonFields<int> distance = BandKeyFields("distance_band", kDistanceBands, "distance", DistanceBandName);
  static const JsonFields<int> coverage = BandKeyFields("coverage_band", kCoverageBands, "coverage", CoverageBandName);
  static const JsonFields<CellStats> fields{{
      JsonMember("joint", &CellStats::joint, JsonEntries{JointKeyFields(), BandFields()}),
      JsonMember("distance", &CellStats::distance, JsonEntries{distance, BandFields()}),
      JsonMember("coverage", &CellStats::coverage, JsonEntries{coverage, BandFields()}),
  }};
  return fields;
}

// The quantiles of every metric, for readers: derived from the bins.
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

// The lists that name cells are built for the catalogue their names are
// read in; writing needs none (a cell knows its own name).
JsonFields<CellResult> CellResultFields(const Catalogue& catalogue) {
  return {{
      JsonMember("cell", &CellResult::cell, JsonCellName(catalogue)),
      JsonDerived<CellResult>("variant", [](const CellResult& c) { return std::string(c.cell.variant_info().name); }),
      JsonDerived<CellResult>("convention",
                              [](const CellResult& c) { return std::string(Info(c.cell.convention).name); }),
      JsonDerived<CellResult>("format", [](const CellResult& c) { return std::string(Info(c.cell.format).name); }),
      JsonMember("backend", &CellResult::backend),
      JsonDerived<CellResult>("counts",
                              [](const CellResult& c) { return WriteFields(BandCountFields(), c.stats.All()); }),
      JsonDerived<CellResult>("summary", [](const CellResult& c) { return SummaryToJson(c.stats.All()); }),
      JsonMember("bands", &CellResult::stats, JsonObject{CellStatsFields()}),
  }};
}

const JsonFields<RasterAgreement>& RasterAgreementFields() {
  static const JsonFields<RasterAgreement> fields{{
      JsonAccess<RasterAgreement>(
          "convention", [](auto& a) -> auto& { return a.encoding.convention; }, JsonConventionName()),
      JsonAccess<RasterAgreement>(
          "format", [](auto& a) -> auto& { return a.encoding.format; }, JsonFormatName()),
      JsonMember("texels", &RasterAgreement::texels),
      JsonMember("differing", &RasterAgreement::differing),
      JsonMember("uncovered", &RasterAgreement::uncovered),
      JsonMember("max_code_distance", &RasterAgreement::max_code_distance),
  }};
  return fields;
}

const JsonFields<BackendRecord>& BackendFields() {
  // Where older files lack it, the backend was judged on the host.
  static const JsonNamed<JudgedOn> judge{
      [](const JudgedOn& where) -> std::string { return where == JudgedOn::kDevice ? "device" : "host"; },
      [](std::string_view where) -> Expected<JudgedOn> {
        if (where == "host") return JudgedOn::kHost;
        if (where == "device") return JudgedOn::kDevice;
        return InvalidArgument(fmt::format("judge must be \"host\" or \"device\", not \"{}\"", where));
      }};
  static const JsonFields<BackendRecord> fields{{
      JsonMember("name", &BackendRecord::name),
      JsonMember("device", &BackendRecord::device, JsonObject{DeviceFields()}),
      JsonAccess<BackendRecord>(
          "shaders", [](auto& b) -> auto& { return b.program.shaders; }, JsonText()),
      JsonAccess<BackendRecord>(
          "program_hash", [](auto& b) -> auto& { return b.program.hash; }, JsonText()),
      JsonMemberOr("judge", &BackendRecord::judge, judge, JudgedOn::kHost),
      // Only a raster run's rendering backend has one (and files written
      // before it was kept lack it).
      JsonOnlyIf(JsonMemberOr("raster_agreement", &BackendRecord::raster_agreement,
                              JsonArray{JsonObject{RasterAgreementFields()}}, {}),
                 [](const BackendRecord& b) { return !b.raster_agreement.empty(); }),
  }};
  return fields;
}

const JsonFields<StageSeconds>& StageFields() {
  using Pass = std::pair<std::string, double>;
  static const JsonFields<Pass> pass{{JsonMember("pass", &Pass::first), JsonMember("seconds", &Pass::second)}};
  static const JsonFields<StageSeconds> fields{{
      JsonMember("setup", &StageSeconds::setup),
      JsonMember("build", &StageSeconds::build),
      JsonMember("judging", &StageSeconds::judging),
      JsonMember("build_waited", &StageSeconds::build_waited),
      JsonMember("device_waited", &StageSeconds::device_waited),
      JsonMemberOr("device_passes", &StageSeconds::device_passes, JsonArray{JsonObject{pass}}, {}),
      JsonMemberOr("judge_host_steps", &StageSeconds::judge_host_steps, JsonArray{JsonObject{pass}}, {}),
  }};
  return fields;
}

JsonFields<RunInfo> RunFields(const Catalogue& catalogue) {
  return {{
      JsonMember("version", &RunInfo::version),
      JsonMember("commit", &RunInfo::commit),
      JsonMember("started_at", &RunInfo::started_at),
      JsonMember("host", &RunInfo::host),
      JsonMember("seed", &RunInfo::seed),
      JsonMember("samples", &RunInfo::samples),
      JsonMember("samples_per_frame", &RunInfo::samples_per_frame),
      JsonMember("seconds", &RunInfo::seconds),
      JsonMember("reconstructions", &RunInfo::reconstructions),
      JsonMemberOr("stage_seconds", &RunInfo::stages, JsonObject{StageFields()}, {}),
      JsonMember("shards", &RunInfo::shards,
                 JsonArray{JsonNamed<Shard>{[](const Shard& s) { return s.ToString(); }, ParseShard}}),
      JsonMember("partial", &RunInfo::partial),
      JsonMember("samples_judged", &RunInfo::samples_judged),
      JsonMember("cells", &RunInfo::cells, JsonArray{JsonCellName(catalogue)}),
      JsonMember("domain", &RunInfo::domain, JsonObject{DomainFields()}),
      JsonMember("backends", &RunInfo::backends, JsonArray{JsonObject{BackendFields()}}),
  }};
}

JsonFields<Results> ResultsFields(const Catalogue& catalogue) {
  return {{
      JsonMember("run", &Results::run, JsonObject{RunFields(catalogue)}),
      JsonMember("cells", &Results::cells, JsonArray{JsonObject{CellResultFields(catalogue)}}),
  }};
}

}  // namespace

JsonNamed<Cell> JsonCellName(const Catalogue& catalogue) {
  return {[](const Cell& cell) { return cell.Name(); },
          [&catalogue](std::string_view name) { return catalogue.ParseCell(name); }};
}
JsonNamed<Variant> JsonVariantName(const Catalogue& catalogue) {
  return {[&catalogue](const Variant& v) -> std::string { return std::string(catalogue.Info(v).name); },
          [&catalogue](std::string_view name) { return catalogue.ParseVariant(name); }};
}
JsonNamed<Convention> JsonConventionName() {
  return {[](const Convention& c) -> std::string { return std::string(Info(c).name); }, ParseConvention};
}
JsonNamed<Format> JsonFormatName() {
  return {[](const Format& f) -> std::string { return std::string(Info(f).name); }, ParseFormat};
}

const JsonFields<DeviceInfo>& DeviceFields() {
  static const JsonFields<DeviceInfo> fields{{
      JsonMember("name", &DeviceInfo::name),
      JsonMember("driver", &DeviceInfo::driver),
      JsonMember("api", &DeviceInfo::api),
      JsonMember("kind", &DeviceInfo::kind,
                 JsonNamed<DeviceKind>{[](const DeviceKind& kind) -> std::string { return DeviceKindName(kind); },
                                       [](std::string_view name) -> Expected<DeviceKind> {
                                         const std::optional<DeviceKind> kind = ParseDeviceKind(name);
                                         if (!kind) {
                                           return InvalidArgument(
                                               fmt::format("'{}' is not a device kind; allowed: cpu, gpu", name));
                                         }
                                         return *kind;
                                       }}),
      JsonMember("compiler", &DeviceInfo::compiler),
  }};
  return fields;
}

json DeviceToJson(const DeviceInfo& device) { return WriteFields(DeviceFields(), device); }

Expected<DeviceInfo> DeviceFromJson(const JsonReader& r) {
  DeviceInfo device;
  DB_RETURN_IF_ERROR(ReadFields(DeviceFields(), r, device));
  return device;
}

const JsonFields<Domain>& DomainFields() {
  static const JsonNamed<ProductionModel> production{
      [](const ProductionModel& m) -> std::string { return ProductionModelName(m); }, ParseProductionModel};
  static const JsonNamed<ConstantsModel> constants{
      [](const ConstantsModel& m) -> std::string { return ConstantsModelName(m); }, ParseConstantsModel};
  // What files written before a field existed meant: a domain without a
  // name, depth produced exactly, exact constants.
  static const JsonFields<Domain> fields{
      {
          JsonMember("fov_degrees", &Domain::fov_degrees, RangeCodec()),
          JsonMember("aspect", &Domain::aspect, RangeCodec()),
          JsonMember("near", &Domain::near, RangeCodec()),
          JsonMember("ratio", &Domain::ratio, RangeCodec()),
          JsonMember("finite_far", &Domain::finite_far),
          JsonMember("infinite_far", &Domain::infinite_far),
          JsonMember("far", &Domain::far, JsonNullable{RangeCodec()}),
          JsonMember("camera_distance", &Domain::camera_distance, RangeCodec()),
          JsonMember("eye_depth", &Domain::eye_depth, JsonNullable{RangeCodec()}),
          JsonMember("resolutions", &Domain::resolutions, JsonArray{ResolutionPairCodec()}),
          JsonMemberOr("name", &Domain::name, JsonText(), "custom"),
          JsonMemberOr("production", &Domain::production, production, ProductionModel::kExact),
          JsonMemberOr("constants", &Domain::constants, constants, ConstantsModel::kExact),
      },
      [](const JsonReader& r, const Domain& d) {
        const Status valid = d.Validate();
        return valid.ok() ? valid : r.Error(valid.message());
      }};
  return fields;
}

json DomainToJson(const Domain& domain) { return WriteFields(DomainFields(), domain); }

json ToJson(const Results& results) {
  return WriteDocument(kResultsSchema, ResultsFields(Catalogue::BuiltIn()), results);
}

namespace {

// Every band's histogram of the total error holds one value per finite
// sample, and that of the shader's part at most as many (none where the
// stored value denotes no point float32 holds: judge.cc); the other
// metrics are the encoding's, copied into its cells, and hold their own
// counts. A band's counts add up within 64 bits. A histogram changed by hand, or a file damaged, fails
// here with the cell and the band named, before any figure is drawn from it.
Status CheckHistograms(const Results& results, const std::string& source) {
  for (const CellResult& c : results.cells) {
    const auto check = [&](const std::map<int, BandStats>& bands, const char* family,
                           std::string (*band_name)(int)) -> Status {
      for (const auto& [band_key, band] : bands) {
        const int key = band_key;  // (clang 14 lambdas cannot capture a structured binding)
        const auto where = [&] {
          return fmt::format("{}: cell {} ({} backend), {} band {}", source, c.cell.Name(), c.backend, family,
                             band_name(key));
        };
        std::uint64_t counted = 0;
        for (std::uint64_t n :
             {band.finite, band.nan, band.inf, band.stored_nonfinite, band.degenerate, band.outside, band.undrawn}) {
          if (__builtin_add_overflow(counted, n, &counted)) {
            return InvalidArgument(fmt::format("{}: its counts add up past 2^64", where()));
          }
        }
        for (Metric m : {Metric::kTotal, Metric::kArith}) {
          const std::uint64_t in_bins = band[m].Count();
          if (m == Metric::kTotal ? in_bins != band.finite : in_bins > band.finite) {
            return InvalidArgument(fmt::format(
                "{}: the {} histogram holds {} samples where the band judged {} finite; the file was changed or "
                "damaged",
                where(), MetricName(m), in_bins, band.finite));
          }
        }
      }
      return Status::Ok();
    };
    DB_RETURN_IF_ERROR(check(c.stats.joint, "joint", [](int joint) {
      return RatioBandName(RatioOfJoint(joint)) + " x " + DepthBandName(DepthOfJoint(joint));
    }));
    DB_RETURN_IF_ERROR(check(c.stats.distance, "distance", DistanceBandName));
    DB_RETURN_IF_ERROR(check(c.stats.coverage, "coverage", CoverageBandName));
  }
  return Status::Ok();
}

// Whether adding `b` to `a` keeps every count within 64 bits.
bool AddsWithinRange(const CellStats& a, const CellStats& b) {
  const auto fits = [](std::uint64_t x, std::uint64_t y) {
    std::uint64_t sum;
    return !__builtin_add_overflow(x, y, &sum);
  };
  const auto bands_fit = [&](const std::map<int, BandStats>& x, const std::map<int, BandStats>& y) {
    for (const auto& [key, band] : y) {
      const auto it = x.find(key);
      if (it == x.end()) continue;
      const BandStats& held = it->second;
      if (!fits(held.finite, band.finite) || !fits(held.nan, band.nan) || !fits(held.inf, band.inf) ||
          !fits(held.stored_nonfinite, band.stored_nonfinite) || !fits(held.degenerate, band.degenerate) ||
          !fits(held.outside, band.outside) || !fits(held.undrawn, band.undrawn)) {
        return false;
      }
      for (int m = 0; m < kMetricCount; ++m) {
        if (!fits(held.metrics[m].Count(), band.metrics[m].Count())) return false;
      }
    }
    return true;
  };
  return bands_fit(a.joint, b.joint) && bands_fit(a.distance, b.distance) && bands_fit(a.coverage, b.coverage);
}

}  // namespace

Expected<Results> ResultsFromJson(const json& j, const std::string& source, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(Results results, ReadDocument(kResultsSchema, ResultsFields(catalogue), j, source));
  DB_RETURN_IF_ERROR(CheckHistograms(results, source));
  return results;
}

Status WriteResults(const std::filesystem::path& path, const Results& results) {
  return WriteFileAtomically(path, ToJson(results).dump(1) + "\n");
}

Expected<Results> ReadResults(const std::filesystem::path& path, const Catalogue& catalogue) {
  DB_ASSIGN_OR_RETURN(const json j, ReadJsonFile(path));
  return ResultsFromJson(j, path.string(), catalogue);
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

// Adds `part`'s counts into `into`'s, encoding by encoding.
void MergeAgreement(const std::vector<RasterAgreement>& part, std::vector<RasterAgreement>& into) {
  for (const RasterAgreement& a : part) {
    const auto same = std::find_if(into.begin(), into.end(),
                                   [&](const RasterAgreement& held) { return held.encoding == a.encoding; });
    if (same == into.end()) {
      into.push_back(a);
    } else {
      same->Merge(a);
    }
  }
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
    for (const auto& [name, seconds] : part.run.stages.judge_host_steps) stages.AddJudgeHostStep(name, seconds);
    merged.run.reconstructions += part.run.reconstructions;
    merged.run.samples_judged += part.run.samples_judged;
    merged.run.partial = merged.run.partial || part.run.partial;
    for (std::size_t b = 0; b < part.run.backends.size(); ++b) {
      MergeAgreement(part.run.backends[b].raster_agreement, merged.run.backends[b].raster_agreement);
    }
    for (const CellResult& c : part.cells) {
      auto it = std::find_if(merged.cells.begin(), merged.cells.end(),
                             [&](const CellResult& m) { return m.cell == c.cell && m.backend == c.backend; });
      if (it == merged.cells.end()) {
        merged.cells.push_back(c);
      } else if (!AddsWithinRange(it->stats, c.stats)) {
        return InvalidArgument(fmt::format("{}: cell {} ({} backend): added to the other parts, its counts would pass "
                                           "2^64",
                                           name(p), c.cell.Name(), c.backend));
      } else {
        it->stats.Merge(c.stats);
      }
    }
  }
  std::sort(merged.run.shards.begin(), merged.run.shards.end());
  return merged;
}

}  // namespace depthbench
