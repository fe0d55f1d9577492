#include "bench/gate/gate.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "bench/pipeline/sampler.h"

namespace depthbench {

SamplePlan GatePlan() {
  SamplePlan plan;
  plan.seed = 1122;
  plan.samples = 200000;
  plan.samples_per_frame = kSamplesPerFrame;
  plan.domain.camera_distance = {0.0, 0.0};
  return plan;
}

int GateComparison::failures() const {
  return static_cast<int>(std::count_if(cells.begin(), cells.end(), [](const CellVerdict& c) { return c.failed(); }));
}

int GateComparison::improvements() const {
  return static_cast<int>(std::count_if(cells.begin(), cells.end(), [](const CellVerdict& c) { return c.improved(); }));
}

int GateComparison::compared() const {
  return static_cast<int>(
      std::count_if(cells.begin(), cells.end(), [](const CellVerdict& c) { return !c.appeared && !c.disappeared; }));
}

std::string GateComparison::Uncovered() const {
  // Named up to a handful each; the counts say how many.
  constexpr std::size_t kNamed = 5;
  std::vector<std::string> missing_cells, missing_bands;
  for (const CellVerdict& c : cells) {
    if (c.appeared) missing_cells.push_back(c.cell);
    for (const std::string& band : c.not_compared) missing_bands.push_back(c.cell + ": " + band);
  }
  const auto list = [&](const std::vector<std::string>& names, const char* what) {
    std::string out = fmt::format("{} {} not in the baseline (", names.size(), what);
    for (std::size_t k = 0; k < names.size() && k < kNamed; ++k) out += (k == 0 ? "" : ", ") + names[k];
    return out + (names.size() > kNamed ? ", ...)" : ")");
  };
  std::string out;
  if (!missing_cells.empty()) out = list(missing_cells, missing_cells.size() == 1 ? "cell" : "cells");
  if (!missing_bands.empty()) {
    out += (out.empty() ? "" : "; ") + list(missing_bands, missing_bands.size() == 1 ? "band" : "bands");
  }
  return out;
}

namespace {

// Compares one figure; `grew` and `shrank` collect the verdicts.
void CompareBits(const char* what, double before, double after, double tolerance, std::vector<std::string>& grew,
                 std::vector<std::string>& shrank) {
  // Bits lost can be infinite (an infinite error): two infinities are equal.
  if (before == after) return;
  const double change = after - before;
  if (std::isnan(change) || change > tolerance) {
    grew.push_back(fmt::format("{} {:.2f} -> {:.2f} bits", what, before, after));
  } else if (change < -tolerance) {
    shrank.push_back(fmt::format("{} {:.2f} -> {:.2f} bits", what, before, after));
  }
}

void CompareCount(const char* what, std::uint64_t before, std::uint64_t after, std::vector<std::string>& grew,
                  std::vector<std::string>& shrank) {
  if (before == 0 && after > 0) grew.push_back(fmt::format("{} appeared (0 -> {})", what, after));
  if (before > 0 && after == 0) shrank.push_back(fmt::format("{} gone ({} -> 0)", what, before));
}

}  // namespace

Expected<GateComparison> CompareWithBaseline(const Baseline& baseline, const Baseline& run,
                                             const GateTolerance& tolerance, const Catalogue& catalogue) {
  if (baseline.backend != run.backend) {
    return InvalidArgument(
        fmt::format("the baseline was made on the {} backend, not {}", baseline.backend, run.backend));
  }
  if (baseline.device.name != run.device.name) {
    return InvalidArgument(fmt::format("the baseline was made on device '{}'; this run is on '{}'",
                                       baseline.device.name, run.device.name));
  }
  if (!(baseline.plan == run.plan)) {
    return InvalidArgument(fmt::format(
        "the baseline was made with another sample plan (seed {}, {} samples, {} per frame, {}); this gate uses "
        "seed {}, {} samples, {} per frame, {}",
        baseline.plan.seed, baseline.plan.samples, baseline.plan.samples_per_frame, baseline.plan.domain.Describe(),
        run.plan.seed, run.plan.samples, run.plan.samples_per_frame, run.plan.domain.Describe()));
  }
  GateComparison comparison;
  comparison.backend = run.backend;
  if (baseline.device.driver != run.device.driver) {
    comparison.notes.push_back(fmt::format("driver changed: '{}' -> '{}'", baseline.device.driver, run.device.driver));
  }
  if (baseline.device.compiler != run.device.compiler) {
    comparison.notes.push_back(
        fmt::format("compiler changed: '{}' -> '{}'", baseline.device.compiler, run.device.compiler));
  }

  // Every cell of either side, in catalog order.
  std::set<Cell> cells;
  for (const auto* side : {&baseline.cells, &run.cells}) {
    for (const auto& [name, figures] : *side) {
      Expected<Cell> cell = catalogue.ParseCell(name);
      if (!cell.ok()) return cell.status();
      cells.insert(*cell);
    }
  }
  for (const Cell& cell : cells) {
    const std::string name = cell.Name();
    CellVerdict verdict;
    verdict.cell = name;
    auto before = baseline.cells.find(name);
    auto after = run.cells.find(name);
    if (after == run.cells.end()) {
      verdict.disappeared = true;
    } else if (before == baseline.cells.end()) {
      verdict.appeared = true;
    } else {
      for (const auto& [band, f] : after->second) {
        (void)f;
        if (!before->second.contains(band)) verdict.not_compared.push_back(band);
      }
      for (const auto& [band, b] : before->second) {
        BandChange worse{band, b, {}, {}}, better{band, b, {}, {}};
        auto a = after->second.find(band);
        if (a == after->second.end()) {
          worse.reasons.push_back("band disappeared");
        } else {
          worse.after = better.after = a->second;
          const BandFigures& f = a->second;
          if (b.judged == 0 || f.judged == 0) {
            // Bits lost of no finite output read 0: compare nothing but
            // whether there is output to measure.
            if (b.judged > 0) {
              worse.reasons.push_back(
                  fmt::format("no finite output ({} NaN, {} Inf; was {} judged, total p99.9 {:.2f} bits)", f.nan, f.inf,
                              b.judged, b.total_p999));
            } else if (f.judged > 0) {
              better.reasons.push_back(
                  fmt::format("finite outputs again ({} judged, total p99.9 {:.2f} bits; was "
                              "none: {} NaN, {} Inf)",
                              f.judged, f.total_p999, b.nan, b.inf));
            }
          } else {
            // A p99.9 needs enough samples to mean something; where it has
            // them, it may move by its sampling interval (a driver update
            // that shifts a few samples near the top) without failing.
            if (b.judged >= MinimumSamples(Level::kP999) && f.judged >= MinimumSamples(Level::kP999)) {
              const double p999_tolerance = std::max(tolerance.p999_bits, b.p999_interval_bits);
              CompareBits("total p99.9", b.total_p999, f.total_p999, p999_tolerance, worse.reasons, better.reasons);
              CompareBits("arith p99.9", b.arith_p999, f.arith_p999, p999_tolerance, worse.reasons, better.reasons);
            }
            CompareBits("total max", b.total_max, f.total_max, tolerance.max_bits, worse.reasons, better.reasons);
            CompareBits("arith max", b.arith_max, f.arith_max, tolerance.max_bits, worse.reasons, better.reasons);
          }
          CompareCount("NaN", b.nan, f.nan, worse.reasons, better.reasons);
          CompareCount("Inf", b.inf, f.inf, worse.reasons, better.reasons);
        }
        if (!worse.reasons.empty()) {
          verdict.worse.push_back(worse);
        } else if (!better.reasons.empty()) {
          verdict.better.push_back(better);
        }
      }
    }
    comparison.cells.push_back(std::move(verdict));
  }
  return comparison;
}

}  // namespace depthbench
