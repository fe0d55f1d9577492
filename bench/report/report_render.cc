#include "bench/report/report_render.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/report/report_json.h"

namespace depthbench {
namespace {

constexpr std::size_t kWorstInSummary = 5;
constexpr std::size_t kChangesInSummary = 20;
constexpr std::size_t kFindingsInSummary = 5;

// Where the page's template takes the libraries and the document.
constexpr std::string_view kLibrariesMark = "<!--DEPTHBENCH:LIBRARIES-->";
constexpr std::string_view kDataMark = "/*DEPTHBENCH:DATA*/null";

// Bits lost; a figure that is not finite means every bit is lost.
std::string Bits(const Figure& bits) { return bits ? fmt::format("{:.1f}", *bits) : "all"; }
std::string Number(const Figure& x) { return x ? fmt::format("{:.3g}", *x) : "-"; }

std::string Budget(const BudgetRatio& b) {
  switch (b.kind) {
    case BudgetRatio::Kind::kNone: return "-";
    case BudgetRatio::Kind::kAlways: return "always";
    case BudgetRatio::Kind::kNever: return "never";
    case BudgetRatio::Kind::kRatio: return Number(b.ratio);
  }
  return "-";
}

// A table cell must not break the Markdown table.
std::string Escape(std::string s) {
  std::string out;
  for (char c : s) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out;
}

// The verdict line first (what changed since the last report, in counts
// of cells), then the cells that got worse.
void Verdict(const Report& report, std::string& out) {
  if (!report.history) {
    out += "**Verdict: not compared** (no history was kept for this run, `--no-history`).\n\n";
    return;
  }
  const HistorySection& h = *report.history;
  if (h.previous.empty()) {
    out += fmt::format(
        "**Verdict: first run** of this sample plan on this device in `{}`: nothing to compare with yet.\n\n",
        h.database);
    return;
  }
  std::vector<std::string> previous;
  for (const HistorySection::Previous& p : h.previous) {
    previous.push_back(fmt::format("{} run {} (commit `{}`)", p.backend, p.run, p.commit.substr(0, 12)));
  }
  // Worse first, grouped by cell and backend; a cell worse in one band and
  // better in another counts as worse.
  std::map<std::pair<std::string, std::string>, std::vector<std::string>> worse;
  std::set<std::pair<std::string, std::string>> better;
  for (const HistorySection::Change& c : h.changes) {
    const std::pair<std::string, std::string> key{c.cell, c.backend};
    if (c.direction == "worse") worse[key].push_back(fmt::format("{}: {}", c.band, fmt::join(c.reasons, ", ")));
  }
  for (const HistorySection::Change& c : h.changes) {
    const std::pair<std::string, std::string> key{c.cell, c.backend};
    if (c.direction == "better" && !worse.count(key)) better.insert(key);
  }
  const std::size_t cells = report.headline.size();
  const std::size_t unchanged = cells - std::min(cells, worse.size() + better.size());
  out += fmt::format(
      "**Verdict: {}** since {}: {} cells worse, {} better, {} unchanged of {} (tolerance {} bit at "
      "p99.9, {} bit at the maximum).\n\n",
      worse.empty() ? "nothing got worse" : fmt::format("{} cell(s) got worse", worse.size()),
      fmt::join(previous, ", "), worse.size(), better.size(), unchanged, cells, h.tolerance_p999_bits,
      h.tolerance_max_bits);
  std::size_t shown = 0;
  for (const auto& [key, bands] : worse) {
    if (shown++ == kChangesInSummary) {
      out += fmt::format("- ... and {} more (see report.html)\n", worse.size() - kChangesInSummary);
      break;
    }
    const std::size_t kBandsShown = 3;
    std::vector<std::string> first(bands.begin(), bands.begin() + std::min(bands.size(), kBandsShown));
    out += fmt::format("- `{}` on {}: {}{}\n", key.first, key.second, Escape(fmt::format("{}", fmt::join(first, "; "))),
                       bands.size() > kBandsShown ? fmt::format(" (+{} bands)", bands.size() - kBandsShown) : "");
  }
  if (!worse.empty()) out += "\n";
  for (const std::string& note : h.notes) out += fmt::format("Note: {}\n\n", note);
}

// What to use: the report's first screen (Report::recommendations).
void WhatToUse(const Report& report, std::string& out) {
  if (report.recommendations.empty()) return;
  const RecommendationRow& first = report.recommendations.front();
  out += fmt::format(
      "## What to use ({})\n\nPer convention and format: the cheapest variant within 0.25 bit of the most precise "
      "(tied ones in parentheses), p99.9 bits lost at the far plane with the model's 95% interval, cost in {}, and "
      "the far/near up to which the far plane keeps 1e-3 and 1e-6.\n\n",
      first.backend, first.cost_unit);
  out += "| convention | format | use | f/n | bits lost [95%] | cost | f/n for 1e-3 | f/n for 1e-6 |\n";
  out += "|---|---|---|---|---:|---:|---:|---:|\n";
  for (const RecommendationRow& r : report.recommendations) {
    std::string use = "`" + r.variants.front() + "`";
    if (r.variants.size() > 1) {
      use +=
          fmt::format(" (= {})", fmt::join(std::vector<std::string>(r.variants.begin() + 1, r.variants.end()), ", "));
    }
    const std::string interval =
        r.bits_low && r.bits_high ? fmt::format(" [{:.1f}, {:.1f}]", *r.bits_low, *r.bits_high) : "";
    out += fmt::format("| {} | {} | {} | {} | {}{} | {} | {} | {} |\n", r.convention, r.format, use, r.ratio,
                       Bits(r.bits), interval,
                       !r.cost            ? "-"
                       : *r.cost >= 100.0 ? fmt::format("{:.0f}", *r.cost)
                                          : fmt::format("{:.3g}", *r.cost),
                       Budget(r.ratio_for_1e3), Budget(r.ratio_for_1e6));
  }
  out += "\n";
}

void Worst(const Report& report, std::string& out) {
  out +=
      "## Worst cells\n\nHighest p99.9 bits lost over the default domain (every projection, pose and depth the "
      "sampler draws).\n\n";
  out += "| cell | backend | p99.9 bits lost | max bits lost | NaN | Inf |\n|---|---|---:|---:|---:|---:|\n";
  for (const HeadlineRow* row : WorstRows(report, kWorstInSummary)) {
    out += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", row->cell.Name(), row->cell.backend,
                       Bits(row->measured->p999_bits), Bits(row->measured->max_bits), row->measured->nan,
                       row->measured->inf);
  }
  out += "\n";
}

void Findings(const Report& report, std::string& out) {
  const std::vector<NonFiniteRow>& rows = report.nonfinite;
  out += "## NaN and Inf\n\n";
  if (rows.empty()) {
    out += "No cell produced a NaN or an infinity where the true point is finite.\n\n";
    return;
  }
  out += fmt::format("{} (cell, backend, sweep) with NaN or Inf outputs:\n\n", rows.size());
  std::size_t shown = 0;
  for (const NonFiniteRow& row : rows) {
    if (shown++ == kFindingsInSummary) {
      out += fmt::format("- ... and {} more (see report.html)\n", rows.size() - kFindingsInSummary);
      break;
    }
    out += fmt::format("- `{}` on {}, {}: {} NaN, {} Inf of {}; first: `{}`\n", row.cell.Name(), row.cell.backend,
                       row.sweep, row.nan, row.inf, row.judged, row.command);
  }
  out += "\n";
}

}  // namespace

std::vector<std::filesystem::path> PlotLibrary::Bundles() const {
  return {node_modules / "vega" / "build" / "vega.min.js", node_modules / "vega-lite" / "build" / "vega-lite.min.js",
          node_modules / "vega-embed" / "build" / "vega-embed.min.js"};
}

Status PlotLibrary::Check() const {
  for (const std::filesystem::path& bundle : Bundles()) {
    if (!std::filesystem::is_regular_file(bundle)) {
      return NotFound(fmt::format(
          "{} is missing: the page's plotting library (Vega-Lite) is not installed; run ./setup.sh, or "
          "npm ci --prefix reports, or point --plot-library at a node_modules folder that holds vega, vega-lite "
          "and vega-embed",
          bundle.string()));
    }
  }
  return Status::Ok();
}

Expected<std::string> RenderHtml(const Report& report, const std::filesystem::path& template_file,
                                 const PlotLibrary& library) {
  DB_RETURN_IF_ERROR(library.Check());
  DB_ASSIGN_OR_RETURN(std::string page, ReadFile(template_file, kMaxSourceFileBytes));
  std::string scripts;
  for (const std::filesystem::path& bundle : library.Bundles()) {
    DB_ASSIGN_OR_RETURN(std::string code, ReadFile(bundle, kMaxSourceFileBytes));
    // The page is offline: drop the pointer to a source map it cannot load.
    const std::size_t map = code.rfind("//# sourceMappingURL=");
    if (map != std::string::npos) code.erase(map);
    if (code.find("</script") != std::string::npos) {
      return InvalidArgument(bundle.string() + ": contains \"</script\" and cannot be inlined in the page");
    }
    scripts += fmt::format("<script>/* {} */\n{}\n</script>\n", bundle.filename().string(), code);
  }
  // JSON holds '<' only inside strings, where "<\/" means the same.
  std::string data = ReportToJson(report).dump();
  for (std::size_t at = 0; (at = data.find("</", at)) != std::string::npos; at += 3) data.replace(at, 2, "<\\/");

  const std::size_t libraries_at = page.find(kLibrariesMark);
  const std::size_t data_at = page.find(kDataMark);
  if (libraries_at == std::string::npos || data_at == std::string::npos || data_at < libraries_at) {
    return InvalidArgument(fmt::format("{}: not a report template (it lacks {} before {})", template_file.string(),
                                       kLibrariesMark, kDataMark));
  }
  page.replace(data_at, kDataMark.size(), data);
  page.replace(libraries_at, kLibrariesMark.size(), scripts);
  return page;
}

std::string RenderMarkdown(const Report& report) {
  const ReportEnvironment& env = report.environment;
  std::string out = "# depthbench precision report\n\n";
  std::vector<std::string> devices;
  for (const auto& [name, device] : env.backends) devices.push_back(fmt::format("{} ({})", name, device.name));
  out +=
      fmt::format("{} · commit `{}` · {} · {} samples per far/near ratio, {} default-domain samples{} · {:.0f} s\n\n",
                  env.started_at, env.commit.substr(0, 12), fmt::join(devices, ", "), env.fit_sweeps.samples_per_ratio,
                  env.default_sweep.samples, env.quick ? " (quick)" : "", env.seconds.value_or(0.0));
  Verdict(report, out);
  WhatToUse(report, out);
  Worst(report, out);
  Findings(report, out);
  out += "The whole report, with plots: `report.html`; every figure it shows: `results.json`.\n";
  return out;
}

std::vector<const HeadlineRow*> WorstRows(const Report& report, std::size_t count) {
  std::vector<const HeadlineRow*> rows;
  for (const HeadlineRow& row : report.headline) {
    if (row.measured) rows.push_back(&row);
  }
  std::stable_sort(rows.begin(), rows.end(), [](const HeadlineRow* a, const HeadlineRow* b) {
    const double a_p999 = a->measured->p999_bits.value_or(INFINITY), b_p999 = b->measured->p999_bits.value_or(INFINITY);
    if (a_p999 != b_p999) return a_p999 > b_p999;
    return a->measured->max_bits.value_or(INFINITY) > b->measured->max_bits.value_or(INFINITY);
  });
  if (rows.size() > count) rows.resize(count);
  return rows;
}

}  // namespace depthbench
