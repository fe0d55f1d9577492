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
    {kNoContraction, "no-contraction"}, {kExactDivision, "exact-division"}, {kWorstDivision, "worst-division"}};

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

  // First pass: the float types, the results to decorate, the divisions.
  std::map<std::uint32_t, std::uint32_t> float_width;                        // type id -> width
  std::map<std::uint32_t, std::pair<std::uint32_t, std::uint32_t>> vectors;  // id -> (component, count)
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> vector_of;
  std::vector<std::uint32_t> contractible;
  std::uint32_t uint_type = 0;
  bool float64_capability = false;
  for (const Instruction& inst : instructions) {
    const std::uint32_t* w = spirv.data() + inst.at;
    if (inst.op == spv::OpCapability && w[1] == spv::CapabilityFloat64) float64_capability = true;
    if (inst.op == spv::OpTypeFloat) float_width[w[1]] = w[2];
    if (inst.op == spv::OpTypeInt && w[2] == 32 && w[3] == 0) uint_type = w[1];
    if (inst.op == spv::OpTypeVector) {
      vectors[w[1]] = {w[2], w[3]};
      vector_of[{w[2], w[3]}] = w[1];
    }
    if (Contractible(inst.op)) contractible.push_back(w[2]);
  }
  std::uint32_t bound = spirv[kBoundWord];
  // The float64 types the divisions need, made where missing.
  std::vector<std::uint32_t> new_types;
  std::uint32_t double_type = 0;
  for (const auto& [id, width] : float_width) {
    if (width == 64) double_type = id;
  }
  std::map<std::uint32_t, std::uint32_t> widened;  // float32 type -> its float64 counterpart
  auto widen = [&](std::uint32_t type) -> std::uint32_t {
    if (auto found = widened.find(type); found != widened.end()) return found->second;
    if (double_type == 0) {
      double_type = bound++;
      new_types.insert(new_types.end(), {Word(spv::OpTypeFloat, 3), double_type, 64});
    }
    std::uint32_t wide = double_type;
    if (auto v = vectors.find(type); v != vectors.end()) {
      const std::pair<std::uint32_t, std::uint32_t> key{double_type, v->second.second};
      if (auto existing = vector_of.find(key); existing != vector_of.end()) {
        wide = existing->second;
      } else {
        wide = bound++;
        vector_of[key] = wide;
        new_types.insert(new_types.end(), {Word(spv::OpTypeVector, 4), wide, double_type, v->second.second});
      }
    }
    widened[type] = wide;
    return wide;
  };
  // worst-division: the unsigned integer type of a float32 type's bits, and
  // the constant 2 of that type, made where missing.
  std::uint32_t two = 0;
  std::map<std::uint32_t, std::pair<std::uint32_t, std::uint32_t>> bits_of;
  auto bits = [&](std::uint32_t type) -> std::pair<std::uint32_t, std::uint32_t> {
    if (auto found = bits_of.find(type); found != bits_of.end()) return found->second;
    if (uint_type == 0) {
      uint_type = bound++;
      new_types.insert(new_types.end(), {Word(spv::OpTypeInt, 4), uint_type, 32, 0});
    }
    if (two == 0) {
      two = bound++;
      new_types.insert(new_types.end(), {Word(spv::OpConstant, 4), uint_type, two, 2});
    }
    std::pair<std::uint32_t, std::uint32_t> made{uint_type, two};
    if (auto v = vectors.find(type); v != vectors.end()) {
      const std::uint32_t count = v->second.second;
      const std::pair<std::uint32_t, std::uint32_t> key{uint_type, count};
      auto existing = vector_of.find(key);
      if (existing == vector_of.end()) {
        existing = vector_of.emplace(key, bound++).first;
        new_types.insert(new_types.end(), {Word(spv::OpTypeVector, 4), existing->second, uint_type, count});
      }
      made = {existing->second, bound++};
      new_types.insert(new_types.end(), {Word(spv::OpConstantComposite, 3 + count), made.first, made.second});
      new_types.insert(new_types.end(), count, two);
    }
    bits_of[type] = made;
    return made;
  };
  auto is_float32 = [&](std::uint32_t type) {
    if (auto v = vectors.find(type); v != vectors.end()) type = v->second.first;
    auto f = float_width.find(type);
    return f != float_width.end() && f->second == 32;
  };

  // Second pass: copy, inserting and rewriting.
  std::vector<std::uint32_t> out(spirv.begin(), spirv.begin() + kHeaderWords);
  bool decorated = false, capability_added = false;
  std::size_t first_function = spirv.size();
  for (const Instruction& inst : instructions) {
    if (inst.op == spv::OpFunction) {
      first_function = inst.at;
      break;
    }
  }
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
    if (exact_division && inst.op == spv::OpFDiv && is_float32(w[1])) {
      const std::uint32_t type = w[1], result = w[2], a = w[3], b = w[4];
      const std::uint32_t wide = widen(type);
      const std::uint32_t wide_a = bound++, wide_b = bound++, quotient = bound++;
      const std::uint32_t rounded = worst_division ? bound++ : result;
      to.insert(to.end(), {Word(spv::OpFConvert, 4), wide, wide_a, a, Word(spv::OpFConvert, 4), wide, wide_b, b,
                           Word(spv::OpFDiv, 5), wide, quotient, wide_a, wide_b, Word(spv::OpFConvert, 4), type, rounded,
                           quotient});
      if (worst_division) {
        // Two steps of the float's bits away from zero: the correctly
        // rounded quotient moved by 2 ulp, within 2.5 ulp of the exact one.
        const auto [uint_of, two_of] = bits(type);
        const std::uint32_t raw = bound++, pushed = bound++;
        to.insert(to.end(), {Word(spv::OpBitcast, 4), uint_of, raw, rounded, Word(spv::OpIAdd, 5), uint_of, pushed, raw,
                             two_of, Word(spv::OpBitcast, 4), type, result, pushed});
      }
      continue;
    }
    to.insert(to.end(), w, w + inst.words);
  }
  // The new types close the global section, before the first function.
  out.insert(out.end(), new_types.begin(), new_types.end());
  out.insert(out.end(), tail.begin(), tail.end());
  out[kBoundWord] = bound;
  return out;
}

}  // namespace depthbench
