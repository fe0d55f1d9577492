// StubBackend: a backend for the sweep's tests that can be told to fail,
// as Amber's executor tests drive a stub engine. It gives the CPU
// backend's positions, so a run without a fault is a real run, and plants
// one fault where a test asks: at Prepare, at a Run, in the positions a
// Run reads back (too few of them), or in rendering depths for the raster
// form.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/backends/cpu/cpu_backend.h"

namespace depthbench {

class StubBackend final : public Backend {
 public:
  enum class Fault { kNone, kPrepare, kRun, kReadBack, kRenderDepths };

  struct Options {
    Fault fault = Fault::kNone;
    // The Run call (counted from 0) at which kRun or kReadBack strikes; the
    // calls before it succeed.
    std::uint64_t fail_at_run = 0;
    // Whether the sweep may call Run from several threads at once (it then
    // runs each depth slot's cells apart).
    bool concurrent = true;
  };

  explicit StubBackend(Options options) : options_(options), cpu_(MakeCpuBackend()) {}

  std::string name() const override { return "stub"; }
  const DeviceInfo& device() const override { return cpu_->device(); }
  ProgramInfo program() const override { return cpu_->program(); }
  bool concurrent() const override { return options_.concurrent; }
  std::uint64_t runs() const { return runs_; }

  Status Prepare(std::span<const CellPlan> cells, PassKind pass) override {
    if (options_.fault == Fault::kPrepare) return Unavailable("the stub was told to fail in Prepare");
    return cpu_->Prepare(cells, pass);
  }

  bool renders_depths() const override { return options_.fault == Fault::kRenderDepths; }
  Expected<RenderedDepths> RenderDepths(const ShaderInputs&) override {
    return Internal("the stub was told to fail in RenderDepths");
  }

  Expected<std::span<const float>> Run(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                       std::vector<float>& scratch) override {
    const std::uint64_t call = runs_++;
    const bool strikes = call >= options_.fail_at_run;
    if (options_.fault == Fault::kRun && strikes) return Internal("the stub was told to fail in Run");
    auto out = cpu_->Run(batch, which, scratch);
    if (!out.ok() || options_.fault != Fault::kReadBack || !strikes) return out;
    // One value short of the positions asked for, as a truncated read-back.
    return out->first(which.size() * 3 * std::size_t{batch.count} - 1);
  }

 private:
  Options options_;
  std::unique_ptr<Backend> cpu_;
  std::atomic<std::uint64_t> runs_{0};
};

}  // namespace depthbench
