// Fuzz target: the scene-file parser. The bytes are a scene file's TOML text.
// Invariants: no crash, hang or sanitizer report; a refused scene says why;
// an accepted scene holds a domain the bench accepts.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "bench/choose/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const depthbench::Expected<depthbench::Scene> scene = depthbench::ParseScene(text, "fuzz.toml");
  if (!scene.ok()) {
    if (scene.status().message().empty()) std::abort();  // refused without a reason
    return 0;
  }
  // What the parser lets through must pass the same checks as flags do, or
  // choose would sample a domain that run refuses.
  if (!scene->domain.Validate().ok()) std::abort();
  (void)scene->Candidates();
  (void)scene->requirement.Describe();
  return 0;
}
