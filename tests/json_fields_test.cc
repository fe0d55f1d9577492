// The field lists that write and read every saved JSON type
// (bench/base/json_fields.h): one list, both directions, located errors.
#include "bench/base/json_fields.h"

#include <cctype>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace depthbench {
namespace {

using nlohmann::json;

struct Count {
  std::uint64_t value = 0;
  std::uint64_t first_index = UINT64_MAX;
};

struct Probe {
  std::string name;
  std::uint32_t taps = 1;
  double seconds = 0.0;
  std::optional<double> limit;  // null when none
  std::vector<std::string> tags;
  std::string made_by = "today";  // older files lack it: "an older bench"
  std::optional<Count> extra;     // written only when measured
  bool has_total = false;
  std::uint64_t total = 0;  // only where has_total
  std::map<std::string, Count> by_name;
  std::map<int, Count> by_band;
};

const JsonFields<Count>& CountFields() {
  static const JsonFields<Count> fields{{
      JsonMember("value", &Count::value),
      JsonMember("first_index", &Count::first_index, JsonIndexOrNull()),
  }};
  return fields;
}

const JsonFields<int>& BandFields() {
  static const JsonFields<int> fields{{
      JsonAccess<int>("band", [](auto& band) -> auto& { return band; }, JsonInteger<int>{0, 3}),
      JsonDerived<int>("band_name", [](int band) { return "band " + std::to_string(band); }),
  }};
  return fields;
}

const JsonFields<Probe>& ProbeFields() {
  static const JsonFields<Probe> fields{
      {
          JsonMember("name", &Probe::name),
          JsonMember("taps", &Probe::taps, JsonInteger<std::uint32_t>{1}),
          JsonMember("seconds", &Probe::seconds),
          JsonMember("limit", &Probe::limit, JsonNullable{JsonReal()}),
          JsonMember("tags", &Probe::tags, JsonArray{JsonText()}),
          JsonMemberOr("made_by", &Probe::made_by, JsonText(), "an older bench"),
          JsonOptionalMember("extra", &Probe::extra, JsonObject{CountFields()}),
          JsonMember("has_total", &Probe::has_total),
          JsonOnlyIf(JsonMember("total", &Probe::total), [](const Probe& p) { return p.has_total; }),
          JsonDerived<Probe>("taps_per_second", [](const Probe& p) { return JsonNumber(p.taps / p.seconds); }),
          JsonMember("by_name", &Probe::by_name,
                     JsonMap{JsonObject{CountFields()},
                             [](std::string_view name) -> Expected<std::string> {
                               if (name.empty()) return InvalidArgument("an empty name");
                               std::string lower(name);
                               for (char& c : lower) c = static_cast<char>(std::tolower(c));
                               return lower;
                             }}),
          JsonMember("by_band", &Probe::by_band, JsonEntries{BandFields(), CountFields()}),
      },
      [](const JsonReader& r, const Probe& p) {
        return p.tags.size() <= p.taps ? Status::Ok() : r.Error("more tags than taps");
      }};
  return fields;
}

Probe Example() {
  Probe p;
  p.name = "divide";
  p.taps = 4;
  p.seconds = 0.5;
  p.tags = {"alu", "fast"};
  p.extra = Count{3, 7};
  p.has_total = true;
  p.total = 12;
  p.by_name = {{"reciprocal", {1, UINT64_MAX}}};
  p.by_band = {{0, {5, 2}}, {3, {6, UINT64_MAX}}};
  return p;
}

Expected<Probe> Read(const json& j) {
  Probe p;
  DB_RETURN_IF_ERROR(ReadFields(ProbeFields(), JsonReader(j, "probe.json"), p));
  return p;
}

std::string ErrorOf(const json& j) {
  const Expected<Probe> read = Read(j);
  return read.ok() ? "(read)" : read.status().message();
}

TEST(JsonFieldsTest, WritesEveryFieldAndReadsBackWhatItWrote) {
  const json written = WriteFields(ProbeFields(), Example());
  EXPECT_EQ(written["limit"], nullptr);
  EXPECT_EQ(written["extra"]["first_index"], 7);
  EXPECT_EQ(written["by_name"]["reciprocal"]["first_index"], nullptr);
  EXPECT_EQ(written["by_band"][1]["band"], 3);
  EXPECT_EQ(written["by_band"][1]["band_name"], "band 3");
  EXPECT_EQ(written["taps_per_second"], 8.0);
  const Expected<Probe> read = Read(written);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(WriteFields(ProbeFields(), *read).dump(), written.dump());
  EXPECT_EQ(read->by_band.at(0).first_index, 2u);
}

// Derived fields are for readers: what a file says there is not read.
TEST(JsonFieldsTest, DerivedFieldsAreWrittenButNotRead) {
  json j = WriteFields(ProbeFields(), Example());
  j["taps_per_second"] = "anything";
  j["by_band"][0]["band_name"] = 17;
  EXPECT_EQ(ErrorOf(j), "(read)");
}

TEST(JsonFieldsTest, ErrorsNameTheFileTheFieldAndTheAllowedRange) {
  json j = WriteFields(ProbeFields(), Example());
  j["taps"] = 0;
  EXPECT_EQ(ErrorOf(j), "probe.json: taps: 0 is outside [1, 4294967295]");
  j = WriteFields(ProbeFields(), Example());
  j["by_band"][1]["band"] = 4;
  EXPECT_EQ(ErrorOf(j), "probe.json: by_band[1].band: 4 is outside [0, 3]");
  j = WriteFields(ProbeFields(), Example());
  j["extra"]["value"] = "many";
  EXPECT_EQ(ErrorOf(j), "probe.json: extra.value: expected an unsigned integer, found a string");
  j = WriteFields(ProbeFields(), Example());
  j["tags"][1] = 3;
  EXPECT_EQ(ErrorOf(j), "probe.json: tags[1]: expected a string, found an integer");
  j = WriteFields(ProbeFields(), Example());
  j.erase("seconds");
  EXPECT_EQ(ErrorOf(j), "probe.json: seconds: missing field");
  j = WriteFields(ProbeFields(), Example());
  j["taps"] = 1;
  EXPECT_EQ(ErrorOf(j), "probe.json: (top level): more tags than taps");
  EXPECT_EQ(ErrorOf(json::array()), "probe.json: (top level): expected an object, found an array");
}

TEST(JsonFieldsTest, AbsentFieldsReadAsWhatOlderFilesMeant) {
  json j = WriteFields(ProbeFields(), Example());
  j.erase("made_by");
  j.erase("extra");
  const Expected<Probe> read = Read(j);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->made_by, "an older bench");
  EXPECT_FALSE(read->extra.has_value());
  EXPECT_FALSE(WriteFields(ProbeFields(), *read).contains("extra"));
}

// A field that exists only where an earlier one says so: required then,
// neither read nor written otherwise.
TEST(JsonFieldsTest, ConditionalFieldsFollowTheFieldsBeforeThem) {
  json j = WriteFields(ProbeFields(), Example());
  j.erase("total");
  EXPECT_EQ(ErrorOf(j), "probe.json: total: missing field");
  j["has_total"] = false;
  j["total"] = "not read";
  const Expected<Probe> read = Read(j);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->total, 0u);
  EXPECT_FALSE(WriteFields(ProbeFields(), *read).contains("total"));
}

TEST(JsonFieldsTest, MapsRefuseAKeyGivenTwice) {
  json j = WriteFields(ProbeFields(), Example());
  j["by_name"]["Reciprocal"] = j["by_name"]["reciprocal"];
  EXPECT_EQ(ErrorOf(j), "probe.json: by_name.reciprocal: 'reciprocal' is given twice");
  j = WriteFields(ProbeFields(), Example());
  j["by_name"][""] = j["by_name"]["reciprocal"];
  EXPECT_EQ(ErrorOf(j), "probe.json: by_name.: an empty name");
  j = WriteFields(ProbeFields(), Example());
  j["by_band"][1]["band"] = 0;
  EXPECT_EQ(ErrorOf(j), "probe.json: by_band[1]: the same entry as one before it");
}

TEST(JsonFieldsTest, DocumentsCarryTheirSchema) {
  constexpr JsonSchema kProbe{"depthbench.probe", 2, "a probe"};
  const json written = WriteDocument(kProbe, ProbeFields(), Example());
  EXPECT_EQ(written["schema"], "depthbench.probe");
  EXPECT_EQ(written["schema_version"], 2);
  const Expected<Probe> read = ReadDocument(kProbe, ProbeFields(), written, "probe.json");
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->name, "divide");
  json other = written;
  other["schema_version"] = 1;
  EXPECT_FALSE(ReadDocument(kProbe, ProbeFields(), other, "probe.json").ok());
}

}  // namespace
}  // namespace depthbench
