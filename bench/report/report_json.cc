#include "bench/report/report_json.h"

#include <string>

#include "bench/results/results.h"  // DeviceToJson

namespace depthbench {
namespace {

using json = nlohmann::json;

json Value(const Figure& figure) { return figure ? json(*figure) : json(nullptr); }

// A row about a cell: its columns, then `fields`; no backend column in rows
// that compare backends.
json CellRow(const CellColumns& cell, json fields) {
  fields["variant"] = cell.variant;
  fields["convention"] = cell.convention;
  fields["format"] = cell.format;
  if (!cell.backend.empty()) fields["backend"] = cell.backend;
  return fields;
}

template <class Row, class Write>
json Rows(const std::vector<Row>& rows, Write write) {
  json out = json::array();
  for (const Row& row : rows) out.push_back(write(row));
  return out;
}

json Budget(const BudgetRatio& b) {
  switch (b.kind) {
    case BudgetRatio::Kind::kNone: return nullptr;
    case BudgetRatio::Kind::kAlways: return "always";
    case BudgetRatio::Kind::kNever: return "never";
    case BudgetRatio::Kind::kRatio: return Value(b.ratio);
  }
  return nullptr;
}

json Environment(const ReportEnvironment& e) {
  json backends = json::array(), stages = json::array();
  for (const auto& [name, d] : e.backends) {
    backends.push_back({{"name", name}, {"device", DeviceToJson(d)}});
  }
  for (const auto& [stage, seconds] : e.stages) stages.push_back({{"stage", stage}, {"seconds", Value(seconds)}});
  return {{"version", e.version},
          {"commit", e.commit},
          {"host", e.host},
          {"started_at", e.started_at},
          {"seconds", Value(e.seconds)},
          {"stages", stages},
          {"backends", backends},
          {"quick", e.quick},
          {"fit_sweeps",
           {{"seed", e.fit_sweeps.seed},
            {"samples_per_ratio", e.fit_sweeps.samples_per_ratio},
            {"ratios", e.fit_sweeps.ratios},
            {"held_out", e.fit_sweeps.held_out},
            {"domain", e.fit_sweeps.domain}}},
          {"default_sweep",
           {{"seed", e.default_sweep.seed},
            {"samples", e.default_sweep.samples},
            {"reconstructions", e.default_sweep.reconstructions},
            {"domain", e.default_sweep.domain}}},
          {"speed_files", e.speed_files}};
}

json Headline(const HeadlineRow& r) {
  json predicted = json::object();
  for (const auto& [name, bits] : r.predicted_bits) predicted[name] = Value(bits);
  json row = CellRow(r.cell, {{"cell", r.cell.Name()},
                              {"infinite_far", r.infinite_far},
                              {"model", r.model},
                              {"points", r.points},
                              {"slope", Value(r.slope)},
                              {"slope_low", Value(r.slope_low)},
                              {"slope_high", Value(r.slope_high)},
                              {"predicted_bits", predicted},
                              {"ratio_for_1e-3", Budget(r.ratio_for_1e3)},
                              {"ratio_for_1e-6", Budget(r.ratio_for_1e6)},
                              {"holdout_max_miss", Value(r.holdout_max_miss)}});
  if (r.measured) {
    row["p999_bits"] = Value(r.measured->p999_bits);
    row["max_bits"] = Value(r.measured->max_bits);
    row["nan"] = r.measured->nan;
    row["inf"] = r.measured->inf;
  }
  return row;
}

json ModelPoint(const ModelPointRow& r) {
  return CellRow(r.cell, {{"level", r.level},
                          {"ratio", r.ratio},
                          {"log10_ratio", Value(r.log10_ratio)},
                          {"depth", Value(r.depth)},
                          {"measured", Value(r.measured)},
                          {"state", PointStateName(r.state)},
                          {"model", Value(r.model)},
                          {"low", Value(r.low)},
                          {"high", Value(r.high)},
                          {"held_out", r.held_out}});
}

json Differences(const BackendDifferences& d) {
  return {
      {"backends", d.backends},
      {"compared", d.compared},
      {"notable", d.notable},
      {"largest_bits", Value(d.largest_bits)},
      {"threshold_bits", d.threshold_bits},
      {"rows", Rows(d.rows, [&](const BackendDifferenceRow& r) {
         json row = CellRow(r.cell, {{"ratio", r.ratio}, {"metric", r.metric}, {"difference", Value(r.difference)}});
         row[d.backends.at(0)] = Value(r.first);
         row[d.backends.at(1)] = Value(r.second);
         return row;
       })}};
}

json Speed(const SpeedSection& s) {
  json out = {{"sources", Rows(s.sources,
                               [](const FrontSource& f) {
                                 return json{{"source", f.source},         {"kind", CostKindName(f.kind)},
                                             {"device", f.device},         {"cost_unit", f.cost_unit},
                                             {"cost_title", f.cost_title}, {"accuracy", f.accuracy}};
                               })},
              {"rows", Rows(s.rows, [](const FrontRow& r) {
                 return CellRow(r.cell, {{"source", r.source},
                                         {"ratio", r.ratio},
                                         {"cost", Value(r.cost)},
                                         {"spread", Value(r.spread)},
                                         {"bits", Value(r.bits)},
                                         {"bits_low", Value(r.bits_low)},
                                         {"bits_high", Value(r.bits_high)},
                                         {"nonfinite", r.nonfinite},
                                         {"on_front", r.on_front}});
               })}};
  if (s.error) out["error"] = *s.error;
  return out;
}

json History(const std::optional<HistorySection>& h) {
  if (!h) return nullptr;
  return {{"database", h->database},
          {"run", h->run},
          {"runs_recorded", h->runs_recorded},
          {"previous",
           Rows(h->previous,
                [](const HistorySection::Previous& p) {
                  return json{{"backend", p.backend}, {"run", p.run}, {"made_at", p.made_at}, {"commit", p.commit}};
                })},
          {"tolerance", {{"p999_bits", h->tolerance_p999_bits}, {"max_bits", h->tolerance_max_bits}}},
          {"notes", h->notes},
          {"changes", Rows(h->changes,
                           [](const HistorySection::Change& c) {
                             return json{{"direction", DirectionName(c.direction)},
                                         {"backend", c.backend},
                                         {"cell", c.cell},
                                         {"band", c.band},
                                         {"reasons", c.reasons},
                                         {"before_p999_bits", Value(c.before_p999_bits)},
                                         {"after_p999_bits", Value(c.after_p999_bits)}};
                           })},
          {"trend", Rows(h->trend, [](const HistorySection::TrendPoint& p) {
             return json{{"run", p.run},
                         {"made_at", p.made_at},
                         {"commit", p.commit},
                         {"backend", p.backend},
                         {"cell", p.cell},
                         {"p999_bits", Value(p.p999_bits)},
                         {"max_bits", Value(p.max_bits)},
                         {"nonfinite", p.nonfinite}};
           })}};
}

json SceneJson(const std::optional<SceneSection>& scene) {
  if (!scene) return nullptr;
  return {{"name", scene->name},
          {"requirement", scene->requirement},
          {"backend", scene->backend},
          {"cost_unit", scene->cost_unit},
          {"unit", scene->unit},
          {"limit", scene->limit},
          {"at_depth", scene->at_depth ? json(*scene->at_depth) : json(nullptr)},
          {"proven", scene->proven},
          {"rows", Rows(scene->rows,
                        [](const SceneRow& r) {
                          return json{{"convention", r.convention},     {"format", r.format},
                                      {"variant", r.variant},           {"measured", Value(r.measured)},
                                      {"far_end", Value(r.far_end)},    {"meets", r.meets},
                                      {"proven", Value(r.proven)},
                                      {"times_limit", r.times_limit},   {"bytes_per_pixel", r.bytes_per_pixel},
                                      {"cost", Value(r.cost)},
                                      {"by_depth", Rows(r.by_depth, [](const SceneRow::DepthPoint& p) {
                                         return json{{"depth_min", p.depth_min},
                                                     {"depth_max", p.depth_max},
                                                     {"value", Value(p.value)}};
                                       })}};
                        })},
          {"what_ifs", scene->what_ifs},
          {"not_candidates", scene->not_candidates},
          {"capture", scene->capture ? json{{"image", scene->capture->image},
                                            {"cell", scene->capture->cell},
                                            {"backend", scene->capture->backend},
                                            {"source", scene->capture->source},
                                            {"pixels", scene->capture->pixels},
                                            {"median_bits", scene->capture->median_bits},
                                            {"p999_bits", scene->capture->p999_bits},
                                            {"worst_bits", scene->capture->worst_bits}}
                                     : json(nullptr)}};
}

}  // namespace

nlohmann::json ReportToJson(const Report& report) {
  return WithSchema(kReportSchema,
                    {{"environment", Environment(report.environment)},
                     {"scene", SceneJson(report.scene)},
                     {"recommendations", Rows(report.recommendations,
                                              [](const RecommendationRow& r) {
                                                return json{{"convention", r.convention},
                                                            {"format", r.format},
                                                            {"backend", r.backend},
                                                            {"ratio", r.ratio},
                                                            {"variants", r.variants},
                                                            {"bits", Value(r.bits)},
                                                            {"bits_low", Value(r.bits_low)},
                                                            {"bits_high", Value(r.bits_high)},
                                                            {"proven_bits", Value(r.proven_bits)},
                                                            {"cost", Value(r.cost)},
                                                            {"cost_kind", CostKindName(r.cost_kind)},
                                                            {"cost_unit", r.cost_unit},
                                                            {"ratio_for_1e-3", Budget(r.ratio_for_1e3)},
                                                            {"ratio_for_1e-6", Budget(r.ratio_for_1e6)},
                                                            {"keeps_nothing", r.keeps_nothing},
                                                            {"bytes_per_pixel", r.bytes_per_pixel},
                                                            {"error_far_100m", Value(r.error_far_100m)},
                                                            {"error_far_10km", Value(r.error_far_10km)}};
                                              })},
                     {"headline", Rows(report.headline, Headline)},
                     {"precision_points", Rows(report.precision_points, ModelPoint)},
                     {"depth_points", Rows(report.depth_points, ModelPoint)},
                     {"split", Rows(report.split,
                                    [](const SplitRow& r) {
                                      return CellRow(r.cell, {{"ratio", r.ratio},
                                                              {"log10_ratio", Value(r.log10_ratio)},
                                                              {"total", Value(r.total)},
                                                              {"production", Value(r.production)},
                                                              {"storage", Value(r.storage)},
                                                              {"arith", Value(r.arith)}});
                                    })},
                     {"backend_differences", Differences(report.backend_differences)},
                     {"findings",
                      {{"nonfinite", Rows(report.nonfinite,
                                          [](const NonFiniteRow& r) {
                                            return CellRow(r.cell, {{"sweep", r.sweep},
                                                                    {"kind", NonFiniteKindName(r.kind)},
                                                                    {"nan", r.nan},
                                                                    {"inf", r.inf},
                                                                    {"judged", r.judged},
                                                                    {"first_index", r.first_index},
                                                                    {"command", r.command}});
                                          })},
                       {"groups", Rows(report.finding_groups,
                                       [](const FindingGroup& g) {
                                         return json{{"variant", g.variant},     {"kind", NonFiniteKindName(g.kind)},
                                                     {"rows", g.rows},           {"outputs", g.outputs},
                                                     {"encodings", g.encodings}, {"sweeps", g.sweeps},
                                                     {"backends", g.backends},   {"command", g.command}};
                                       })},
                       {"worst", Rows(report.worst,
                                      [](const WorstSampleRow& r) {
                                        return CellRow(r.cell, {{"bits", Value(r.bits)},
                                                                {"relative", Value(r.relative)},
                                                                {"index", r.index},
                                                                {"command", r.command}});
                                      })}}},
                     {"speed", Speed(report.speed)},
                     {"history", History(report.history)}});
}

}  // namespace depthbench
