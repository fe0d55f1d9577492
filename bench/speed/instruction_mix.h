// The static cost of a shader function: its instruction mix by class,
// counted from the compiled SPIR-V (parsed with SPIRV-Tools), never from
// the GLSL text. A function's mix includes the functions it calls, once
// per call site (the formulas have no loops or recursion, so this is what
// one call executes).
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>

#include "bench/base/status.h"

namespace depthbench {

// A class of operations: how many SPIR-V instructions, and how many scalar
// lanes they compute (a vec3 divide is one instruction of three lanes).
struct OpCount {
  std::uint32_t instructions = 0;
  std::uint32_t lanes = 0;
  OpCount& operator+=(const OpCount& other) {
    instructions += other.instructions;
    lanes += other.lanes;
    return *this;
  }
  friend bool operator==(const OpCount&, const OpCount&) = default;
};

struct InstructionMix {
  OpCount fdiv;           // OpFDiv (reciprocals 1/x included: SPIR-V has no reciprocal)
  OpCount fmul;           // OpFMul, OpVectorTimesScalar, OpMatrixTimesScalar
  OpCount fadd;           // OpFAdd, OpFSub
  OpCount fneg;           // OpFNegate
  OpCount fma;            // GLSL.std.450 Fma
  OpCount dot;            // OpDot: lanes = the vectors' length
  OpCount matrix_vector;  // OpMatrixTimesVector, OpVectorTimesMatrix: lanes = the multiply-adds
  OpCount matrix_matrix;  // OpMatrixTimesMatrix: lanes = the multiply-adds
  OpCount extended;       // every other GLSL.std.450 instruction (inversesqrt, sqrt, min, ...)
  std::map<std::string, OpCount> extended_by_name;  // "InverseSqrt" -> count
  std::uint32_t function_calls = 0;
  // Every instruction of the function's body and of what it calls
  // (labels and variables included, OpFunction/OpFunctionEnd not).
  std::uint32_t total_instructions = 0;

  InstructionMix& operator+=(const InstructionMix& other);
  friend bool operator==(const InstructionMix&, const InstructionMix&) = default;
};

// The mix of the function whose debug name is `function_name`, or starts
// with it followed by '(' (glslang names functions "name(" + their
// parameter signature, except the entry point "main"), in a SPIR-V module. InvalidArgument when the module does not
// parse or no function of that name is in it.
Expected<InstructionMix> CountInstructionMix(std::span<const std::uint32_t> spirv, std::string_view function_name);

// Name of a GLSL.std.450 instruction ("InverseSqrt"), or "GLSL.std.450 #N".
std::string GlslStd450Name(std::uint32_t number);

}  // namespace depthbench
