#include "bench/report/report_model.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

namespace depthbench {

Figure Shown(double x) {
  if (!std::isfinite(x)) return std::nullopt;
  return std::stod(fmt::format("{:.4g}", x));
}

std::string CellColumns::Name() const { return fmt::format("{}/{}/{}", variant, convention, format); }

const char* NonFiniteKindName(NonFiniteKind kind) {
  switch (kind) {
    case NonFiniteKind::kNaN: return "NaN";
    case NonFiniteKind::kInf: return "Inf";
    case NonFiniteKind::kNaNAndInf: return "NaN and Inf";
  }
  return "?";
}

const char* CostKindName(CostKind kind) {
  switch (kind) {
    case CostKind::kMeasuredGpu: return "measured on a GPU";
    case CostKind::kMeasuredSoftware: return "measured on a software rasteriser";
    case CostKind::kStaticModel: return "static cost model";
  }
  return "?";
}

std::size_t HistorySection::worse() const {
  return static_cast<std::size_t>(
      std::count_if(changes.begin(), changes.end(), [](const Change& c) { return c.direction == Direction::kWorse; }));
}

const char* PointStateName(ModelPointRow::State state) {
  switch (state) {
    case ModelPointRow::State::kMeasured: return "measured";
    case ModelPointRow::State::kNotFinite: return "not finite";
    case ModelPointRow::State::kBelowResolution: return "below resolution";
  }
  return "?";
}

const char* DirectionName(HistorySection::Direction direction) {
  return direction == HistorySection::Direction::kWorse ? "worse" : "better";
}

}  // namespace depthbench
