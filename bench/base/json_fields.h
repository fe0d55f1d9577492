// One field list per saved JSON type: the type is written from it and read
// back from it, so the writer and the reader cannot disagree about what a
// file holds. A list names each field's key, the member it holds and the
// codec that spells the member in JSON; WriteFields writes every field of a
// value, ReadFields reads them in the list's order with located errors
// (json_reader.h: "results.json: run.backends[0].judge: ...").
//
//   const JsonFields<DeviceInfo>& DeviceFields() {
//     static const JsonFields<DeviceInfo> fields{{JsonMember("name", &DeviceInfo::name), ...}};
//     return fields;
//   }
//
// A codec for values of type V is any type with
//   nlohmann::json Write(const V&) const;
//   Status Read(const JsonReader& value, V& out) const;  // errors located at `value`
// Those below spell the values every saved type holds: text, flags,
// numbers, integers with their allowed range, names, nulls, arrays, objects
// with their own field list, and maps.
#pragma once

#include <concepts>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench/base/json_reader.h"
#include "bench/base/status.h"

namespace depthbench {

template <class Codec, class V>
concept JsonCodecOf = requires(const Codec& codec, const V& value, V& out, const JsonReader& reader) {
  { codec.Write(value) } -> std::convertible_to<nlohmann::json>;
  { codec.Read(reader, out) } -> std::same_as<Status>;
};

// One field of a JSON object that holds a T.
template <class T>
struct JsonField {
  std::string key;
  std::function<nlohmann::json(const T&)> write = nullptr;
  // Empty for a field derived from the others (a maximum beside the exact
  // square it comes from), written for people and other programs: never
  // read back.
  std::function<Status(const JsonReader& value, T& out)> read = nullptr;
  // Empty for a required field. Otherwise the field may be absent (files
  // written before it existed): reading one without it calls this instead.
  std::function<void(T& out)> absent = nullptr;
  // Empty for a field every value has. Otherwise the field is written only
  // where this holds, and a required one is read only where it holds of
  // the fields read before it.
  std::function<bool(const T&)> exists = nullptr;
};

template <class T>
struct JsonFields {
  std::vector<JsonField<T>> fields;
  // A rule between fields (min <= median <= max), checked once all are
  // read; its error is located at the object. Empty when there is none.
  std::function<Status(const JsonReader& object, const T& value)> check = nullptr;
};

template <class T>
nlohmann::json WriteFields(const JsonFields<T>& list, const T& value) {
  nlohmann::json out = nlohmann::json::object();
  for (const JsonField<T>& field : list.fields) {
    if (!field.exists || field.exists(value)) out[field.key] = field.write(value);
  }
  return out;
}

// Reads into `out`, whose members the list does not name keep their values.
template <class T>
Status ReadFields(const JsonFields<T>& list, const JsonReader& object, T& out) {
  DB_RETURN_IF_ERROR(object.ExpectObject());
  for (const JsonField<T>& field : list.fields) {
    if (!field.read) continue;
    if (field.absent && !object.Has(field.key)) {
      field.absent(out);
      continue;
    }
    if (!field.absent && field.exists && !field.exists(out)) continue;
    DB_ASSIGN_OR_RETURN(const JsonReader value, object.Field(field.key));
    DB_RETURN_IF_ERROR(field.read(value, out));
  }
  return list.check ? list.check(object, out) : Status::Ok();
}

// A whole file: the header of `schema` (json_reader.h WithSchema), then the fields.
template <class T>
nlohmann::json WriteDocument(const JsonSchema& schema, const JsonFields<T>& list, const T& value) {
  return WithSchema(schema, WriteFields(list, value));
}

// `source` names the input in error messages (a file path).
template <class T>
Expected<T> ReadDocument(const JsonSchema& schema, const JsonFields<T>& list, const nlohmann::json& json,
                         const std::string& source) {
  const JsonReader top(json, source);
  DB_RETURN_IF_ERROR(top.CheckSchema(schema));
  T value{};
  DB_RETURN_IF_ERROR(ReadFields(list, top, value));
  return value;
}

// ---------------------------------------------------------------- codecs

struct JsonText {
  nlohmann::json Write(const std::string& value) const { return value; }
  Status Read(const JsonReader& r, std::string& out) const { return StoreInto(r.String(), out); }
};

struct JsonBool {
  nlohmann::json Write(bool value) const { return value; }
  Status Read(const JsonReader& r, bool& out) const { return StoreInto(r.Bool(), out); }
};

// A double; "inf", "-inf" and "nan" where JSON has no number (JsonNumber).
struct JsonReal {
  nlohmann::json Write(double value) const { return JsonNumber(value); }
  Status Read(const JsonReader& r, double& out) const { return StoreInto(r.Number(), out); }
};

// A finite double within [lowest, highest]: a figure with a known range
// (bits lost), where "nan" or a value outside would be a damaged file.
struct JsonRealIn {
  double lowest;
  double highest;
  nlohmann::json Write(double value) const { return JsonNumber(value); }
  Status Read(const JsonReader& r, double& out) const {
    DB_ASSIGN_OR_RETURN(const double value, r.Number());
    if (!(value >= lowest && value <= highest)) {
      return r.Error(fmt::format("{} is outside [{:g}, {:g}]", JsonNumber(value).dump(), lowest, highest));
    }
    out = value;
    return Status::Ok();
  }
};

// An integer within [min, max], the type's whole range unless narrowed.
// Unsigned ones read null as UINT64_MAX (JsonReader::Unsigned).
template <std::integral Int>
struct JsonInteger {
  Int min = std::numeric_limits<Int>::min();
  Int max = std::numeric_limits<Int>::max();

  nlohmann::json Write(Int value) const { return value; }
  Status Read(const JsonReader& r, Int& out) const {
    if constexpr (std::is_unsigned_v<Int>) {
      DB_ASSIGN_OR_RETURN(const std::uint64_t value, r.Unsigned());
      return Store(r, value, out);
    } else {
      DB_ASSIGN_OR_RETURN(const std::int64_t value, r.Integer());
      return Store(r, value, out);
    }
  }

 private:
  template <class Read>
  Status Store(const JsonReader& r, Read value, Int& out) const {
    if (std::cmp_less(value, min) || std::cmp_greater(value, max)) {
      return r.Error(fmt::format("{} is outside [{}, {}]", value, min, max));
    }
    out = static_cast<Int>(value);
    return Status::Ok();
  }
};

// A sample index that may be absent (UINT64_MAX): a number or null (JsonIndex).
struct JsonIndexOrNull {
  nlohmann::json Write(std::uint64_t value) const { return JsonIndex(value); }
  Status Read(const JsonReader& r, std::uint64_t& out) const { return StoreInto(r.Unsigned(), out); }
};

// A value spelled by its name (a cell, a format, a shard "2/4"); a name
// that `parse` refuses is an error located at the field, with parse's words.
template <class V>
struct JsonNamed {
  std::function<std::string(const V&)> name;
  std::function<Expected<V>(std::string_view)> parse;

  nlohmann::json Write(const V& value) const { return name(value); }
  Status Read(const JsonReader& r, V& out) const {
    DB_ASSIGN_OR_RETURN(const std::string text, r.String());
    Expected<V> value = parse(text);
    if (!value.ok()) return r.Error(value.status().message());
    out = std::move(*value);
    return Status::Ok();
  }
};

// A std::optional whose empty state is written as null.
template <class Codec>
struct JsonNullable {
  Codec codec;

  template <class V>
  nlohmann::json Write(const std::optional<V>& value) const {
    return value ? nlohmann::json(codec.Write(*value)) : nlohmann::json(nullptr);
  }
  template <class V>
  Status Read(const JsonReader& r, std::optional<V>& out) const {
    if (r.json().is_null()) {
      out.reset();
      return Status::Ok();
    }
    return codec.Read(r, out.emplace());
  }
};
template <class Codec>
JsonNullable(Codec) -> JsonNullable<Codec>;

template <class Codec>
struct JsonArray {
  Codec element;

  template <class V>
  nlohmann::json Write(const std::vector<V>& values) const {
    nlohmann::json out = nlohmann::json::array();
    for (const V& value : values) out.push_back(element.Write(value));
    return out;
  }
  template <class V>
  Status Read(const JsonReader& r, std::vector<V>& out) const {
    out.clear();
    return r.ForEach([&](const JsonReader& item) { return element.Read(item, out.emplace_back()); });
  }
};
template <class Codec>
JsonArray(Codec) -> JsonArray<Codec>;

// A nested object with its own field list (a copy: a list built for one
// read, such as one that names cells of a command's catalogue, need not
// outlive the codecs made from it).
template <class T>
struct JsonObject {
  JsonFields<T> fields;

  nlohmann::json Write(const T& value) const { return WriteFields(fields, value); }
  Status Read(const JsonReader& r, T& out) const { return ReadFields(fields, r, out); }
};
template <class T>
JsonObject(const JsonFields<T>&) -> JsonObject<T>;

// A map from names to values, as an object with one field per entry.
// `key`, when set, gives the name the map keeps for a name as written (a
// cell's own spelling for an alias); names that come to the same one are
// refused.
template <class Codec>
struct JsonMap {
  Codec value;
  std::function<Expected<std::string>(std::string_view)> key = nullptr;

  template <class V>
  nlohmann::json Write(const std::map<std::string, V>& map) const {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [name, entry] : map) out[name] = value.Write(entry);
    return out;
  }
  template <class V>
  Status Read(const JsonReader& r, std::map<std::string, V>& out) const {
    out.clear();
    DB_ASSIGN_OR_RETURN(const std::vector<std::string> names, r.Keys());
    for (const std::string& written : names) {
      DB_ASSIGN_OR_RETURN(const JsonReader entry, r.Field(written));
      std::string name = written;
      if (key) {
        Expected<std::string> kept = key(written);
        if (!kept.ok()) return entry.Error(kept.status().message());
        name = std::move(*kept);
      }
      if (out.contains(name)) return entry.Error(fmt::format("'{}' is given twice", name));
      DB_RETURN_IF_ERROR(value.Read(entry, out[name]));
    }
    return Status::Ok();
  }
};
template <class Codec>
JsonMap(Codec) -> JsonMap<Codec>;
template <class Codec, class Key>
JsonMap(Codec, Key) -> JsonMap<Codec>;

// A map as an array of objects, one per entry: the fields of its key beside
// the fields of its value. Two entries of one key are refused.
template <class Key, class Value>
struct JsonEntries {
  const JsonFields<Key>& key;
  const JsonFields<Value>& value;

  nlohmann::json Write(const std::map<Key, Value>& map) const {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& [k, v] : map) {
      nlohmann::json entry = WriteFields(value, v);
      entry.update(WriteFields(key, k));
      out.push_back(std::move(entry));
    }
    return out;
  }
  Status Read(const JsonReader& r, std::map<Key, Value>& out) const {
    out.clear();
    return r.ForEach([&](const JsonReader& entry) -> Status {
      Key k{};
      DB_RETURN_IF_ERROR(ReadFields(key, entry, k));
      if (out.contains(k)) return entry.Error("the same entry as one before it");
      return ReadFields(value, entry, out[k]);
    });
  }
};
template <class Key, class Value>
JsonEntries(const JsonFields<Key>&, const JsonFields<Value>&) -> JsonEntries<Key, Value>;

// The codec a member of type V gets when its field names none.
template <class V>
struct JsonDefaultCodec {
  using type = JsonInteger<V>;
};
template <>
struct JsonDefaultCodec<std::string> {
  using type = JsonText;
};
template <>
struct JsonDefaultCodec<bool> {
  using type = JsonBool;
};
template <>
struct JsonDefaultCodec<double> {
  using type = JsonReal;
};

// ---------------------------------------------------------------- fields

// The field `key` holding what `access` reaches in a T: a member pointer,
// or a function from T& (const or not) to a reference to one of its parts.
template <class T, class Access, class Codec>
JsonField<T> JsonAccess(std::string key, Access access, Codec codec) {
  using V = std::remove_cvref_t<std::invoke_result_t<Access, T&>>;
  static_assert(JsonCodecOf<Codec, V>, "the codec does not write and read the member's type");
  return {std::move(key), [=](const T& value) { return nlohmann::json(codec.Write(std::invoke(access, value))); },
          [=](const JsonReader& field, T& value) { return codec.Read(field, std::invoke(access, value)); }};
}

// The field `key` holding member `member`, spelled by `codec` (by default:
// text, flag, number or full-range integer, as its type is).
template <class T, class V, class Codec = typename JsonDefaultCodec<V>::type>
JsonField<T> JsonMember(std::string key, V T::*member, Codec codec = {}) {
  return JsonAccess<T>(std::move(key), member, std::move(codec));
}

// A member that files written before it existed lack: they read as
// `absent` (what those files meant).
template <class T, class V, class Codec>
JsonField<T> JsonMemberOr(std::string key, V T::*member, Codec codec, std::type_identity_t<V> absent) {
  JsonField<T> field = JsonMember(std::move(key), member, std::move(codec));
  field.absent = [member, absent](T& value) { value.*member = absent; };
  return field;
}

// A std::optional member: the field is written where it holds a value and
// read where the file has it.
template <class T, class V, class Codec>
JsonField<T> JsonOptionalMember(std::string key, std::optional<V> T::*member, Codec codec) {
  static_assert(JsonCodecOf<Codec, V>, "the codec does not write and read the member's type");
  return {std::move(key), [=](const T& value) { return nlohmann::json(codec.Write(*(value.*member))); },
          [=](const JsonReader& field, T& value) { return codec.Read(field, (value.*member).emplace()); },
          [=](T& value) { (value.*member).reset(); }, [=](const T& value) { return (value.*member).has_value(); }};
}

// A field derived from the others, written only (see JsonField::read).
template <class T, class Write>
JsonField<T> JsonDerived(std::string key, Write write) {
  return {std::move(key), [=](const T& value) { return nlohmann::json(write(value)); }, nullptr};
}

// `field`, present only where `exists` holds (see JsonField::exists).
template <class T>
JsonField<T> JsonOnlyIf(JsonField<T> field, std::type_identity_t<std::function<bool(const T&)>> exists) {
  field.exists = std::move(exists);
  return field;
}

}  // namespace depthbench
