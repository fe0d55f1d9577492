// Typed, located reads from parsed JSON. Every error names the source file
// and the path of the field ("results.json: cells[3].bands.joint[0].finite:
// expected an unsigned integer, found a string"), so a bad file is fixed
// without guessing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/base/status.h"

namespace depthbench {

// What every depthbench JSON file starts with: "schema" (its kind) and
// "schema_version". A reader accepts one version.
struct JsonSchema {
  const char* name;  // "depthbench.results"
  int version;       // 1
  const char* what;  // "a results file (depthbench run --json)", for errors
};

class JsonReader {
 public:
  JsonReader(const nlohmann::json& json, std::string source, std::string path = "")
      : json_(json), source_(std::move(source)), path_(std::move(path)) {}

  // Parses text; a syntax error names the source, line and column.
  static Expected<nlohmann::json> Parse(const std::string& text, const std::string& source);

  bool Has(const std::string& key) const { return json_.is_object() && json_.contains(key); }
  Expected<JsonReader> Field(const std::string& key) const;  // must exist
  Expected<JsonReader> Element(std::size_t index) const;     // of an array
  Expected<std::size_t> ArraySize() const;                   // must be an array
  Status ExpectObject() const;                               // Ok when this is an object
  Expected<std::vector<std::string>> Keys() const;           // of an object, in order

  Expected<std::string> String() const;
  Expected<double> Number() const;           // also "inf", "-inf", "nan" strings
  Expected<std::uint64_t> Unsigned() const;  // null reads as UINT64_MAX (no value)
  Expected<std::int64_t> Integer() const;
  Expected<bool> Bool() const;

  // Shorthands: Field(key) then the typed read.
  Expected<std::string> String(const std::string& key) const;
  Expected<double> Number(const std::string& key) const;
  Expected<std::uint64_t> Unsigned(const std::string& key) const;
  Expected<std::int64_t> Integer(const std::string& key) const;
  Expected<bool> Bool(const std::string& key) const;

  // Calls `read` on every element of this array, or of the array `key`.
  using ElementReader = std::function<Status(const JsonReader&)>;
  Status ForEach(const ElementReader& read) const;
  Status ForEach(const std::string& key, const ElementReader& read) const;

  // Ok when this object's "schema" and "schema_version" are `schema`'s;
  // otherwise an error that says what the file is and what was expected.
  Status CheckSchema(const JsonSchema& schema) const;

  Status Error(const std::string& message) const;
  const nlohmann::json& json() const { return json_; }
  const std::string& path() const { return path_; }
  const std::string& source() const { return source_; }

 private:
  const nlohmann::json& json_;
  std::string source_;
  std::string path_;
};

// The parsed content of a JSON file; errors name the file (and the line and
// column of a syntax error).
Expected<nlohmann::json> ReadJsonFile(const std::filesystem::path& path);

// `body` (an object) with the header of a file of `schema` added:
// "schema": its name, "schema_version": its version.
nlohmann::json WithSchema(const JsonSchema& schema, nlohmann::json body);

// A double as JSON: a number, or "inf"/"-inf"/"nan" (JSON has no such numbers).
nlohmann::json JsonNumber(double x);
// An index that may be absent (UINT64_MAX): a number or null.
nlohmann::json JsonIndex(std::uint64_t index);

}  // namespace depthbench
