// Fuzz target: the formulas. The bytes decode to a point of the fuzz domain
// (a projection, camera pose, pixel and depth: bench/fuzz/fuzz_case.h),
// which runs through every cell's CPU float32 path and the reference. The
// invariants are the campaign's (bench/fuzz/case_check.h): a finite output
// where the reference is finite, the arithmetic error within the documented
// bound. A violation is a finding, not a crash: the first of each signature
// is written as a reproducer (depthbench run --repro FILE) into
// $DEPTHBENCH_FUZZ_FINDINGS (default: the current folder) and counted.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/fuzz/case_check.h"
#include "bench/fuzz/fuzz_case.h"

namespace {

using namespace depthbench;

struct Target {
  std::unique_ptr<Backend> cpu;
  std::unique_ptr<CaseChecker> checker;
  Domain domain = FuzzDomain();
  std::set<std::string> seen;
};

Target& Instance() {
  static Target* target = [] {
    auto* t = new Target;
    t->cpu = MakeCpuBackend();
    auto checker = CaseChecker::Make(AllCells(), {t->cpu.get()}, 1);
    if (!checker.ok()) {
      std::fprintf(stderr, "fuzz_formulas: %s\n", checker.status().message().c_str());
      std::abort();
    }
    t->checker = std::make_unique<CaseChecker>(std::move(*checker));
    return t;
  }();
  return *target;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Target& t = Instance();
  const FuzzCase c = CaseAt(t.domain, DecodePoint({data, size}));
  const CaseSource source(c);
  if (Status s = t.checker->Evaluate(source, 0, 1); !s.ok()) {
    std::fprintf(stderr, "fuzz_formulas: %s\n", s.message().c_str());
    std::abort();  // the CPU backend cannot fail: a failure here is a bug
  }
  for (std::size_t k = 0; k < t.checker->cells().size(); ++k) {
    const Cell& cell = t.checker->cells()[k];
    if (!CellRunsOn(cell, c.frame)) continue;
    const Judgement& j = t.checker->At(k, 0, 0);
    if (!j.violates()) continue;
    const std::string signature = cell.Name() + " cpu " + FindingKindName(j.kind());
    if (!t.seen.insert(signature).second) continue;
    std::string name = signature;
    for (char& ch : name) {
      if (ch == '/' || ch == ' ') ch = '_';
    }
    const char* dir = std::getenv("DEPTHBENCH_FUZZ_FINDINGS");
    const std::string path = std::string(dir ? dir : ".") + "/finding_" + name + ".json";
    ReproFile file;
    file.fuzz_case = c;
    file.cells = {cell};
    file.backends = {"cpu"};
    file.finding = {{"signature", signature}, {"kind", FindingKindName(j.kind())}};
    if (Status s = WriteReproFile(path, file); !s.ok())
      std::fprintf(stderr, "fuzz_formulas: %s\n", s.message().c_str());
    std::fprintf(stderr, "fuzz_formulas: finding %s, written to %s\n", signature.c_str(), path.c_str());
  }
  return 0;
}
