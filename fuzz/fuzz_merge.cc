// Fuzz target: merge's inputs. The bytes, split at the first NUL, are two
// results documents (run --json); each goes through the results reader and,
// when both are accepted, through MergeResults, as `depthbench merge a b`
// does. Invariants: no crash, hang, sanitizer report or escaping exception;
// a refusal says why; a merge holds the shards of both parts and is partial
// when either is; a document never merges with itself when it holds a shard
// (the same shard twice); what merges is written and read back in full
// (written again, the same text).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "bench/base/json_reader.h"
#include "bench/results/results.h"
#include "fuzz/fuzz_support.h"

namespace {

using depthbench::fuzzing::Accepted;
using depthbench::fuzzing::CheckRoundTrip;

depthbench::Expected<depthbench::Results> Read(const std::string& text, const std::string& name) {
  const depthbench::Expected<nlohmann::json> json = depthbench::JsonReader::Parse(text, name);
  if (!json.ok()) return json.status();
  return depthbench::ResultsFromJson(*json, name);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace depthbench;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = bytes.find('\0');
  const std::string first = bytes.substr(0, nul);
  const std::string second = nul == std::string::npos ? std::string() : bytes.substr(nul + 1);

  const Expected<Results> a = Read(first, "a.json");
  if (!Accepted(a)) return 0;
  if (!a->run.shards.empty() && MergeResults({*a, *a}, {"a.json", "a.json"}, true).ok()) std::abort();
  const Expected<Results> b = Read(second, "b.json");
  if (!Accepted(b)) return 0;
  for (const bool allow_partial : {false, true}) {
    const Expected<Results> merged = MergeResults({*a, *b}, {"a.json", "b.json"}, allow_partial);
    if (!Accepted(merged)) continue;
    if (merged->run.shards.size() != a->run.shards.size() + b->run.shards.size()) std::abort();
    if (merged->run.partial != (a->run.partial || b->run.partial)) std::abort();
    if (!allow_partial && merged->run.partial) std::abort();
    CheckRoundTrip<Results>(*merged, ToJson, ResultsFromJson);
  }
  return 0;
}
