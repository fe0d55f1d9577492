// Typed, located reads from parsed JSON. Every error names the source file
// and the path of the field ("results.json: cells[3].bands.joint[0].finite:
// expected an unsigned integer, found a string"), so a bad file is fixed
// without guessing.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "bench/base/status.h"

namespace depthbench {

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

  Status Error(const std::string& message) const;
  const nlohmann::json& json() const { return json_; }
  const std::string& path() const { return path_; }
  const std::string& source() const { return source_; }

 private:
  const nlohmann::json& json_;
  std::string source_;
  std::string path_;
};

// A double as JSON: a number, or "inf"/"-inf"/"nan" (JSON has no such numbers).
nlohmann::json JsonNumber(double x);
// An index that may be absent (UINT64_MAX): a number or null.
nlohmann::json JsonIndex(std::uint64_t index);

}  // namespace depthbench
