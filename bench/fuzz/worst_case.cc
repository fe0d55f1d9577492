#include "bench/fuzz/worst_case.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "bench/fuzz/case_check.h"

namespace depthbench {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kTopUnit = 1.0 - 0x1.0p-53;

FuzzPoint UniformPoint(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  FuzzPoint p;
  for (int k = 0; k < kFuzzUnits; ++k) UnitOf(p, k) = unit(rng);
  return p;
}

// Moves units [first, last) of p: each with probability 1/2, by a step of
// random sign and a scale drawn log-uniformly between 2^-2 and 2^-40.
FuzzPoint Step(FuzzPoint p, int first, int last, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  bool moved = false;
  while (!moved) {
    for (int k = first; k < last; ++k) {
      if (unit(rng) < 0.5) continue;
      const double step = std::exp2(-2.0 - 38.0 * unit(rng)) * (unit(rng) < 0.5 ? -1.0 : 1.0);
      UnitOf(p, k) = std::clamp(UnitOf(p, k) + step, 0.0, kTopUnit);
      moved = true;
    }
  }
  return p;
}

}  // namespace

Expected<SearchResult> SearchWorstCase(const SearchOptions& options, Backend& backend) {
  DB_RETURN_IF_ERROR(options.domain.Validate());
  DB_ASSIGN_OR_RETURN(CaseChecker checker, CaseChecker::Make({options.cell}, {&backend}));
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::pair<double, FuzzPoint>> elite;  // (total error, point), best first
  SearchResult result;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  const std::uint32_t frames = std::max<std::uint32_t>(1, options.frames_per_generation);
  constexpr int kFrameUnits = 13;

  auto budget_left = [&] {
    return elapsed() < options.seconds && (options.evaluations == 0 || result.evaluations < options.evaluations);
  };
  while (budget_left()) {
    PointBatch batch(options.domain);
    for (std::uint32_t f = 0; f < frames; ++f) {
      // A frame: a fresh random one (a quarter of them, and all until the
      // elite fills), or a step from an elite frame.
      FuzzPoint base;
      const bool explore = elite.size() < options.elite || unit(rng) < 0.25;
      if (explore) {
        base = UniformPoint(rng);
      } else {
        // Better inputs are picked more often: rank-weighted.
        const auto pick = static_cast<std::size_t>(elite.size() * unit(rng) * unit(rng));
        base = elite[pick].second;
        if (unit(rng) < 0.7) base = Step(base, 0, kFrameUnits, rng);
      }
      batch.AddFrame(base, [&](std::uint32_t s) {
        FuzzPoint p = base;
        if (explore || s >= kSamplesPerFrame / 2) {
          if (s > 0) p.sample = UniformPoint(rng).sample;
        } else if (s > 0) {
          p = Step(p, kFrameUnits, kFuzzUnits, rng);
        }
        return p;
      });
    }
    const CaseSource source = batch.Source();
    const std::uint32_t count = batch.count();
    DB_RETURN_IF_ERROR(checker.Evaluate(source, 0, count));
    result.evaluations += count;
    for (std::uint32_t i = 0; i < count; ++i) {
      const Judgement& j = checker.At(0, 0, i);
      if (!j.judged || !std::isfinite(j.total)) continue;
      // Only a better input than the elite's worst enters it.
      if (elite.size() >= options.elite && j.total <= elite.back().first) continue;
      if (j.total > result.worst) {
        result.worst = j.total;
        result.point = batch.point(i);
        result.worst_case = batch.CaseOf(i);
      }
      elite.emplace_back(j.total, batch.point(i));
      std::sort(elite.begin(), elite.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
      if (elite.size() > options.elite) elite.pop_back();
    }
    if (options.progress) options.progress(std::min(1.0, elapsed() / options.seconds), result.worst);
  }
  result.seconds = elapsed();
  return result;
}

}  // namespace depthbench
