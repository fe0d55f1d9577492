#include "bench/bound/spirv_eval.h"

#include <algorithm>
#include <atomic>
#include <unordered_map>

#include <fmt/format.h>
#include <glslang/SPIRV/GLSL.std.450.h>
#include <glslang/SPIRV/spirv.hpp>

namespace depthbench::bound {

namespace {

struct Instruction {
  spv::Op op;
  const std::uint32_t* w;  // w[0] is the opcode word, w[1] on the operands
  std::uint32_t count;     // words, the opcode word included
  std::uint32_t file;      // OpString id of the source file (0: none)
  std::uint32_t line;
};

struct Type {
  spv::Op op = spv::OpNop;             // OpTypeFloat, OpTypeVector, ...
  std::uint32_t width = 0;             // bits of a scalar
  std::uint32_t element = 0;           // vector, matrix, array: the part's type; pointer: the pointee
  std::uint32_t count = 0;             // vector, matrix, array: how many parts
  std::vector<std::uint32_t> members;  // struct
};

struct FunctionInfo {
  std::vector<std::uint32_t> parameters;                  // OpFunctionParameter result ids
  std::size_t first = 0;                                  // the body's first instruction (its first OpLabel)
  std::size_t end = 0;                                    // its OpFunctionEnd
  std::unordered_map<std::uint32_t, std::size_t> labels;  // label id -> instruction index
};

// Values by id, for one evaluation at a time: a flat array (SPIR-V ids are
// small and unique in a module), cleared in O(1) by moving to a new
// generation, so that the many evaluations of one analysis reuse it.
class IdMap {
 public:
  void Clear() { ++generation_; }
  const Value* Find(std::uint32_t id) const {
    return id < values_.size() && generations_[id] == generation_ ? &values_[id] : nullptr;
  }
  bool Contains(std::uint32_t id) const { return Find(id) != nullptr; }
  // The value of `id`, empty if it had none in this evaluation.
  Value& operator[](std::uint32_t id) {
    if (id >= values_.size()) {
      values_.resize(id + 1);
      generations_.resize(id + 1, 0);
    }
    if (generations_[id] != generation_) {
      values_[id] = Value{};
      generations_[id] = generation_;
    }
    return values_[id];
  }

 private:
  std::vector<Value> values_;
  std::vector<std::uint32_t> generations_;
  std::uint32_t generation_ = 1;
};

std::string Text(const std::uint32_t* words, std::size_t count) {
  std::string text(reinterpret_cast<const char*>(words), count * sizeof(std::uint32_t));
  return text.substr(0, text.find('\0'));
}

}  // namespace

class Module {
 public:
  std::vector<std::uint32_t> words;
  std::vector<Instruction> code;
  std::unordered_map<std::uint32_t, Type> types;
  std::unordered_map<std::uint32_t, std::uint32_t> type_of;  // result id -> type id
  std::unordered_map<std::uint32_t, Value> constants;
  std::unordered_map<std::uint32_t, FunctionInfo> functions;
  std::unordered_map<std::uint32_t, std::string> names, strings;
  std::unordered_map<std::uint32_t, std::size_t> globals;  // module-scope OpVariable -> its instruction
  std::uint32_t glsl_std_450 = 0;
  std::uint32_t id_bound = 0;
  bool row_major = false;  // some member is decorated RowMajor
  // The evaluations' values and variables (one evaluation at a time).
  mutable IdMap values, memory;

  // A value of `type` whose lanes are all undefined (or zero).
  Value Shape(std::uint32_t type_id, bool zero) const {
    const auto it = types.find(type_id);
    if (it == types.end()) return {};
    const Type& t = it->second;
    switch (t.op) {
      case spv::OpTypeFloat: return zero ? Value::Float(Lane::Exact(0.0)) : Value{};
      case spv::OpTypeInt:
      case spv::OpTypeBool: return zero ? Value::Integer(0) : Value{};
      case spv::OpTypeVector:
      case spv::OpTypeMatrix:
      case spv::OpTypeArray: return Value::Composite(std::vector<Value>(t.count, Shape(t.element, zero)));
      case spv::OpTypeStruct: {
        std::vector<Value> parts;
        for (std::uint32_t member : t.members) parts.push_back(Shape(member, zero));
        return Value::Composite(std::move(parts));
      }
      default: return {};
    }
  }

  std::string Where(const Instruction& in) const {
    if (in.file == 0) return "";
    const auto name = strings.find(in.file);
    return fmt::format(" (line {} of {})", in.line, name == strings.end() ? "the program" : name->second);
  }

  Status Parse() {
    if (words.size() < 5 || words[0] != spv::MagicNumber) return InvalidArgument("not a SPIR-V module");
    id_bound = words[3];
    std::uint32_t file = 0, line = 0;
    std::uint32_t function = 0;
    for (std::size_t at = 5; at < words.size();) {
      const std::uint32_t count = words[at] >> 16;
      if (count == 0 || at + count > words.size()) return InvalidArgument("the SPIR-V module is cut short");
      const auto op = static_cast<spv::Op>(words[at] & 0xFFFFu);
      const std::uint32_t* w = &words[at];
      if (op == spv::OpLine) {
        file = w[1];
        line = w[2];
      } else if (op == spv::OpNoLine || op == spv::OpFunctionEnd) {
        file = 0;
      }
      code.push_back({op, w, count, file, line});
      const std::size_t index = code.size() - 1;
      DB_RETURN_IF_ERROR(Declare(code.back(), index, function));
      at += count;
    }
    return Status::Ok();
  }

 private:
  Status Declare(const Instruction& in, std::size_t index, std::uint32_t& function) {
    const std::uint32_t* w = in.w;
    switch (in.op) {
      case spv::OpName: names[w[1]] = Text(w + 2, in.count - 2); break;
      case spv::OpString: strings[w[1]] = Text(w + 2, in.count - 2); break;
      case spv::OpMemberDecorate:
        if (in.count > 3 && w[3] == spv::DecorationRowMajor) row_major = true;
        break;
      case spv::OpExtInstImport:
        if (Text(w + 2, in.count - 2) == "GLSL.std.450") glsl_std_450 = w[1];
        break;
      case spv::OpTypeFloat:
      case spv::OpTypeInt: types[w[1]] = {in.op, w[2], 0, 0, {}}; break;
      case spv::OpTypeBool: types[w[1]] = {in.op, 1, 0, 0, {}}; break;
      case spv::OpTypeVector:
      case spv::OpTypeMatrix: types[w[1]] = {in.op, 0, w[2], w[3], {}}; break;
      case spv::OpTypeArray: {
        const auto length = constants.find(w[3]);
        types[w[1]] = {
            in.op, 0, w[2], length == constants.end() ? 0 : static_cast<std::uint32_t>(length->second.integer), {}};
        break;
      }
      case spv::OpTypeStruct: types[w[1]] = {in.op, 0, 0, 0, std::vector<std::uint32_t>(w + 2, w + in.count)}; break;
      case spv::OpTypePointer: types[w[1]] = {in.op, 0, w[3], 0, {}}; break;
      case spv::OpConstant:
      case spv::OpSpecConstant: {
        type_of[w[2]] = w[1];
        const Type& t = types[w[1]];
        if (t.op == spv::OpTypeFloat && t.width == 32) {
          constants[w[2]] = Value::Float(Lane::Exact(static_cast<double>(std::bit_cast<float>(w[3]))));
        } else if (t.op == spv::OpTypeInt) {
          constants[w[2]] = Value::Integer(t.width > 32 && in.count > 4 ? (std::uint64_t{w[4]} << 32) | w[3] : w[3]);
        }
        break;
      }
      case spv::OpConstantTrue:
      case spv::OpConstantFalse:
      case spv::OpSpecConstantTrue:
      case spv::OpSpecConstantFalse:
        type_of[w[2]] = w[1];
        constants[w[2]] = Value::Integer(in.op == spv::OpConstantTrue || in.op == spv::OpSpecConstantTrue ? 1 : 0);
        break;
      case spv::OpConstantComposite:
      case spv::OpSpecConstantComposite: {
        type_of[w[2]] = w[1];
        std::vector<Value> parts;
        for (std::uint32_t k = 3; k < in.count; ++k) {
          const auto part = constants.find(w[k]);
          parts.push_back(part == constants.end() ? Value{} : part->second);
        }
        constants[w[2]] = Value::Composite(std::move(parts));
        break;
      }
      case spv::OpConstantNull: constants[w[2]] = Shape(w[1], true); break;
      case spv::OpUndef: constants[w[2]] = Shape(w[1], false); break;
      case spv::OpVariable:
        type_of[w[2]] = w[1];
        if (function == 0) globals[w[2]] = index;
        break;
      case spv::OpFunction:
        function = w[2];
        functions[function].first = 0;
        break;
      case spv::OpFunctionParameter:
        type_of[w[2]] = w[1];
        functions[function].parameters.push_back(w[2]);
        break;
      case spv::OpLabel: {
        FunctionInfo& f = functions[function];
        if (f.first == 0) f.first = index;
        f.labels[w[1]] = index;
        break;
      }
      case spv::OpFunctionEnd:
        functions[function].end = index;
        function = 0;
        break;
      default: break;
    }
    return Status::Ok();
  }
};

namespace {

using Op = spv::Op;

// Component-wise application of a binary float rule to two values of the
// same shape (scalars, vectors, matrices' columns).
template <class Rule>
Expected<Value> Lanewise(const Value& a, const Value& b, Rule rule) {
  if (a.kind == Value::Kind::kFloat && b.kind == Value::Kind::kFloat) {
    const Lane out = rule(a.lane, b.lane);
    if (out.error < 0.0 || !std::isfinite(out.error))
      return InvalidArgument("a divisor that may be zero or out of range");
    return Value::Float(out);
  }
  if (a.kind == Value::Kind::kComposite && b.kind == Value::Kind::kComposite && a.parts.size() == b.parts.size()) {
    std::vector<Value> parts;
    for (std::size_t k = 0; k < a.parts.size(); ++k) {
      Expected<Value> part = Lanewise(a.parts[k], b.parts[k], rule);
      if (!part.ok()) return part.status();
      parts.push_back(std::move(part).value());
    }
    return Value::Composite(std::move(parts));
  }
  return InvalidArgument("an operand with no known float value (an undefined or integer lane)");
}

// The same with a scalar for b: every lane of a times it.
template <class Rule>
Expected<Value> ByScalar(const Value& a, const Value& scalar, Rule rule) {
  if (a.kind == Value::Kind::kComposite) {
    std::vector<Value> parts;
    for (const Value& part : a.parts) {
      Expected<Value> out = ByScalar(part, scalar, rule);
      if (!out.ok()) return out.status();
      parts.push_back(std::move(out).value());
    }
    return Value::Composite(std::move(parts));
  }
  return Lanewise(a, scalar, rule);
}

Expected<std::vector<Lane>> Lanes(const Value& v) {
  std::vector<Lane> lanes;
  for (const Value& part : v.parts) {
    if (part.kind != Value::Kind::kFloat) return InvalidArgument("a vector with a lane of no known float value");
    lanes.push_back(part.lane);
  }
  return lanes;
}

Expected<Value> DotOf(const Value& a, const Value& b, const Machine& machine) {
  DB_ASSIGN_OR_RETURN(std::vector<Lane> x, Lanes(a));
  DB_ASSIGN_OR_RETURN(std::vector<Lane> y, Lanes(b));
  if (x.size() != y.size()) return InvalidArgument("a dot product of vectors of different lengths");
  return Value::Float(Dot(x, y, static_cast<int>(x.size()), machine));
}

// Rows of a matrix (its parts are columns) as vectors.
Value Transposed(const Value& m) {
  std::vector<Value> rows;
  const std::size_t row_count = m.parts.empty() ? 0 : m.parts[0].parts.size();
  for (std::size_t r = 0; r < row_count; ++r) {
    std::vector<Value> row;
    for (const Value& column : m.parts) row.push_back(r < column.parts.size() ? column.parts[r] : Value{});
    rows.push_back(Value::Composite(std::move(row)));
  }
  return Value::Composite(std::move(rows));
}

// A composite of f(part) for each part of `whole`.
template <class F>
Expected<Value> EachPart(const Value& whole, F f) {
  std::vector<Value> out;
  for (const Value& part : whole.parts) {
    DB_ASSIGN_OR_RETURN(Value v, f(part));
    out.push_back(std::move(v));
  }
  return Value::Composite(std::move(out));
}

// The bound on a camera-to-world product's error relative to the exact
// point's distance from the camera, or infinity where `m` and `v` are not
// one: m = [R~ t; 0 1] with R~ a rotation R rounded entry by entry and t
// exact, v = (v~, 1). A rotation keeps lengths, which lane by lane
// bounds cannot see: with |R v| = |v| the distance,
//   |fl(R~ v~ + t) - (R v + t)| <= |v~ - v| + |R~ - R|_F |v~|
//                                  + gamma_n (|(|R~| |v~|)| + |t|),
// the last the dot products' roundings in any order (n terms),
// |(|R~| |v~|)| <= (sqrt(3) + |R~ - R|_F) |v~| and |v~| <= (1 + r_v)|v|.
// Each lane's error enters by its relative bound where it has one, so the
// figure holds point by point, with the box's least |v| only where a lane
// has none (and for the translation's rounding).
double CameraToWorldRelative(const Value& m, const Value& v) {
  if (!m.camera_to_world || m.parts.size() != 4 || v.parts.size() != 4) return INFINITY;
  for (const Value& column : m.parts) {
    if (column.parts.size() != 4) return INFINITY;
    for (const Value& lane : column.parts)
      if (lane.kind != Value::Kind::kFloat) return INFINITY;
  }
  for (const Value& lane : v.parts)
    if (lane.kind != Value::Kind::kFloat) return INFINITY;
  const Lane& w = v.parts[3].lane;
  if (w.error != 0.0 || w.exact != Enclosure(1.0)) return INFINITY;
  // The view vector's error: relative lanes, and the rest over its least length.
  double least_sq = 0.0, relative = 0.0, absolute_sq = 0.0;
  for (int j = 0; j < 3; ++j) {
    const Lane& x = v.parts[j].lane;
    least_sq += x.exact.mig() * x.exact.mig();
    if (x.relative < INFINITY) {
      relative = std::max(relative, x.relative);
    } else {
      absolute_sq += x.error * x.error;
    }
  }
  const double least = std::sqrt(least_sq) * (1.0 - 0x1p-50);
  if (absolute_sq > 0.0 && !(least > 0.0)) return INFINITY;
  const double r_v = Up(std::sqrt(relative * relative + (absolute_sq > 0.0 ? absolute_sq / (least * least) : 0.0)));
  // |R~ - R|_F: each entry within its relative bound of |R_ij| <= 1, or its error.
  double entries_sq = 0.0, translation_sq = 0.0;
  bool translated = false;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      const Lane& e = m.parts[c].parts[r].lane;
      const double bound = std::min(e.error, e.relative);
      entries_sq += bound * bound;
    }
  }
  for (int r = 0; r < 3; ++r) {
    const Lane& t = m.parts[3].parts[r].lane;
    if (t.error != 0.0) return INFINITY;
    translation_sq += t.exact.mag() * t.exact.mag();
    translated = translated || t.exact != Enclosure(0.0);
  }
  const double frobenius = Up(std::sqrt(entries_sq));
  const int n = translated ? 4 : 3;
  const double gamma = n * kUnitRoundoff / (1.0 - n * kUnitRoundoff);
  const double translation = translated ? gamma * std::sqrt(translation_sq) / least : 0.0;
  if (translated && !(least > 0.0)) return INFINITY;
  // A rotation's exact entries are orthonormal to the double rounding of
  // the angles' sines and cosines: 2^-40 covers it.
  const double total = r_v * (1.0 + 0x1p-40) + frobenius * (1.0 + r_v) +
                       gamma * (std::sqrt(3.0) + frobenius) * (1.0 + r_v) + translation + n * kUnderflow / least;
  return std::isfinite(total) ? Up(total) : INFINITY;
}

std::atomic<std::uint32_t> next_vector{1};

// matrix * vector: the dot product of each row with the vector; a
// camera-to-world product's first three lanes carry its distance bound.
Expected<Value> MatrixTimesVector(const Value& m, const Value& v, const Machine& machine) {
  DB_ASSIGN_OR_RETURN(Value out, EachPart(Transposed(m), [&](const Value& row) { return DotOf(row, v, machine); }));
  const double relative = CameraToWorldRelative(m, v);
  if (relative < INFINITY && out.parts.size() == 4) {
    const std::uint32_t id = next_vector.fetch_add(1, std::memory_order_relaxed);
    for (int k = 0; k < 3; ++k) {
      Lane& lane = out.parts.Mutable()[k].lane;
      lane.vector = id;
      lane.component = k;
      lane.distance_relative = relative;
    }
  }
  return out;
}

// The part of `root` at `path`, to read; null when there is none.
const Value* At(const Value& root, std::span<const std::uint32_t> path) {
  const Value* v = &root;
  for (std::uint32_t index : path) {
    if (v->kind != Value::Kind::kComposite || index >= v->parts.size()) return nullptr;
    v = &v->parts[index];
  }
  return v;
}

// The same, to change: the parts on the way become `root`'s own.
Value* MutableAt(Value& root, std::span<const std::uint32_t> path) {
  Value* v = &root;
  for (std::uint32_t index : path) {
    if (v->kind != Value::Kind::kComposite || index >= v->parts.size()) return nullptr;
    v = &v->parts.Mutable()[index];
  }
  return v;
}

// The lanes of a vector operand of OpCompositeConstruct (or the scalar itself).
void Flatten(const Value& v, std::vector<Value>& out) {
  if (v.kind == Value::Kind::kComposite) {
    for (const Value& part : v.parts) out.push_back(part);
  } else {
    out.push_back(v);
  }
}

class Evaluator {
 public:
  Evaluator(const Module& module, const Machine& machine)
      : m_(module), machine_(machine), values_(module.values), memory_(module.memory), next_slot_(module.id_bound) {
    values_.Clear();
    memory_.Clear();
  }

  Expected<Value> Call(std::uint32_t function_id, std::vector<Value> arguments) {
    const auto found = m_.functions.find(function_id);
    if (found == m_.functions.end() || found->second.first == 0)
      return InvalidArgument("a call to a function with no body");
    if (++depth_ > 64) return InvalidArgument("calls nested more than 64 deep (recursion?)");
    const FunctionInfo& f = found->second;
    // Ids are unique in a module and calls do not recurse, so one map of
    // values serves every call.
    for (std::size_t k = 0; k < f.parameters.size() && k < arguments.size(); ++k) {
      values_[f.parameters[k]] = arguments[k];
    }
    Expected<Value> result = Run(f, values_, Name(function_id));
    --depth_;
    return result;
  }

  // A value for a parameter: a pointer parameter gets a variable holding it.
  Value Argument(std::uint32_t function_id, std::size_t k, const Value& value) {
    const FunctionInfo& f = m_.functions.at(function_id);
    const auto type = m_.type_of.find(f.parameters[k]);
    if (type == m_.type_of.end() || m_.types.at(type->second).op != Op::OpTypePointer) return value;
    const std::uint32_t slot = next_slot_++;
    memory_[slot] = value;
    Value pointer;
    pointer.kind = Value::Kind::kPointer;
    pointer.variable = slot;
    return pointer;
  }

 private:
  std::string Name(std::uint32_t id) const {
    const auto name = m_.names.find(id);
    if (name == m_.names.end()) return fmt::format("%{}", id);
    return name->second.substr(0, name->second.find('('));
  }

  Status Refuse(const Instruction& in, const std::string& function, const std::string& what) const {
    return InvalidArgument(fmt::format("cannot bound {} in {}{}", what, function, m_.Where(in)));
  }

  Expected<Value> Get(IdMap& values, std::uint32_t id) {
    if (const Value* v = values.Find(id)) return *v;
    if (const auto c = m_.constants.find(id); c != m_.constants.end()) return c->second;
    if (const auto g = m_.globals.find(id); g != m_.globals.end()) {
      if (!memory_.Contains(id)) {
        const Instruction& var = m_.code[g->second];
        const std::uint32_t pointee = m_.types.at(var.w[1]).element;
        memory_[id] =
            var.count > 4 && m_.constants.contains(var.w[4]) ? m_.constants.at(var.w[4]) : m_.Shape(pointee, false);
      }
      Value pointer;
      pointer.kind = Value::Kind::kPointer;
      pointer.variable = id;
      return pointer;
    }
    return InvalidArgument(fmt::format("a value (%{}) it has no bound for", id));
  }

  Expected<std::uint64_t> Known(IdMap& values, std::uint32_t id) {
    DB_ASSIGN_OR_RETURN(Value v, Get(values, id));
    if (v.kind != Value::Kind::kInteger)
      return InvalidArgument("an integer or condition that depends on computed floats");
    return v.integer;
  }

  Expected<Value> Float(const Instruction& in, IdMap& values) {
    const std::uint32_t* w = in.w;
    DB_ASSIGN_OR_RETURN(Value a, Get(values, w[3]));
    if (in.op == Op::OpFNegate) {
      return ByScalar(a, Value::Float(Lane::Exact(-1.0)), [](const Lane& x, const Lane&) { return Negate(x); });
    }
    DB_ASSIGN_OR_RETURN(Value b, Get(values, w[4]));
    const Machine& machine = machine_;
    const auto multiply = [&](const Lane& x, const Lane& y) { return Multiply(x, y, machine); };
    switch (in.op) {
      case Op::OpFAdd: return Lanewise(a, b, [&](const Lane& x, const Lane& y) { return Add(x, y, machine); });
      case Op::OpFSub: return Lanewise(a, b, [&](const Lane& x, const Lane& y) { return Subtract(x, y, machine); });
      case Op::OpFMul: return Lanewise(a, b, multiply);
      case Op::OpFDiv: return Lanewise(a, b, [&](const Lane& x, const Lane& y) { return Divide(x, y, machine); });
      case Op::OpVectorTimesScalar:
      case Op::OpMatrixTimesScalar: return ByScalar(a, b, multiply);
      case Op::OpDot: return DotOf(a, b, machine);
      case Op::OpMatrixTimesVector: return MatrixTimesVector(a, b, machine);
      case Op::OpVectorTimesMatrix: return EachPart(b, [&](const Value& column) { return DotOf(a, column, machine); });
      case Op::OpMatrixTimesMatrix:
        return EachPart(b, [&](const Value& column) { return MatrixTimesVector(a, column, machine); });
      default: return InvalidArgument("not a float operation");
    }
  }

  Expected<Value> Extended(const Instruction& in, IdMap& values) {
    const std::uint32_t* w = in.w;
    if (w[3] != m_.glsl_std_450) return InvalidArgument("an extended instruction outside GLSL.std.450");
    auto operand = [&](int k) { return Get(values, w[k]); };
    switch (w[4]) {
      case GLSLstd450FAbs: {
        DB_ASSIGN_OR_RETURN(Value a, operand(5));
        return ByScalar(a, Value::Float(Lane::Exact(1.0)), [](const Lane& x, const Lane&) {
          auto abs = [](const Enclosure& e) {
            return e.contains_zero() ? Enclosure(0.0, e.mag()) : Enclosure(e.mig(), e.mag());
          };
          return Lane{abs(x.exact), x.error, abs(x.computed), x.relative};
        });
      }
      case GLSLstd450FMin:
      case GLSLstd450FMax:
      case GLSLstd450NMin:
      case GLSLstd450NMax: {
        // |min(x~, y~) - min(x, y)| <= max(ex, ey), and the same for max.
        const bool min = w[4] == GLSLstd450FMin || w[4] == GLSLstd450NMin;
        DB_ASSIGN_OR_RETURN(Value a, operand(5));
        DB_ASSIGN_OR_RETURN(Value b, operand(6));
        return Lanewise(a, b, [min](const Lane& x, const Lane& y) {
          auto pick = [min](const Enclosure& p, const Enclosure& q) {
            return min ? Enclosure(std::min(p.lo, q.lo), std::min(p.hi, q.hi))
                       : Enclosure(std::max(p.lo, q.lo), std::max(p.hi, q.hi));
          };
          return Lane{pick(x.exact, y.exact), std::max(x.error, y.error), pick(x.computed, y.computed)};
        });
      }
      case GLSLstd450Fma: {
        // Vulkan: inherited from a multiply followed by an add; the
        // unfused bound covers a fused one too.
        DB_ASSIGN_OR_RETURN(Value a, operand(5));
        DB_ASSIGN_OR_RETURN(Value b, operand(6));
        DB_ASSIGN_OR_RETURN(Value c, operand(7));
        const Machine& machine = machine_;
        DB_ASSIGN_OR_RETURN(Value product,
                            Lanewise(a, b, [&](const Lane& x, const Lane& y) { return Multiply(x, y, machine); }));
        return Lanewise(product, c, [&](const Lane& x, const Lane& y) { return Add(x, y, machine); });
      }
      default: return InvalidArgument(fmt::format("the GLSL.std.450 instruction #{}", w[4]));
    }
  }

  Expected<Value> Integer(const Instruction& in, IdMap& values) {
    const std::uint32_t* w = in.w;
    DB_ASSIGN_OR_RETURN(std::uint64_t a, Known(values, w[3]));
    if (in.op == Op::OpNot) return Value::Integer(~a & 0xFFFFFFFFu);
    if (in.op == Op::OpLogicalNot) return Value::Integer(a == 0 ? 1 : 0);
    if (in.op == Op::OpSNegate) return Value::Integer((0 - a) & 0xFFFFFFFFu);
    DB_ASSIGN_OR_RETURN(std::uint64_t b, Known(values, w[4]));
    const auto sa = static_cast<std::int32_t>(a), sb = static_cast<std::int32_t>(b);
    switch (in.op) {
      case Op::OpIAdd: return Value::Integer((a + b) & 0xFFFFFFFFu);
      case Op::OpISub: return Value::Integer((a - b) & 0xFFFFFFFFu);
      case Op::OpIMul: return Value::Integer((a * b) & 0xFFFFFFFFu);
      case Op::OpUDiv: return b == 0 ? Value::Integer(0) : Value::Integer(a / b);
      case Op::OpUMod: return b == 0 ? Value::Integer(0) : Value::Integer(a % b);
      case Op::OpBitwiseAnd: return Value::Integer(a & b);
      case Op::OpBitwiseOr: return Value::Integer(a | b);
      case Op::OpBitwiseXor: return Value::Integer(a ^ b);
      case Op::OpShiftLeftLogical: return Value::Integer((a << (b & 31u)) & 0xFFFFFFFFu);
      case Op::OpShiftRightLogical: return Value::Integer(a >> (b & 31u));
      case Op::OpShiftRightArithmetic: return Value::Integer(static_cast<std::uint32_t>(sa >> (b & 31u)));
      case Op::OpIEqual:
      case Op::OpLogicalEqual: return Value::Integer(a == b);
      case Op::OpINotEqual:
      case Op::OpLogicalNotEqual: return Value::Integer(a != b);
      case Op::OpULessThan: return Value::Integer(a < b);
      case Op::OpULessThanEqual: return Value::Integer(a <= b);
      case Op::OpUGreaterThan: return Value::Integer(a > b);
      case Op::OpUGreaterThanEqual: return Value::Integer(a >= b);
      case Op::OpSLessThan: return Value::Integer(sa < sb);
      case Op::OpSLessThanEqual: return Value::Integer(sa <= sb);
      case Op::OpSGreaterThan: return Value::Integer(sa > sb);
      case Op::OpSGreaterThanEqual: return Value::Integer(sa >= sb);
      case Op::OpLogicalAnd: return Value::Integer((a != 0) && (b != 0));
      case Op::OpLogicalOr: return Value::Integer((a != 0) || (b != 0));
      default: return InvalidArgument("not an integer operation");
    }
  }

  static bool IsInteger(Op op) {
    switch (op) {
      case Op::OpNot:
      case Op::OpLogicalNot:
      case Op::OpSNegate:
      case Op::OpIAdd:
      case Op::OpISub:
      case Op::OpIMul:
      case Op::OpUDiv:
      case Op::OpUMod:
      case Op::OpBitwiseAnd:
      case Op::OpBitwiseOr:
      case Op::OpBitwiseXor:
      case Op::OpShiftLeftLogical:
      case Op::OpShiftRightLogical:
      case Op::OpShiftRightArithmetic:
      case Op::OpIEqual:
      case Op::OpLogicalEqual:
      case Op::OpINotEqual:
      case Op::OpLogicalNotEqual:
      case Op::OpULessThan:
      case Op::OpULessThanEqual:
      case Op::OpUGreaterThan:
      case Op::OpUGreaterThanEqual:
      case Op::OpSLessThan:
      case Op::OpSLessThanEqual:
      case Op::OpSGreaterThan:
      case Op::OpSGreaterThanEqual:
      case Op::OpLogicalAnd:
      case Op::OpLogicalOr: return true;
      default: return false;
    }
  }
  static bool IsFloatOp(Op op) {
    switch (op) {
      case Op::OpFNegate:
      case Op::OpFAdd:
      case Op::OpFSub:
      case Op::OpFMul:
      case Op::OpFDiv:
      case Op::OpVectorTimesScalar:
      case Op::OpMatrixTimesScalar:
      case Op::OpDot:
      case Op::OpMatrixTimesVector:
      case Op::OpVectorTimesMatrix:
      case Op::OpMatrixTimesMatrix: return true;
      default: return false;
    }
  }
  static bool IsFloatComparison(Op op) { return op >= Op::OpFOrdEqual && op <= Op::OpFUnordGreaterThanEqual; }

  Expected<Value> Run(const FunctionInfo& f, IdMap& values, const std::string& name) {
    std::size_t pc = f.first;
    std::uint32_t block = 0, previous = 0;
    for (int steps = 0; steps < 1000000; ++steps) {
      if (pc >= f.end) return InvalidArgument(fmt::format("{} runs past its end", name));
      const Instruction& in = m_.code[pc];
      const std::uint32_t* w = in.w;
      auto refuse = [&](const std::string& what) { return Refuse(in, name, what); };
      auto jump = [&](std::uint32_t label) -> Status {
        const auto target = f.labels.find(label);
        if (target == f.labels.end()) return refuse("a branch to a missing block");
        pc = target->second;
        return Status::Ok();
      };
      auto set = [&](Expected<Value> v) -> Status {
        if (!v.ok()) return refuse(v.status().message());
        values[w[2]] = std::move(v).value();
        return Status::Ok();
      };
      ++pc;
      switch (in.op) {
        case Op::OpLabel:
          previous = block;
          block = w[1];
          break;
        case Op::OpLine:
        case Op::OpNoLine:
        case Op::OpNop:
        case Op::OpSelectionMerge:
        case Op::OpName:
        case Op::OpDecorate:
        case Op::OpMemberDecorate: break;
        case Op::OpLoopMerge: return refuse("a loop");
        case Op::OpBranch: DB_RETURN_IF_ERROR(jump(w[1])); break;
        case Op::OpBranchConditional: {
          Expected<std::uint64_t> condition = Known(values, w[1]);
          if (!condition.ok()) return refuse("a branch on a computed float value");
          DB_RETURN_IF_ERROR(jump(*condition != 0 ? w[2] : w[3]));
          break;
        }
        case Op::OpSwitch: {
          Expected<std::uint64_t> selector = Known(values, w[1]);
          if (!selector.ok()) return refuse("a switch on a computed value");
          std::uint32_t target = w[2];
          for (std::uint32_t k = 3; k + 1 < in.count; k += 2) {
            if (w[k] == *selector) target = w[k + 1];
          }
          DB_RETURN_IF_ERROR(jump(target));
          break;
        }
        case Op::OpPhi: {
          bool found = false;
          for (std::uint32_t k = 3; k + 1 < in.count; k += 2) {
            if (w[k + 1] == previous) {
              DB_RETURN_IF_ERROR(set(Get(values, w[k])));
              found = true;
            }
          }
          if (!found) return refuse("a phi with no value from the block before it");
          break;
        }
        case Op::OpReturn: return Value{};
        case Op::OpReturnValue: {
          Expected<Value> v = Get(values, w[1]);
          if (!v.ok()) return refuse(v.status().message());
          return v;
        }
        case Op::OpVariable: {
          // Without an initializer it is undefined; its shape is made only
          // when a part of it is stored first (most are stored whole).
          memory_[w[2]] = in.count > 4 ? Get(values, w[4]).value() : Value{};
          Value pointer;
          pointer.kind = Value::Kind::kPointer;
          pointer.variable = w[2];
          values[w[2]] = pointer;
          break;
        }
        case Op::OpAccessChain:
        case Op::OpInBoundsAccessChain: {
          Expected<Value> base = Get(values, w[3]);
          if (!base.ok() || base->kind != Value::Kind::kPointer) return refuse("an access through an unknown pointer");
          Value pointer = *base;
          for (std::uint32_t k = 4; k < in.count; ++k) {
            Expected<std::uint64_t> index = Known(values, w[k]);
            if (!index.ok()) return refuse("an index computed from floats");
            pointer.path.push_back(static_cast<std::uint32_t>(*index));
          }
          values[w[2]] = pointer;
          break;
        }
        case Op::OpLoad: {
          Expected<Value> pointer = Get(values, w[3]);
          if (!pointer.ok() || pointer->kind != Value::Kind::kPointer)
            return refuse("a load through an unknown pointer");
          const Value* v = At(memory_[pointer->variable], pointer->path);
          if (v == nullptr) return refuse("a load from outside its variable");
          values[w[2]] = *v;
          break;
        }
        case Op::OpStore: {
          Expected<Value> pointer = Get(values, w[1]);
          Expected<Value> v = Get(values, w[2]);
          if (!pointer.ok() || pointer->kind != Value::Kind::kPointer || !v.ok())
            return refuse("a store it cannot follow");
          Value& root = memory_[pointer->variable];
          if (root.kind == Value::Kind::kUndefined && !pointer->path.empty()) {
            const auto type = m_.type_of.find(pointer->variable);
            if (type != m_.type_of.end()) root = m_.Shape(m_.types.at(type->second).element, false);
          }
          Value* target = MutableAt(root, pointer->path);
          if (target == nullptr) return refuse("a store outside its variable");
          *target = std::move(v).value();
          break;
        }
        case Op::OpFunctionCall: {
          std::vector<Value> arguments;
          for (std::uint32_t k = 4; k < in.count; ++k) {
            Expected<Value> a = Get(values, w[k]);
            if (!a.ok()) return refuse(a.status().message());
            arguments.push_back(std::move(a).value());
          }
          Expected<Value> result = Call(w[3], std::move(arguments));
          if (!result.ok()) return result.status();
          values[w[2]] = std::move(result).value();
          break;
        }
        case Op::OpCopyObject: DB_RETURN_IF_ERROR(set(Get(values, w[3]))); break;
        case Op::OpCompositeConstruct: {
          const Type& type = m_.types.at(w[1]);
          std::vector<Value> parts;
          for (std::uint32_t k = 3; k < in.count; ++k) {
            Expected<Value> part = Get(values, w[k]);
            if (!part.ok()) return refuse(part.status().message());
            if (type.op == Op::OpTypeVector) {
              Flatten(*part, parts);
            } else {
              parts.push_back(std::move(part).value());
            }
          }
          values[w[2]] = Value::Composite(std::move(parts));
          break;
        }
        case Op::OpCompositeExtract: {
          Expected<Value> whole = Get(values, w[3]);
          if (!whole.ok()) return refuse(whole.status().message());
          const Value* v = At(*whole, std::span<const std::uint32_t>(w + 4, in.count - 4));
          if (v == nullptr) return refuse("an extract from outside its composite");
          values[w[2]] = *v;
          break;
        }
        case Op::OpCompositeInsert: {
          Expected<Value> part = Get(values, w[3]);
          Expected<Value> whole = Get(values, w[4]);
          if (!part.ok() || !whole.ok()) return refuse("an insert of an unknown value");
          Value out = std::move(whole).value();
          Value* v = MutableAt(out, std::span<const std::uint32_t>(w + 5, in.count - 5));
          if (v == nullptr) return refuse("an insert outside its composite");
          *v = std::move(part).value();
          values[w[2]] = std::move(out);
          break;
        }
        case Op::OpVectorShuffle: {
          Expected<Value> a = Get(values, w[3]);
          Expected<Value> b = Get(values, w[4]);
          if (!a.ok() || !b.ok()) return refuse("a shuffle of unknown vectors");
          std::vector<Value> parts;
          for (std::uint32_t k = 5; k < in.count; ++k) {
            const std::uint32_t c = w[k];
            if (c == 0xFFFFFFFFu) {
              parts.emplace_back();
            } else if (c < a->parts.size()) {
              parts.push_back(a->parts[c]);
            } else if (c - a->parts.size() < b->parts.size()) {
              parts.push_back(b->parts[c - a->parts.size()]);
            } else {
              return refuse("a shuffle component out of range");
            }
          }
          values[w[2]] = Value::Composite(std::move(parts));
          break;
        }
        case Op::OpVectorExtractDynamic: {
          Expected<Value> v = Get(values, w[3]);
          Expected<std::uint64_t> index = Known(values, w[4]);
          if (!v.ok() || !index.ok() || *index >= v->parts.size()) return refuse("a vector index computed from floats");
          values[w[2]] = v->parts[*index];
          break;
        }
        case Op::OpSelect: {
          Expected<Value> condition = Get(values, w[3]);
          if (!condition.ok()) return refuse(condition.status().message());
          if (condition->kind != Value::Kind::kInteger) return refuse("a select on a computed float value");
          DB_RETURN_IF_ERROR(set(Get(values, condition->integer != 0 ? w[4] : w[5])));
          break;
        }
        case Op::OpConvertUToF:
        case Op::OpConvertSToF: {
          Expected<std::uint64_t> x = Known(values, w[3]);
          if (!x.ok()) return refuse("a conversion of an unknown integer");
          const double exact =
              in.op == Op::OpConvertSToF ? static_cast<double>(static_cast<std::int32_t>(*x)) : static_cast<double>(*x);
          const double rounded = NearestFloat32(exact);
          const double error = std::fabs(rounded - exact);
          values[w[2]] = Value::Float(
              {Enclosure(exact), error, Enclosure(rounded), exact != 0.0 ? Up(error / std::fabs(exact)) : 0.0});
          break;
        }
        case Op::OpExtInst: DB_RETURN_IF_ERROR(set(Extended(in, values))); break;
        default:
          if (IsFloatOp(in.op)) {
            DB_RETURN_IF_ERROR(set(Float(in, values)));
          } else if (IsInteger(in.op)) {
            DB_RETURN_IF_ERROR(set(Integer(in, values)));
          } else if (IsFloatComparison(in.op)) {
            Value computed;
            computed.kind = Value::Kind::kComputedBool;
            values[w[2]] = computed;
          } else {
            return refuse(fmt::format("the instruction Op#{}", static_cast<int>(in.op)));
          }
      }
    }
    return InvalidArgument(fmt::format("{} runs more than a million instructions", name));
  }

  const Module& m_;
  const Machine& machine_;
  IdMap& values_;
  IdMap& memory_;            // variables by id, then the slots of pointer arguments
  std::uint32_t next_slot_;  // past the module's ids
  int depth_ = 0;
};

}  // namespace

SpirvProgram::SpirvProgram(std::unique_ptr<Module> module) : module_(std::move(module)) {}
SpirvProgram::SpirvProgram(SpirvProgram&&) noexcept = default;
SpirvProgram& SpirvProgram::operator=(SpirvProgram&&) noexcept = default;
SpirvProgram::~SpirvProgram() = default;

Expected<SpirvProgram> SpirvProgram::Parse(std::span<const std::uint32_t> words) {
  auto module = std::make_unique<Module>();
  module->words.assign(words.begin(), words.end());
  DB_RETURN_IF_ERROR(module->Parse());
  return SpirvProgram(std::move(module));
}

bool SpirvProgram::RowMajorMatrices() const { return module_->row_major; }

Expected<std::uint32_t> SpirvProgram::Function(std::string_view name) const {
  const std::string prefix = std::string(name) + "(";
  for (const auto& [id, info] : module_->functions) {
    const auto found = module_->names.find(id);
    if (found != module_->names.end() && (found->second == name || found->second.starts_with(prefix))) return id;
  }
  return NotFound(fmt::format("the program has no function named {}", name));
}

Expected<Value> SpirvProgram::Evaluate(std::uint32_t function, std::span<const Value> arguments,
                                       const Machine& machine) const {
  Evaluator evaluator(*module_, machine);
  const auto found = module_->functions.find(function);
  if (found == module_->functions.end()) return NotFound(fmt::format("the program has no function %{}", function));
  std::vector<Value> values;
  for (std::size_t k = 0; k < arguments.size(); ++k) values.push_back(evaluator.Argument(function, k, arguments[k]));
  return evaluator.Call(function, std::move(values));
}

}  // namespace depthbench::bound
