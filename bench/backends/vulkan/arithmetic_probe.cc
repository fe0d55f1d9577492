#include "bench/backends/vulkan/arithmetic_probe.h"

#include <map>
#include <set>
#include <utility>

#include <fmt/format.h>
#include <glslang/SPIRV/spirv.hpp>

namespace depthbench {
namespace {

constexpr std::size_t kHeaderWords = 5;
constexpr std::size_t kBoundWord = 3;

struct Probe {
  std::uint32_t bit;
  std::string_view name;
};
constexpr Probe kProbes[] = {
    {kNoContraction, "no-contraction"},
    {kExactDivision, "exact-division"},
    {kWorstDivision, "worst-division"},
    {kComputeAttributes, "compute-attributes"}};

// The arithmetic a compiler may contract: SPIR-V's NoContraction applies to
// these.
bool Contractible(spv::Op op) {
  switch (op) {
    case spv::OpFAdd:
    case spv::OpFSub:
    case spv::OpFMul:
    case spv::OpFDiv:
    case spv::OpFRem:
    case spv::OpFMod:
    case spv::OpFNegate:
    case spv::OpVectorTimesScalar:
    case spv::OpMatrixTimesScalar:
    case spv::OpVectorTimesMatrix:
    case spv::OpMatrixTimesVector:
    case spv::OpMatrixTimesMatrix:
    case spv::OpDot: return true;
    default: return false;
  }
}

// Instructions of the module's preamble, before its annotations end: the
// NoContraction decorations go after them.
bool BeforeTypes(spv::Op op) {
  switch (op) {
    case spv::OpCapability:
    case spv::OpExtension:
    case spv::OpExtInstImport:
    case spv::OpMemoryModel:
    case spv::OpEntryPoint:
    case spv::OpExecutionMode:
    case spv::OpExecutionModeId:
    case spv::OpString:
    case spv::OpSourceExtension:
    case spv::OpSource:
    case spv::OpSourceContinued:
    case spv::OpName:
    case spv::OpMemberName:
    case spv::OpModuleProcessed:
    case spv::OpDecorate:
    case spv::OpMemberDecorate:
    case spv::OpDecorationGroup:
    case spv::OpGroupDecorate:
    case spv::OpGroupMemberDecorate:
    case spv::OpDecorateId:
    case spv::OpDecorateString:
    case spv::OpMemberDecorateString:
    case spv::OpLine:
    case spv::OpNoLine: return true;
    default: return false;
  }
}

std::uint32_t Word(spv::Op op, std::size_t count) {
  return static_cast<std::uint32_t>(count) << spv::WordCountShift | static_cast<std::uint32_t>(op);
}

// One instruction's place in the module.
struct Instruction {
  std::size_t at;
  std::size_t words;
  spv::Op op;
};

Expected<std::vector<Instruction>> Instructions(std::span<const std::uint32_t> spirv) {
  if (spirv.size() < kHeaderWords || spirv[0] != spv::MagicNumber) {
    return InvalidArgument("not a SPIR-V module (no magic number)");
  }
  std::vector<Instruction> out;
  for (std::size_t at = kHeaderWords; at < spirv.size();) {
    const std::size_t words = spirv[at] >> spv::WordCountShift;
    if (words == 0 || at + words > spirv.size()) {
      return InvalidArgument(fmt::format("SPIR-V module: instruction at word {} runs past the end", at));
    }
    out.push_back({at, words, static_cast<spv::Op>(spirv[at] & spv::OpCodeMask)});
    at += words;
  }
  return out;
}

// The module's types, and those the division probes add: made where
// missing, with fresh ids from the module's bound, to close its global
// section (`made`).
class TypeTable {
 public:
  TypeTable(std::span<const std::uint32_t> spirv, const std::vector<Instruction>& instructions)
      : bound_(spirv[kBoundWord]) {
    for (const Instruction& inst : instructions) {
      const std::uint32_t* w = spirv.data() + inst.at;
      if (inst.op == spv::OpTypeFloat) float_width_[w[1]] = w[2];
      if (inst.op == spv::OpTypeFloat && w[2] == 64) double_ = w[1];
      if (inst.op == spv::OpTypeInt && w[2] == 32 && w[3] == 0) uint_ = w[1];
      if (inst.op == spv::OpTypeVector) {
        vectors_[w[1]] = {w[2], w[3]};
        vector_of_[{w[2], w[3]}] = w[1];
      }
    }
  }

  std::uint32_t Fresh() { return bound_++; }
  std::uint32_t bound() const { return bound_; }
  const std::vector<std::uint32_t>& made() const { return made_; }

  bool IsFloat32(std::uint32_t type) const {
    if (auto v = vectors_.find(type); v != vectors_.end()) type = v->second.first;
    auto f = float_width_.find(type);
    return f != float_width_.end() && f->second == 32;
  }

  // The float64 counterpart of a float32 scalar or vector type.
  std::uint32_t Widened(std::uint32_t type) {
    if (double_ == 0) Make({Word(spv::OpTypeFloat, 3), double_ = Fresh(), 64});
    return SameShape(type, double_);
  }

  // The unsigned integer type of a float32 type's bits, and the constant 2
  // of that type.
  std::pair<std::uint32_t, std::uint32_t> Bits(std::uint32_t type) {
    if (auto found = bits_of_.find(type); found != bits_of_.end()) return found->second;
    if (uint_ == 0) Make({Word(spv::OpTypeInt, 4), uint_ = Fresh(), 32, 0});
    if (two_ == 0) Make({Word(spv::OpConstant, 4), uint_, two_ = Fresh(), 2});
    std::pair<std::uint32_t, std::uint32_t> bits{uint_, two_};
    if (auto v = vectors_.find(type); v != vectors_.end()) {
      const std::uint32_t count = v->second.second;
      bits = {SameShape(type, uint_), Fresh()};
      Make({Word(spv::OpConstantComposite, 3 + count), bits.first, bits.second});
      made_.insert(made_.end(), count, two_);
    }
    return bits_of_[type] = bits;
  }

 private:
  void Make(std::initializer_list<std::uint32_t> words) { made_.insert(made_.end(), words); }

  // `component`, or a vector of it as long as `type` is one.
  std::uint32_t SameShape(std::uint32_t type, std::uint32_t component) {
    auto v = vectors_.find(type);
    if (v == vectors_.end()) return component;
    const std::pair<std::uint32_t, std::uint32_t> key{component, v->second.second};
    auto existing = vector_of_.find(key);
    if (existing == vector_of_.end()) {
      existing = vector_of_.emplace(key, Fresh()).first;
      Make({Word(spv::OpTypeVector, 4), existing->second, component, key.second});
    }
    return existing->second;
  }

  std::uint32_t bound_;
  std::map<std::uint32_t, std::uint32_t> float_width_;                        // type id -> width
  std::map<std::uint32_t, std::pair<std::uint32_t, std::uint32_t>> vectors_;  // id -> (component, count)
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> vector_of_;
  std::map<std::uint32_t, std::pair<std::uint32_t, std::uint32_t>> bits_of_;
  std::uint32_t double_ = 0, uint_ = 0, two_ = 0;
  std::vector<std::uint32_t> made_;
};

// A float32 OpFDiv (w) as a float64 division rounded once to float32; with
// `worst`, that quotient then moved two steps of its bits away from zero:
// 2 ulp off the correctly rounded one, within Vulkan's 2.5 ulp of the exact.
void RewriteDivision(const std::uint32_t* w, bool worst, TypeTable& types, std::vector<std::uint32_t>& to) {
  const std::uint32_t type = w[1], result = w[2], a = w[3], b = w[4];
  const std::uint32_t wide = types.Widened(type);
  const std::uint32_t wide_a = types.Fresh(), wide_b = types.Fresh(), quotient = types.Fresh();
  const std::uint32_t rounded = worst ? types.Fresh() : result;
  to.insert(to.end(), {Word(spv::OpFConvert, 4), wide, wide_a, a, Word(spv::OpFConvert, 4), wide, wide_b, b,
                       Word(spv::OpFDiv, 5), wide, quotient, wide_a, wide_b, Word(spv::OpFConvert, 4), type, rounded,
                       quotient});
  if (!worst) return;
  const auto [uint_of, two_of] = types.Bits(type);
  const std::uint32_t raw = types.Fresh(), pushed = types.Fresh();
  to.insert(to.end(), {Word(spv::OpBitcast, 4), uint_of, raw, rounded, Word(spv::OpIAdd, 5), uint_of, pushed, raw,
                       two_of, Word(spv::OpBitcast, 4), type, result, pushed});
}

}  // namespace

Expected<std::uint32_t> ParseArithmeticProbes(std::string_view text) {
  std::uint32_t probes = 0;
  while (!text.empty()) {
    const std::size_t plus = text.find('+');
    const std::string_view name = text.substr(0, plus);
    bool known = false;
    for (const Probe& p : kProbes) {
      if (p.name == name) {
        probes |= p.bit;
        known = true;
      }
    }
    if (!known) {
      return InvalidArgument(
          fmt::format("unknown arithmetic probe '{}'; allowed: no-contraction, exact-division, worst-division "
                      "(or several, joined by '+')",
                      name));
    }
    text = plus == std::string_view::npos ? std::string_view() : text.substr(plus + 1);
  }
  return probes;
}

std::string ArithmeticProbesName(std::uint32_t probes) {
  std::string name;
  for (const Probe& p : kProbes) {
    if ((probes & p.bit) == 0) continue;
    if (!name.empty()) name += '+';
    name += p.name;
  }
  return name;
}

Expected<std::vector<std::uint32_t>> ApplyArithmeticProbes(std::span<const std::uint32_t> spirv, std::uint32_t probes) {
  DB_ASSIGN_OR_RETURN(const std::vector<Instruction> instructions, Instructions(spirv));
  if (probes == 0) return std::vector<std::uint32_t>(spirv.begin(), spirv.end());
  const bool no_contraction = (probes & kNoContraction) != 0;
  const bool worst_division = (probes & kWorstDivision) != 0;
  const bool exact_division = (probes & kExactDivision) != 0 || worst_division;

  // First pass: the types, the results to decorate, where functions begin.
  TypeTable types(spirv, instructions);
  std::vector<std::uint32_t> contractible;
  bool float64_capability = false;
  std::size_t first_function = spirv.size();
  for (const Instruction& inst : instructions) {
    const std::uint32_t* w = spirv.data() + inst.at;
    if (inst.op == spv::OpCapability && w[1] == spv::CapabilityFloat64) float64_capability = true;
    if (Contractible(inst.op)) contractible.push_back(w[2]);
    if (inst.op == spv::OpFunction && first_function == spirv.size()) first_function = inst.at;
  }

  // Second pass: copy, inserting and rewriting.
  std::vector<std::uint32_t> out(spirv.begin(), spirv.begin() + kHeaderWords);
  bool decorated = false, capability_added = false;
  std::vector<std::uint32_t> tail;  // the functions, rewritten
  for (const Instruction& inst : instructions) {
    const std::uint32_t* w = spirv.data() + inst.at;
    std::vector<std::uint32_t>& to = inst.at >= first_function ? tail : out;
    if (exact_division && !float64_capability && !capability_added && inst.op != spv::OpCapability) {
      out.insert(out.end(), {Word(spv::OpCapability, 2), spv::CapabilityFloat64});
      capability_added = true;
    }
    if (no_contraction && !decorated && !BeforeTypes(inst.op)) {
      for (std::uint32_t id : contractible) {
        out.insert(out.end(), {Word(spv::OpDecorate, 3), id, spv::DecorationNoContraction});
      }
      decorated = true;
    }
    if (exact_division && inst.op == spv::OpFDiv && types.IsFloat32(w[1])) {
      RewriteDivision(w, worst_division, types, to);
      continue;
    }
    to.insert(to.end(), w, w + inst.words);
  }
  // The new types close the global section, before the first function.
  out.insert(out.end(), types.made().begin(), types.made().end());
  out.insert(out.end(), tail.begin(), tail.end());
  out[kBoundWord] = types.bound();
  return out;
}

}  // namespace depthbench
