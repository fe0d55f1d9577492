#include "bench/gate/gate_report.h"

#include <algorithm>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "bench/sweep/repro.h"

namespace depthbench {
namespace {

constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();

std::string Join(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

// The command that replays the sample behind a worse band.
// Whether the shader's own part of the error got worse in a band: then its
// worst sample shows the change, where the total's worst may be a sample
// that storage dominates alike before and after.
bool ShaderPartWorse(const BandChange& change) {
  return change.after.arith_max > change.before.arith_max || change.after.arith_p999 > change.before.arith_p999;
}

std::uint64_t ReplayIndex(const BandChange& change) {
  // (NaN and Inf each: one can appear while the other goes.)
  if (change.after.nan > change.before.nan || change.after.inf > change.before.inf) {
    return change.after.first_nonfinite_index;
  }
  if (ShaderPartWorse(change) && change.after.arith_worst_index.value_or(kNone) != kNone) {
    return *change.after.arith_worst_index;
  }
  return change.after.worst_index;
}

// What the replayed sample stands for, before and after: the band's
// maximum of the part it is the worst of.
std::string ReplayFigures(const BandChange& change) {
  if (change.after.nan > change.before.nan || change.after.inf > change.before.inf) {
    return fmt::format("the first NaN or Inf (NaN {} -> {}, Inf {} -> {})", change.before.nan, change.after.nan,
                       change.before.inf, change.after.inf);
  }
  if (ShaderPartWorse(change) && change.after.arith_worst_index.value_or(kNone) != kNone) {
    return fmt::format("the worst sample of the shader's part: its band maximum {:.1f} -> {:.1f} bits lost",
                       change.before.arith_max, change.after.arith_max);
  }
  return fmt::format("the worst sample of the total: its band maximum {:.1f} -> {:.1f} bits lost",
                     change.before.total_max, change.after.total_max);
}

std::string ReproFor(const GateRun& run, const std::string& cell_name, const BandChange& change) {
  const Cell cell = (run.catalogue != nullptr ? *run.catalogue : Catalogue::BuiltIn()).ParseCell(cell_name).value();
  const std::uint64_t index = ReplayIndex(change);
  if (index == kNone) return "";
  std::string command = ReproCommand(run.current.plan.seed, index, run.current.plan.domain, cell, run.current.backend);
  if (!run.shader_dir.empty()) command += " --shaders " + run.shader_dir;
  return command;
}

std::string XmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string DescribeWorse(const CellVerdict& v) {
  if (v.disappeared) return "the cell disappeared";
  std::vector<std::string> parts;
  for (const BandChange& c : v.worse) parts.push_back(c.band + ": " + Join(c.reasons, ", "));
  return Join(parts, "; ");
}

// The counts every verdict states.
struct GateCounts {
  int failures = 0, improvements = 0, cells = 0, compared = 0, not_compared = 0;
  std::vector<std::string> uncovered;  // per backend, what was not compared
  std::vector<std::string> backends;   // "vulkan on llvmpipe (...)"
};
GateCounts CountGate(const std::vector<GateRun>& runs) {
  GateCounts n;
  for (const GateRun& r : runs) {
    n.failures += r.comparison.failures();
    n.improvements += r.comparison.improvements();
    n.cells += static_cast<int>(r.comparison.cells.size());
    n.compared += r.comparison.compared();
    for (const CellVerdict& v : r.comparison.cells) n.not_compared += v.appeared;
    const std::string what = r.comparison.Uncovered();
    if (!what.empty()) n.uncovered.push_back(fmt::format("{} ({})", what, r.current.backend));
    n.backends.push_back(fmt::format("{} on {}", r.current.backend, r.current.device.name));
  }
  return n;
}

const char* VerdictWord(const GateCounts& n) { return n.failures == 0 ? "PASS" : "FAIL"; }
// "no cell got worse (...)" or "3 of 212 cells got worse (...)".
std::string VerdictDetail(const GateCounts& n) {
  return n.failures == 0
             ? fmt::format("no cell got worse ({} cells compared; {})", n.compared, Join(n.backends, ", "))
             : fmt::format("{} of {} cells got worse ({})", n.failures, n.cells, Join(n.backends, ", "));
}

std::string ToleranceLine(const GateTolerance& tolerance) {
  return fmt::format(
      "tolerance: {} bit at p99.9, or its sampling interval where wider, {} bit at the maximum; NaN or Inf appearing "
      "always counts",
      tolerance.p999_bits, tolerance.max_bits);
}

// A worse cell's bands, the one that changed most first.
std::vector<BandChange> WorstBandsFirst(const CellVerdict& v) {
  std::vector<BandChange> bands = v.worse;
  std::stable_sort(bands.begin(), bands.end(), [](const BandChange& a, const BandChange& b) {
    auto growth = [](const BandChange& c) {
      // No finite output is the largest loss there is.
      if (c.after.judged == 0 && c.before.judged > 0) return std::numeric_limits<double>::infinity();
      return std::max(c.after.total_p999 - c.before.total_p999, c.after.arith_p999 - c.before.arith_p999);
    };
    return growth(a) > growth(b);
  });
  return bands;
}

}  // namespace

void PrintGateVerdict(const std::vector<GateRun>& runs, const GateTolerance& tolerance, std::ostream& out) {
  const GateCounts counts = CountGate(runs);
  const int failures = counts.failures, improvements = counts.improvements, cells = counts.cells,
            not_compared = counts.not_compared;
  out << VerdictWord(counts) << ": " << VerdictDetail(counts) << "\n";
  // Only with --allow-uncovered: without it, a gate that does not cover its run gives no verdict.
  for (const std::string& what : counts.uncovered) out << "NOT COMPARED: " << what << "\n";
  if (improvements > 0) out << fmt::format("{} cells improved\n", improvements);
  out << "(" << ToleranceLine(tolerance) << ")\n";
  for (const GateRun& r : runs) {
    for (const std::string& note : r.comparison.notes) out << "note (" << r.current.backend << "): " << note << "\n";
  }
  for (const GateRun& r : runs) {
    for (const CellVerdict& v : r.comparison.cells) {
      if (!v.failed()) continue;
      out << fmt::format("\nworse: {} on {}\n", v.cell, r.current.backend);
      if (v.disappeared) {
        out << "  the cell is in the baseline but did not run\n";
        continue;
      }
      // The bands that changed most first; a handful tells the story.
      const std::vector<BandChange> bands = WorstBandsFirst(v);
      constexpr std::size_t kShown = 4;
      for (std::size_t k = 0; k < bands.size() && k < kShown; ++k) {
        out << fmt::format("  {}: {}\n", bands[k].band, Join(bands[k].reasons, ", "));
      }
      if (bands.size() > kShown)
        out << fmt::format("  ... and {} more bands (--json has them all)\n", bands.size() - kShown);
      // One reproducer, for the band that changed most.
      const std::string repro = ReproFor(r, v.cell, v.worse.front());
      if (!repro.empty()) {
        out << fmt::format("  the sample below, in band {}: {}\n  reproduce: {}\n", v.worse.front().band,
                           ReplayFigures(v.worse.front()), repro);
      }
    }
  }
  for (const GateRun& r : runs) {
    for (const CellVerdict& v : r.comparison.cells) {
      if (!v.improved()) continue;
      out << fmt::format("better: {} on {}: {}: {}\n", v.cell, r.current.backend, v.better.front().band,
                         Join(v.better.front().reasons, ", "));
    }
    for (const CellVerdict& v : r.comparison.cells) {
      if (v.appeared) {
        out << fmt::format("not compared: {} on {}: the cell is not in the baseline\n", v.cell, r.current.backend);
      } else if (!v.not_compared.empty()) {
        out << fmt::format("not compared: {} on {}: bands {} are not in the baseline\n", v.cell, r.current.backend,
                           Join(v.not_compared, ", "));
      }
    }
  }
  // The last line sums up; improvements beyond the tolerance are accepted
  // by rewriting the baselines.
  int unchanged = 0;
  std::vector<std::string> improved_baselines;
  for (const GateRun& r : runs) {
    for (const CellVerdict& v : r.comparison.cells) unchanged += !v.failed() && !v.improved() && !v.appeared;
    if (r.comparison.improvements() > 0 && !r.baseline_path.empty()) {
      improved_baselines.push_back("--baseline " + r.baseline_path);
    }
  }
  out << fmt::format("\nsummary: {} cells worse, {} better, {} unchanged, {} not compared, of {}\n", failures,
                     improvements, unchanged, not_compared, cells);
  if (failures == 0 && !improved_baselines.empty()) {
    out << fmt::format("to keep the improvements: depthbench gate --update {}{}\n", Join(improved_baselines, " "),
                       runs.front().shader_dir.empty() ? "" : " --shaders " + runs.front().shader_dir);
  }
}

TextTable GateCellsTable(const std::vector<GateRun>& runs, std::size_t max_rows) {
  TextTable table({{"worse cell", TextTable::Align::kLeft},
                   {"backend", TextTable::Align::kLeft},
                   {"band that changed most", TextTable::Align::kLeft},
                   {"change", TextTable::Align::kLeft},
                   {"replayed sample", TextTable::Align::kLeft},
                   {"replay", TextTable::Align::kLeft}});
  std::size_t rows = 0;
  for (const GateRun& r : runs) {
    for (const CellVerdict& v : r.comparison.cells) {
      if (!v.failed() || rows++ == max_rows) continue;
      if (v.disappeared) {
        table.AddRow({v.cell, r.current.backend, "-", "in the baseline, did not run", "-", "-"});
        continue;
      }
      const BandChange worst = WorstBandsFirst(v).front();
      const std::string repro = ReproFor(r, v.cell, worst);
      table.AddRow({v.cell, r.current.backend, worst.band, Join(worst.reasons, ", "), ReplayFigures(worst),
                    repro.empty() ? "-" : "`" + repro + "`"});
    }
  }
  return table;
}

std::string GateSummaryMarkdown(const std::vector<GateRun>& runs, const GateTolerance& tolerance) {
  const GateCounts counts = CountGate(runs);
  std::string out =
      fmt::format("### depthbench gate: {}\n\n{}.\n\n", VerdictWord(counts), VerdictDetail(counts));
  for (const std::string& what : counts.uncovered) out += fmt::format("Not compared: {}.\n\n", what);
  // The worse cells, each by the band that changed most, with the command
  // that replays its sample; a page of them tells the story.
  constexpr std::size_t kRows = 20;
  const std::size_t worse = static_cast<std::size_t>(counts.failures);
  if (worse > 0) {
    std::ostringstream table;
    GateCellsTable(runs, kRows).Print(TextOutput(table, TableStyle{TableFormat::kMarkdown, 0}));
    out += table.str() + "\n";
  }
  if (worse > kRows) {
    out += fmt::format("... and {} more worse cells (the gate's --json has them all).\n\n", worse - kRows);
  }
  if (counts.improvements > 0) out += fmt::format("{} cells improved.\n\n", counts.improvements);
  out += fmt::format("<sub>{}.</sub>\n", ToleranceLine(tolerance));
  return out;
}

std::string GateJUnit(const std::vector<GateRun>& runs) {
  int tests = 0, failures = 0, skipped = 0;
  const auto skipped_in = [](const GateComparison& c) {
    return static_cast<int>(
        std::count_if(c.cells.begin(), c.cells.end(), [](const CellVerdict& v) { return v.appeared; }));
  };
  for (const GateRun& r : runs) {
    tests += static_cast<int>(r.comparison.cells.size());
    failures += r.comparison.failures();
    skipped += skipped_in(r.comparison);
  }
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += fmt::format("<testsuites name=\"depthbench gate\" tests=\"{}\" failures=\"{}\" skipped=\"{}\">\n", tests,
                     failures, skipped);
  for (const GateRun& r : runs) {
    xml += fmt::format("  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" skipped=\"{}\">\n",
                       XmlEscape(r.current.backend), r.comparison.cells.size(), r.comparison.failures(),
                       skipped_in(r.comparison));
    for (const CellVerdict& v : r.comparison.cells) {
      xml += fmt::format("    <testcase classname=\"depthbench.gate.{}\" name=\"{}\"", XmlEscape(r.current.backend),
                         XmlEscape(v.cell));
      if (v.appeared) {  // not compared: not a pass
        xml += ">\n      <skipped message=\"not compared: the cell is not in the baseline\"/>\n    </testcase>\n";
        continue;
      }
      if (!v.failed()) {
        xml += v.not_compared.empty()
                   ? "/>\n"
                   : fmt::format(
                         ">\n      <system-out>not compared: bands {} are not in the baseline</system-out>\n"
                         "    </testcase>\n",
                         XmlEscape(Join(v.not_compared, ", ")));
        continue;
      }
      const std::string repro = v.disappeared ? "" : ReproFor(r, v.cell, v.worse.front());
      xml += fmt::format(">\n      <failure message=\"{}\">{}</failure>\n    </testcase>\n",
                         XmlEscape(DescribeWorse(v)), XmlEscape(repro.empty() ? "" : "reproduce: " + repro));
    }
    xml += "  </testsuite>\n";
  }
  xml += "</testsuites>\n";
  return xml;
}

nlohmann::json GateJson(const std::vector<GateRun>& runs, const GateTolerance& tolerance) {
  auto figures = [](const BandFigures& f) {
    // No finite output: no bits figure (null), not 0 bits lost.
    const auto bits = [&](double value) { return f.judged == 0 ? nlohmann::json(nullptr) : JsonNumber(value); };
    return nlohmann::json{{"total_p999_bits", bits(f.total_p999)},
                          {"total_max_bits", bits(f.total_max)},
                          {"arith_p999_bits", bits(f.arith_p999)},
                          {"arith_max_bits", bits(f.arith_max)},
                          {"judged", f.judged},
                          {"nan", f.nan},
                          {"inf", f.inf}};
  };
  auto changes = [&](const std::vector<BandChange>& list) {
    nlohmann::json out = nlohmann::json::array();
    for (const BandChange& c : list) {
      out.push_back(
          {{"band", c.band}, {"reasons", c.reasons}, {"before", figures(c.before)}, {"after", figures(c.after)}});
    }
    return out;
  };
  nlohmann::json backends = nlohmann::json::array();
  bool pass = true;
  for (const GateRun& r : runs) {
    nlohmann::json cells = nlohmann::json::array();
    for (const CellVerdict& v : r.comparison.cells) {
      nlohmann::json cell = {{"cell", v.cell},
                             {"verdict", v.failed()     ? "worse"
                                         : v.appeared   ? "not compared"
                                         : v.improved() ? "better"
                                                        : "same"},
                             {"disappeared", v.disappeared},
                             {"appeared", v.appeared},
                             {"not_compared_bands", v.not_compared},
                             {"worse", changes(v.worse)},
                             {"better", changes(v.better)}};
      if (v.failed() && !v.disappeared) cell["reproduce"] = ReproFor(r, v.cell, v.worse.front());
      cells.push_back(cell);
    }
    pass = pass && r.comparison.failures() == 0;
    backends.push_back({{"backend", r.current.backend},
                        {"device", r.current.device.name},
                        {"baseline_commit", r.baseline.commit},
                        {"notes", r.comparison.notes},
                        {"failures", r.comparison.failures()},
                        {"improvements", r.comparison.improvements()},
                        {"cells", cells}});
  }
  return WithSchema(kGateSchema, {{"verdict", pass ? "pass" : "fail"},
                                  {"tolerance", {{"p999_bits", tolerance.p999_bits}, {"max_bits", tolerance.max_bits}}},
                                  {"backends", backends}});
}

}  // namespace depthbench
