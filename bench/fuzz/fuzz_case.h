// Fuzz cases: single inputs given explicitly rather than drawn from a seed.
//
// A FuzzPoint is a point of the fuzz domain in unit coordinates (every
// choice the sampler makes, sampler.h); the libFuzzer target decodes its
// bytes into one, the campaign mutates them, the worst-case search moves
// them. A FuzzCase is what a point denotes: one frame and one pixel sample,
// the exact inputs a reproducer file records and `depthbench run --repro`
// replays.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/base/json_reader.h"
#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

// The hull of the extremes catalogue (issue 7): near planes down to 1e-7,
// far/near up to 1e9, fields of view from 0.01 to 179.9 degrees, aspect
// 1e-3 to 1e3, cameras up to 1e7 units from the origin.
Domain FuzzDomain();

struct FuzzPoint {
  FrameUnits frame;
  SampleUnits sample;
};

// Bytes <-> point: each unit is 4 little-endian bytes read as
// bits / (2^32 - 1), so all-zero and all-one words reach both ends of every
// range exactly; missing bytes read as zero.
inline constexpr int kFuzzUnits = 18;  // the frame's 13, then the sample's 5
inline constexpr std::size_t kFuzzPointBytes = kFuzzUnits * 4;
FuzzPoint DecodePoint(std::span<const std::uint8_t> bytes);
std::vector<std::uint8_t> EncodePoint(const FuzzPoint& point);
double& UnitOf(FuzzPoint& point, int k);  // k in [0, kFuzzUnits)

struct FuzzCase {
  Frame frame;
  PixelSample sample;
};
FuzzCase CaseAt(const Domain& domain, const FuzzPoint& point);

// Explicit frames and samples: frame f holds samples [f * kSamplesPerFrame,
// (f + 1) * kSamplesPerFrame).
class CaseSource : public SampleSource {
 public:
  CaseSource(std::vector<Frame> frames, std::vector<PixelSample> samples);
  // One case, its sample repeated over the frame.
  explicit CaseSource(const FuzzCase& single);

  Frame FrameAt(std::uint64_t frame_index) const override;
  PixelSample SampleAt(std::uint64_t index, const Frame& frame) const override;
  std::uint64_t sample_count() const { return samples_.size(); }

 private:
  std::vector<Frame> frames_;
  std::vector<PixelSample> samples_;
};

// A batch being assembled from points: frame f is made from one point's
// frame units, its kSamplesPerFrame samples from the sample units of the
// points `sample_point(s)` gives.
class PointBatch {
 public:
  explicit PointBatch(const Domain& domain) : domain_(domain) {}
  void AddFrame(const FuzzPoint& base, const std::function<FuzzPoint(std::uint32_t sample)>& sample_point);
  CaseSource Source() const { return CaseSource(frames_, samples_); }
  std::uint32_t count() const { return static_cast<std::uint32_t>(samples_.size()); }
  const FuzzPoint& point(std::uint32_t i) const { return points_[i]; }
  FuzzCase CaseOf(std::uint32_t i) const { return {frames_[i / kSamplesPerFrame], samples_[i]}; }

 private:
  const Domain& domain_;
  std::vector<FuzzPoint> points_;
  std::vector<Frame> frames_;
  std::vector<PixelSample> samples_;
};

// Whether a cell can run on a frame (finite-far conventions and linear
// formats need a finite far plane).
bool CellRunsOn(const Cell& cell, const Frame& frame);

// Reproducer files: the case's exact inputs, the cells it concerns, and
// what was found.
inline constexpr JsonSchema kReproSchema{"depthbench.repro", 1, "a reproducer file of depthbench fuzz"};
struct ReproFile {
  FuzzCase fuzz_case;
  std::vector<Cell> cells;
  std::vector<std::string> backends;  // where it was found ("cpu", "vulkan")
  nlohmann::json finding;             // free-form: kind, errors, bound, signature
};
nlohmann::json ReproFileToJson(const ReproFile& file);
Expected<ReproFile> ReproFileFromJson(const nlohmann::json& json, const std::string& source);
Expected<ReproFile> ReadReproFile(const std::filesystem::path& path);
Status WriteReproFile(const std::filesystem::path& path, const ReproFile& file);

}  // namespace depthbench
