#include "bench/pipeline/stats.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>
#include <type_traits>

#include <sys/mman.h>

#include <fmt/format.h>

namespace depthbench {

const char* MetricName(Metric m) {
  switch (m) {
    case Metric::kTotal: return "total";
    case Metric::kArith: return "arith";
    case Metric::kStorage: return "storage";
    case Metric::kProduction: return "production";
    case Metric::kAbsolute: return "absolute";
  }
  return "?";
}

std::string RatioBandName(int band) {
  if (band == kInfiniteRatioBand) return "inf";
  if (band == kInfiniteRatioBand - 1) return "1e9+";
  return fmt::format("1e{}", band);
}
std::string DepthBandName(int band) {
  return band == kDepthBands - 1 ? fmt::format("1e{}+", band) : fmt::format("1e{}", band);
}
std::string DistanceBandName(int band) {
  if (band == 0) return "<1";
  return band == kDistanceBands - 1 ? fmt::format("1e{}+", 2 * band - 2) : fmt::format("1e{}", 2 * band - 2);
}
std::string CoverageBandName(int band) {
  static const char* const kNames[kCoverageBands] = {"stored 0",        "stored 1",      "stored after 0",
                                                     "stored before 1", "near doubling", "far doubling",
                                                     "corner pixel",    "edge pixel"};
  return band >= 0 && band < kCoverageBands ? kNames[band] : "?";
}
double RatioBandLow(int band) { return band == kInfiniteRatioBand ? INFINITY : std::pow(10.0, band); }
double DepthBandLow(int band) { return std::pow(10.0, band); }
double DistanceBandLow(int band) { return band == 0 ? 0.0 : std::pow(10.0, 2 * band - 2); }

std::uint64_t MetricStats::Count() const {
  std::uint64_t n = 0;
  for (const auto& [slot, count] : bins) n += count;
  return n;
}

void MetricStats::MergeBins(const std::map<int, std::uint64_t>& other) {
  // Both in slot order: one pass, inserting before the cursor.
  auto at = bins.begin();
  for (const auto& [slot, count] : other) {
    while (at != bins.end() && at->first < slot) ++at;
    if (at != bins.end() && at->first == slot) {
      at->second += count;
    } else {
      at = bins.emplace_hint(at, slot, count);
    }
  }
}

void MetricStats::MergeMax(const MetricStats& other) {
  if (other.max_square > max_square || (other.max_square == max_square && other.worst_index < worst_index)) {
    max_square = other.max_square;
    worst_index = other.worst_index;
  }
}

void MetricStats::Merge(const MetricStats& other) {
  MergeBins(other.bins);
  MergeMax(other);
}

void MetricStats::Merge(MetricStats&& other) {
  if (bins.empty()) {
    bins = std::move(other.bins);
  } else {
    MergeBins(other.bins);
  }
  MergeMax(other);
}

double MetricStats::Quantile(double q, int lowest_octave) const {
  const std::uint64_t n = Count();
  if (n == 0) return 0.0;
  // Rank of the q-quantile among n sorted values (1-based, nearest rank
  // with interpolation inside the bin that holds it).
  const double rank = std::clamp(q, 0.0, 1.0) * static_cast<double>(n);
  std::uint64_t below = 0;
  for (const auto& [slot, count] : bins) {
    if (static_cast<double>(below + count) >= rank && count > 0) {
      // Below the kept range: the edge is an upper bound, and so is the max.
      if (slot == 0) return std::min(std::ldexp(1.0, lowest_octave), max());
      if (slot == kBinsKept + 1) return max();
      double fraction = std::clamp((rank - static_cast<double>(below)) / static_cast<double>(count), 0.0, 1.0);
      double log2_value = lowest_octave + (slot - 1 + fraction) / kBinsPerOctave;
      return std::min(std::exp2(log2_value), max());
    }
    below += count;
  }
  return max();
}

bool MetricStats::BelowRange(double q) const {
  const std::uint64_t n = Count();
  const auto underflow = bins.find(0);
  return n > 0 && underflow != bins.end() &&
         static_cast<double>(underflow->second) >= std::clamp(q, 0.0, 1.0) * static_cast<double>(n);
}

const char* LevelName(Level level) {
  switch (level) {
    case Level::kP50: return "p50";
    case Level::kP99: return "p99";
    case Level::kP999: return "p99.9";
    case Level::kMax: return "max";
  }
  return "?";
}

Expected<Level> ParseLevel(const std::string& name) {
  for (Level l : kAllLevels)
    if (name == LevelName(l)) return l;
  return InvalidArgument(fmt::format("unknown level '{}'; allowed: p50, p99, p99.9, max", name));
}

double LevelQuantile(Level level) {
  switch (level) {
    case Level::kP50: return 0.5;
    case Level::kP99: return 0.99;
    case Level::kP999: return 0.999;
    case Level::kMax: return 1.0;
  }
  return 1.0;
}

std::uint64_t MinimumSamples(Level level) {
  switch (level) {
    case Level::kP50: return 20;
    case Level::kP99: return 400;
    case Level::kP999: return 4000;
    case Level::kMax: return 100;
  }
  return 0;
}

Interval MetricStats::LevelInterval(Level level, Metric metric) const {
  if (level == Level::kMax) return {max(), max()};
  const double n = static_cast<double>(Count());
  if (n == 0.0) return {};
  const double q = LevelQuantile(level);
  const double spread = 1.96 * std::sqrt(n * q * (1.0 - q));
  const int lowest = kLowestOctave[static_cast<int>(metric)];
  return {Quantile(std::max(0.0, n * q - spread) / n, lowest), Quantile(std::min(n, n * q + spread + 1.0) / n, lowest)};
}

double MetricStats::AtLevel(Level level, Metric metric) const {
  return level == Level::kMax ? max() : Quantile(LevelQuantile(level), kLowestOctave[static_cast<int>(metric)]);
}

void BandStats::MergeCounts(const BandStats& other) {
  finite += other.finite;
  nan += other.nan;
  inf += other.inf;
  stored_nonfinite += other.stored_nonfinite;
  degenerate += other.degenerate;
  outside += other.outside;
  undrawn += other.undrawn;
  first_nonfinite_index = std::min(first_nonfinite_index, other.first_nonfinite_index);
}

void BandStats::Merge(const BandStats& other) {
  MergeCounts(other);
  for (int m = 0; m < kMetricCount; ++m) metrics[m].Merge(other.metrics[m]);
}

void BandStats::Merge(BandStats&& other) {
  MergeCounts(other);
  for (int m = 0; m < kMetricCount; ++m) metrics[m].Merge(std::move(other.metrics[m]));
}

double BitsLost(double relative_error) {
  if (std::isnan(relative_error)) return kAllBitsLost;
  if (!(relative_error > 0.0)) return 0.0;
  return std::clamp(std::log2(relative_error) + 24.0, 0.0, kAllBitsLost);
}

Summary Summarize(const BandStats& band, Metric metric) {
  const MetricStats& m = band[metric];
  const int low = kLowestOctave[static_cast<int>(metric)];
  Summary s;
  s.p50 = m.Quantile(0.5, low);
  s.p99 = m.Quantile(0.99, low);
  s.p999 = m.Quantile(0.999, low);
  s.p999_below_range = m.Count() > 0 && m.BelowRange(0.999);
  s.p999_interval = m.LevelInterval(Level::kP999, metric);
  s.p999_supported = m.Count() >= MinimumSamples(Level::kP999);
  s.max = m.max();
  s.worst_index = m.worst_index;
  return s;
}

void CellStats::Merge(const CellStats& other) {
  for (const auto& [band, stats] : other.joint) joint[band].Merge(stats);
  for (const auto& [band, stats] : other.distance) distance[band].Merge(stats);
  for (const auto& [band, stats] : other.coverage) coverage[band].Merge(stats);
}

BandStats CellStats::AllCoverage() const {
  BandStats all;
  for (const auto& [band, stats] : coverage) all.Merge(stats);
  return all;
}

BandStats CellStats::Everything() const {
  BandStats all = All();
  all.Merge(AllCoverage());
  return all;
}

BandStats CellStats::All() const {
  BandStats all;
  for (const auto& [band, stats] : joint) all.Merge(stats);
  return all;
}

BandStats CellStats::ForRatio(int ratio_band) const {
  BandStats out;
  for (const auto& [band, stats] : joint)
    if (RatioOfJoint(band) == ratio_band) out.Merge(stats);
  return out;
}

BandStats CellStats::ForDepth(int depth_band) const {
  BandStats out;
  for (const auto& [band, stats] : joint)
    if (DepthOfJoint(band) == depth_band) out.Merge(stats);
  return out;
}

BandStats CellStats::ForDistance(int distance_band) const {
  auto it = distance.find(distance_band);
  return it == distance.end() ? BandStats{} : it->second;
}

static_assert(std::is_trivially_default_constructible_v<CellAccumulator::Slot>);

CellAccumulator::CellAccumulator() {
  // Fresh anonymous pages read as zeros and take memory only when written.
  void* pages = mmap(nullptr, (kSlots + 1) * sizeof(Slot), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (pages == MAP_FAILED) throw std::bad_alloc();
  slots_.reset(static_cast<Slot*>(pages));
}

void CellAccumulator::Unmap::operator()(Slot* slots) const { munmap(slots, (kSlots + 1) * sizeof(Slot)); }

BandStats CellStats::DistanceBandOf() const {
  BandStats band = All();
  for (int m = 0; m < kMetricCount; ++m) {
    if (m != static_cast<int>(Metric::kTotal) && m != static_cast<int>(Metric::kArith)) band.metrics[m] = {};
  }
  return band;
}

void CellAccumulator::FlushInto(CellStats& out) {
  constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();
  static const Slot kEmpty{};
  for (int s = 0; s < kSlots; ++s) {
    Slot& slot = slots_.get()[s];
    // A slot in use has counted something; reading an untouched one takes
    // no memory (its pages map the kernel's zero page).
    if (std::memcmp(&slot, &kEmpty, sizeof(Slot)) == 0) continue;
    BandStats add;
    for (std::uint32_t n : slot.bins[static_cast<int>(Metric::kTotal)]) add.finite += n;
    add.nan = slot.nan;
    add.inf = slot.inf;
    add.stored_nonfinite = slot.stored_nonfinite;
    add.degenerate = slot.degenerate;
    add.outside = slot.outside;
    add.undrawn = slot.undrawn;
    add.first_nonfinite_index = slot.nan + slot.inf > 0 ? slot.first_nonfinite_index : kNone;
    for (int m = 0; m < kMetricCount; ++m) {
      MetricStats& ms = add.metrics[m];
      for (int b = 0; b < kDenseBins; ++b)
        if (slot.bins[m][b] != 0) ms.bins.emplace_hint(ms.bins.end(), b, slot.bins[m][b]);
      ms.max_square = slot.max_square[m];
      ms.worst_index = slot.max_square[m] > 0.0 ? slot.worst_index[m] : kNone;
    }
    BandStats& to = s < kDistanceBands                 ? out.distance[s]
                    : s < kDistanceBands + kJointBands ? out.joint[s - kDistanceBands]
                                                       : out.coverage[s - kDistanceBands - kJointBands];
    to.Merge(std::move(add));
    std::memset(&slot, 0, sizeof(Slot));
  }
  std::memset(&slots_.get()[kDiscarded], 0, sizeof(Slot));  // (its 32-bit counts must not overflow)
  pending_ = 0;
}

}  // namespace depthbench
