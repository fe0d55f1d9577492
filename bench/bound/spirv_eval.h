// Abstract evaluation of a compiled shader function: each float lane is a
// bound::Lane (an enclosure of the exact value and a bound on the float32
// error, rounding.h), integers and booleans are known values. It runs the
// very SPIR-V module the Vulkan backend runs, so a shader edit changes the
// bound, and a function from the user's file is bounded like a built-in one.
//
// It follows straight-line code through calls, local and private
// variables, composites and branches whose condition is known (the depth
// convention's bits). Whatever it cannot bound is named, never guessed: a
// loop, a branch or a select on a computed float, an instruction it does
// not know, a divisor that may be zero.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bench/base/status.h"
#include "bench/bound/rounding.h"

namespace depthbench::bound {

struct Value;

// A composite's parts, shared between copies until one is changed: the
// programs pass whole parameter blocks by value, and copying them lane by
// lane was most of the analysis's time.
class Parts {
 public:
  Parts() = default;
  explicit Parts(std::vector<Value> parts);
  // (Defined after Value: a vector's element must be complete to index it.)
  std::size_t size() const;
  bool empty() const { return size() == 0; }
  const Value& operator[](std::size_t k) const;
  const Value* begin() const;
  const Value* end() const;
  // The parts, this value's own (copied first when shared).
  std::vector<Value>& Mutable();

 private:
  std::shared_ptr<std::vector<Value>> parts_;
};

struct Value {
  enum class Kind : std::uint8_t { kUndefined, kFloat, kInteger, kComputedBool, kComposite, kPointer };
  Kind kind = Kind::kUndefined;
  Lane lane;                        // kFloat
  std::uint64_t integer = 0;        // kInteger (booleans are 0 and 1)
  Parts parts;                      // kComposite: members, components or columns
  std::uint32_t variable = 0;       // kPointer: the variable
  std::vector<std::uint32_t> path;  // kPointer: the indices into it
  // kComposite: a camera-to-world matrix, its upper 3x3 a rounded rotation
  // and its last column the camera's exact position (bound.cc FrameInputs).
  bool camera_to_world = false;

  static Value Float(const Lane& lane) {
    Value v;
    v.kind = Kind::kFloat;
    v.lane = lane;
    return v;
  }
  static Value Integer(std::uint64_t x) {
    Value v;
    v.kind = Kind::kInteger;
    v.integer = x;
    return v;
  }
  static Value Composite(std::vector<Value> parts) {
    Value v;
    v.kind = Kind::kComposite;
    v.parts = Parts(std::move(parts));
    return v;
  }
};

inline Parts::Parts(std::vector<Value> parts) : parts_(std::make_shared<std::vector<Value>>(std::move(parts))) {}
inline std::size_t Parts::size() const { return parts_ ? parts_->size() : 0; }
inline const Value& Parts::operator[](std::size_t k) const { return (*parts_)[k]; }
inline const Value* Parts::begin() const { return parts_ ? parts_->data() : nullptr; }
inline const Value* Parts::end() const { return parts_ ? parts_->data() + parts_->size() : nullptr; }
inline std::vector<Value>& Parts::Mutable() {
  if (!parts_) {
    parts_ = std::make_shared<std::vector<Value>>();
  } else if (parts_.use_count() > 1) {
    parts_ = std::make_shared<std::vector<Value>>(*parts_);
  }
  return *parts_;
}

class Module;

// A parsed SPIR-V module, ready to evaluate its functions.
class SpirvProgram {
 public:
  // InvalidArgument when the words are not a SPIR-V module.
  static Expected<SpirvProgram> Parse(std::span<const std::uint32_t> words);
  SpirvProgram(SpirvProgram&&) noexcept;
  SpirvProgram& operator=(SpirvProgram&&) noexcept;
  ~SpirvProgram();

  // The function whose debug name is `name` or starts with `name(` (glslang's
  // mangled names); NotFound otherwise.
  Expected<std::uint32_t> Function(std::string_view name) const;

  // Whether the module's buffer blocks hold matrices row-major: what
  // glslang's HLSL front end makes of HLSL's column_major default (its
  // matrices' rows are SPIR-V's columns). A parameter block read from such
  // a buffer holds each matrix transposed.
  bool RowMajorMatrices() const;

  // Evaluates `function` on `arguments` (values, not pointers: a parameter
  // the compiler passes by pointer gets a variable holding its argument).
  // The error says what could not be bounded, and where.
  Expected<Value> Evaluate(std::uint32_t function, std::span<const Value> arguments, const Machine& machine) const;

 private:
  explicit SpirvProgram(std::unique_ptr<Module> module);
  std::unique_ptr<Module> module_;
};

}  // namespace depthbench::bound
