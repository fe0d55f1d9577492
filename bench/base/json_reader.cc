#include "bench/base/json_reader.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "bench/base/files.h"

namespace depthbench {
namespace {

const char* KindOf(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return "null";
    case nlohmann::json::value_t::object: return "an object";
    case nlohmann::json::value_t::array: return "an array";
    case nlohmann::json::value_t::string: return "a string";
    case nlohmann::json::value_t::boolean: return "a boolean";
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned: return "an integer";
    case nlohmann::json::value_t::number_float: return "a number";
    default: return "an unsupported value";
  }
}

}  // namespace

Expected<nlohmann::json> JsonReader::Parse(const std::string& text, const std::string& source) {
  nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!json.is_discarded()) return json;
  // Locate the syntax error: parse again with exceptions for the byte
  // offset, then turn it into a line and column. Not every refusal is a
  // syntax error: a number beyond the range of a double ("1e999") is an
  // out_of_range error without a position (found by fuzz_results_json).
  std::size_t byte = 0;
  try {
    nlohmann::json ignored = nlohmann::json::parse(text);
    (void)ignored;
  } catch (const nlohmann::json::parse_error& e) {
    byte = e.byte;
  } catch (const nlohmann::json::out_of_range& e) {
    return InvalidArgument(
        fmt::format("{}: not valid JSON: a number beyond the range of a double ({})", source, e.what()));
  } catch (const nlohmann::json::exception& e) {
    return InvalidArgument(fmt::format("{}: not valid JSON ({})", source, e.what()));
  }
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return InvalidArgument(fmt::format("{}:{}:{}: not valid JSON", source, line, column));
}

Expected<nlohmann::json> ReadJsonFile(const std::filesystem::path& path) {
  DB_ASSIGN_OR_RETURN(const std::string text, ReadFile(path, kMaxJsonFileBytes));
  return JsonReader::Parse(text, path.string());
}

nlohmann::json WithSchema(const JsonSchema& schema, nlohmann::json body) {
  body["schema"] = schema.name;
  body["schema_version"] = schema.version;
  return body;
}

Status JsonReader::CheckSchema(const JsonSchema& schema) const {
  DB_ASSIGN_OR_RETURN(const std::string name, String("schema"));
  if (name != schema.name) {
    return Error(fmt::format("schema is '{}', expected '{}' ({})", name, schema.name, schema.what));
  }
  DB_ASSIGN_OR_RETURN(const std::int64_t version, Integer("schema_version"));
  if (version != schema.version) {
    return Error(
        fmt::format("schema_version {} is not supported (this depthbench reads version {})", version, schema.version));
  }
  return Status::Ok();
}

Status JsonReader::ForEach(const ElementReader& read) const {
  DB_ASSIGN_OR_RETURN(const std::size_t count, ArraySize());
  for (std::size_t i = 0; i < count; ++i) {
    DB_ASSIGN_OR_RETURN(const JsonReader element, Element(i));
    DB_RETURN_IF_ERROR(read(element));
  }
  return Status::Ok();
}

Status JsonReader::ForEach(const std::string& key, const ElementReader& read) const {
  DB_ASSIGN_OR_RETURN(const JsonReader array, Field(key));
  return array.ForEach(read);
}

Status JsonReader::Error(const std::string& message) const {
  return InvalidArgument(fmt::format("{}: {}: {}", source_, path_.empty() ? "(top level)" : path_, message));
}

Status JsonReader::ExpectObject() const {
  if (!json_.is_object()) return Error(fmt::format("expected an object, found {}", KindOf(json_)));
  return Status::Ok();
}

Expected<std::vector<std::string>> JsonReader::Keys() const {
  DB_RETURN_IF_ERROR(ExpectObject());
  std::vector<std::string> keys;
  for (const auto& item : json_.items()) keys.push_back(item.key());
  return keys;
}

Expected<JsonReader> JsonReader::Field(const std::string& key) const {
  std::string path = path_.empty() ? key : path_ + "." + key;
  DB_RETURN_IF_ERROR(ExpectObject());
  auto it = json_.find(key);
  if (it == json_.end()) {
    return InvalidArgument(fmt::format("{}: {}: missing field", source_, path));
  }
  return JsonReader(*it, source_, path);
}

Expected<JsonReader> JsonReader::Element(std::size_t index) const {
  if (!json_.is_array()) return Error(fmt::format("expected an array, found {}", KindOf(json_)));
  if (index >= json_.size()) return Error(fmt::format("has no element {}", index));
  return JsonReader(json_[index], source_, fmt::format("{}[{}]", path_, index));
}

Expected<std::size_t> JsonReader::ArraySize() const {
  if (!json_.is_array()) return Error(fmt::format("expected an array, found {}", KindOf(json_)));
  return json_.size();
}

Expected<std::string> JsonReader::String() const {
  if (!json_.is_string()) return Error(fmt::format("expected a string, found {}", KindOf(json_)));
  return json_.get<std::string>();
}

Expected<double> JsonReader::Number() const {
  if (json_.is_number()) return json_.get<double>();
  if (json_.is_string()) {
    const auto& s = json_.get_ref<const std::string&>();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
  }
  return Error(fmt::format("expected a number, found {}", KindOf(json_)));
}

Expected<std::uint64_t> JsonReader::Unsigned() const {
  if (json_.is_null()) return std::numeric_limits<std::uint64_t>::max();
  if (json_.is_number_unsigned()) return json_.get<std::uint64_t>();
  if (json_.is_number_integer() && json_.get<std::int64_t>() >= 0) {
    return static_cast<std::uint64_t>(json_.get<std::int64_t>());
  }
  return Error(fmt::format("expected an unsigned integer, found {}", KindOf(json_)));
}

Expected<std::int64_t> JsonReader::Integer() const {
  if (json_.is_number_integer()) return json_.get<std::int64_t>();
  return Error(fmt::format("expected an integer, found {}", KindOf(json_)));
}

Expected<bool> JsonReader::Bool() const {
  if (json_.is_boolean()) return json_.get<bool>();
  return Error(fmt::format("expected true or false, found {}", KindOf(json_)));
}

Expected<std::string> JsonReader::String(const std::string& key) const {
  DB_ASSIGN_OR_RETURN(JsonReader f, Field(key));
  return f.String();
}
Expected<double> JsonReader::Number(const std::string& key) const {
  DB_ASSIGN_OR_RETURN(JsonReader f, Field(key));
  return f.Number();
}
Expected<std::uint64_t> JsonReader::Unsigned(const std::string& key) const {
  DB_ASSIGN_OR_RETURN(JsonReader f, Field(key));
  return f.Unsigned();
}
Expected<std::int64_t> JsonReader::Integer(const std::string& key) const {
  DB_ASSIGN_OR_RETURN(JsonReader f, Field(key));
  return f.Integer();
}
Expected<bool> JsonReader::Bool(const std::string& key) const {
  DB_ASSIGN_OR_RETURN(JsonReader f, Field(key));
  return f.Bool();
}

nlohmann::json JsonNumber(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  return x;
}

nlohmann::json JsonIndex(std::uint64_t index) {
  if (index == std::numeric_limits<std::uint64_t>::max()) return nullptr;
  return index;
}

}  // namespace depthbench
