#include "bench/speed/instruction_mix.h"

#include <algorithm>
#include <functional>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>
#include <glslang/SPIRV/GLSL.std.450.h>
#include <spirv-tools/libspirv.h>
#include <glslang/SPIRV/spirv.hpp>

namespace depthbench {
namespace {

// What one function's own body holds, before its callees are added.
struct FunctionBody {
  InstructionMix own;
  std::vector<std::uint32_t> callees;  // one entry per call site
};

// Everything the counter needs from one pass over the module.
struct ModuleScan {
  std::unordered_map<std::uint32_t, std::string> names;             // id -> OpName
  std::unordered_map<std::uint32_t, std::uint32_t> type_lanes;      // type id -> scalar lanes
  std::unordered_map<std::uint32_t, std::uint32_t> matrix_columns;  // matrix type id -> columns
  std::unordered_map<std::uint32_t, std::uint32_t> value_types;     // result id -> type id
  std::unordered_map<std::uint32_t, bool> glsl_std_450_sets;        // ext inst import ids
  std::unordered_map<std::uint32_t, FunctionBody> functions;
  std::uint32_t current_function = 0;  // 0 outside functions
};

std::string DecodeString(const std::uint32_t* words, std::size_t count) {
  std::string text;
  for (std::size_t w = 0; w < count; ++w) {
    for (int byte = 0; byte < 4; ++byte) {
      const char c = static_cast<char>((words[w] >> (8 * byte)) & 0xffu);
      if (c == '\0') return text;
      text.push_back(c);
    }
  }
  return text;
}

std::uint32_t LanesOf(const ModuleScan& scan, std::uint32_t type_id) {
  auto it = scan.type_lanes.find(type_id);
  return it == scan.type_lanes.end() ? 1 : it->second;
}

// The scalar lanes of the type of value `id` (an operand).
std::uint32_t LanesOfValue(const ModuleScan& scan, std::uint32_t id) {
  auto it = scan.value_types.find(id);
  return it == scan.value_types.end() ? 1 : LanesOf(scan, it->second);
}

void Add(OpCount& count, std::uint32_t lanes) {
  ++count.instructions;
  count.lanes += lanes;
}

// Types and declarations, and every instruction inside a function.
spv_result_t ScanInstruction(void* user_data, const spv_parsed_instruction_t* inst) {
  auto& scan = *static_cast<ModuleScan*>(user_data);
  const std::uint32_t* w = inst->words;
  if (inst->result_id != 0 && inst->type_id != 0) scan.value_types[inst->result_id] = inst->type_id;
  switch (static_cast<spv::Op>(inst->opcode)) {
    case spv::OpName: scan.names[w[1]] = DecodeString(w + 2, inst->num_words - 2u); return SPV_SUCCESS;
    case spv::OpExtInstImport:
      scan.glsl_std_450_sets[w[1]] = DecodeString(w + 2, inst->num_words - 2u) == "GLSL.std.450";
      return SPV_SUCCESS;
    case spv::OpTypeFloat:
    case spv::OpTypeInt:
    case spv::OpTypeBool: scan.type_lanes[w[1]] = 1; return SPV_SUCCESS;
    case spv::OpTypeVector: scan.type_lanes[w[1]] = LanesOf(scan, w[2]) * w[3]; return SPV_SUCCESS;
    case spv::OpTypeMatrix:
      scan.type_lanes[w[1]] = LanesOf(scan, w[2]) * w[3];
      scan.matrix_columns[w[1]] = w[3];
      return SPV_SUCCESS;
    case spv::OpFunction:
      scan.current_function = inst->result_id;
      scan.functions[inst->result_id];
      return SPV_SUCCESS;
    case spv::OpFunctionEnd: scan.current_function = 0; return SPV_SUCCESS;
    default: break;
  }
  if (scan.current_function == 0) return SPV_SUCCESS;

  FunctionBody& body = scan.functions[scan.current_function];
  InstructionMix& mix = body.own;
  ++mix.total_instructions;
  const std::uint32_t lanes = inst->type_id != 0 ? LanesOf(scan, inst->type_id) : 0;
  switch (static_cast<spv::Op>(inst->opcode)) {
    case spv::OpFDiv: Add(mix.fdiv, lanes); break;
    case spv::OpFMul:
    case spv::OpVectorTimesScalar:
    case spv::OpMatrixTimesScalar: Add(mix.fmul, lanes); break;
    case spv::OpFAdd:
    case spv::OpFSub: Add(mix.fadd, lanes); break;
    case spv::OpFNegate: Add(mix.fneg, lanes); break;
    case spv::OpDot: Add(mix.dot, LanesOfValue(scan, w[3])); break;
    case spv::OpMatrixTimesVector:
    case spv::OpVectorTimesMatrix:
      // Each result lane is a dot product over the other operand's length:
      // result lanes * that length multiply-adds (the whole matrix).
      {
        const std::uint32_t matrix = inst->opcode == spv::OpMatrixTimesVector ? w[3] : w[4];
        Add(mix.matrix_vector, LanesOfValue(scan, matrix));
      }
      break;
    case spv::OpMatrixTimesMatrix: {
      // (rows x k) * (k x columns): rows * columns * k multiply-adds.
      const std::uint32_t right_columns = scan.matrix_columns[scan.value_types[w[4]]];
      const std::uint32_t k = LanesOfValue(scan, w[4]) / std::max<std::uint32_t>(1, right_columns);
      Add(mix.matrix_matrix, lanes * k);
      break;
    }
    case spv::OpExtInst: {
      const bool glsl = scan.glsl_std_450_sets[w[3]];
      const std::uint32_t number = w[4];
      if (glsl && number == GLSLstd450Fma) {
        Add(mix.fma, lanes);
      } else {
        Add(mix.extended, lanes);
        Add(mix.extended_by_name[glsl ? GlslStd450Name(number) : fmt::format("extended #{}", number)], lanes);
      }
      break;
    }
    case spv::OpFunctionCall:
      ++mix.function_calls;
      body.callees.push_back(w[3]);
      break;
    default: break;
  }
  return SPV_SUCCESS;
}

}  // namespace

InstructionMix& InstructionMix::operator+=(const InstructionMix& other) {
  fdiv += other.fdiv;
  fmul += other.fmul;
  fadd += other.fadd;
  fneg += other.fneg;
  fma += other.fma;
  dot += other.dot;
  matrix_vector += other.matrix_vector;
  matrix_matrix += other.matrix_matrix;
  extended += other.extended;
  for (const auto& [name, count] : other.extended_by_name) extended_by_name[name] += count;
  function_calls += other.function_calls;
  total_instructions += other.total_instructions;
  return *this;
}

std::string GlslStd450Name(std::uint32_t number) {
  switch (number) {
    case GLSLstd450Round: return "Round";
    case GLSLstd450Trunc: return "Trunc";
    case GLSLstd450FAbs: return "FAbs";
    case GLSLstd450FSign: return "FSign";
    case GLSLstd450Floor: return "Floor";
    case GLSLstd450Ceil: return "Ceil";
    case GLSLstd450Fract: return "Fract";
    case GLSLstd450Sin: return "Sin";
    case GLSLstd450Cos: return "Cos";
    case GLSLstd450Tan: return "Tan";
    case GLSLstd450Atan: return "Atan";
    case GLSLstd450Atan2: return "Atan2";
    case GLSLstd450Pow: return "Pow";
    case GLSLstd450Exp: return "Exp";
    case GLSLstd450Log: return "Log";
    case GLSLstd450Exp2: return "Exp2";
    case GLSLstd450Log2: return "Log2";
    case GLSLstd450Sqrt: return "Sqrt";
    case GLSLstd450InverseSqrt: return "InverseSqrt";
    case GLSLstd450Determinant: return "Determinant";
    case GLSLstd450MatrixInverse: return "MatrixInverse";
    case GLSLstd450FMin: return "FMin";
    case GLSLstd450UMin: return "UMin";
    case GLSLstd450SMin: return "SMin";
    case GLSLstd450FMax: return "FMax";
    case GLSLstd450UMax: return "UMax";
    case GLSLstd450SMax: return "SMax";
    case GLSLstd450FClamp: return "FClamp";
    case GLSLstd450UClamp: return "UClamp";
    case GLSLstd450SClamp: return "SClamp";
    case GLSLstd450FMix: return "FMix";
    case GLSLstd450Step: return "Step";
    case GLSLstd450SmoothStep: return "SmoothStep";
    case GLSLstd450Fma: return "Fma";
    case GLSLstd450Ldexp: return "Ldexp";
    case GLSLstd450Length: return "Length";
    case GLSLstd450Distance: return "Distance";
    case GLSLstd450Cross: return "Cross";
    case GLSLstd450Normalize: return "Normalize";
    case GLSLstd450NMin: return "NMin";
    case GLSLstd450NMax: return "NMax";
    case GLSLstd450NClamp: return "NClamp";
    default: return fmt::format("GLSL.std.450 #{}", number);
  }
}

Expected<InstructionMix> CountInstructionMix(std::span<const std::uint32_t> spirv, std::string_view function_name) {
  ModuleScan scan;
  spv_context context = spvContextCreate(SPV_ENV_UNIVERSAL_1_3);
  spv_diagnostic diagnostic = nullptr;
  const spv_result_t parsed =
      spvBinaryParse(context, &scan, spirv.data(), spirv.size(), nullptr, ScanInstruction, &diagnostic);
  std::string problem;
  if (parsed != SPV_SUCCESS) {
    problem = diagnostic != nullptr && diagnostic->error != nullptr ? diagnostic->error : "no message";
  }
  spvDiagnosticDestroy(diagnostic);
  spvContextDestroy(context);
  if (parsed != SPV_SUCCESS) {
    return InvalidArgument(fmt::format("the SPIR-V module does not parse (SPIRV-Tools: {})", problem));
  }

  const std::string prefix = std::string(function_name) + "(";
  std::uint32_t root = 0;
  for (const auto& [id, body] : scan.functions) {
    auto name = scan.names.find(id);
    if (name != scan.names.end() && (name->second == function_name || name->second.starts_with(prefix))) {
      root = id;
      break;
    }
  }
  if (root == 0) {
    return InvalidArgument(
        fmt::format("the SPIR-V module has no function named '{}' (is it called, and "
                    "was the module compiled with debug names?)",
                    function_name));
  }

  // Inclusive mixes, memoized; GLSL forbids recursion, and a cycle here
  // would mean a malformed module.
  std::unordered_map<std::uint32_t, InstructionMix> inclusive;
  std::unordered_map<std::uint32_t, bool> in_progress;
  std::function<Expected<InstructionMix>(std::uint32_t)> total = [&](std::uint32_t id) -> Expected<InstructionMix> {
    if (auto done = inclusive.find(id); done != inclusive.end()) return done->second;
    auto body = scan.functions.find(id);
    if (body == scan.functions.end()) return InvalidArgument(fmt::format("call of the undefined function %{}", id));
    if (in_progress[id]) return InvalidArgument(fmt::format("function %{} calls itself", id));
    in_progress[id] = true;
    InstructionMix mix = body->second.own;
    for (std::uint32_t callee : body->second.callees) {
      DB_ASSIGN_OR_RETURN(const InstructionMix callee_mix, total(callee));
      mix += callee_mix;
    }
    in_progress[id] = false;
    inclusive[id] = mix;
    return mix;
  };
  return total(root);
}

}  // namespace depthbench
