#include "bench/report/report_render.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/text_table.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/stats.h"
#include "bench/report/report_json.h"

namespace depthbench {
namespace {

// The summary is a CI job page: the verdict line, then at most 40 lines
// in all, whatever changed (tests/report_render_test.cc holds the full set
// of cells to that): the page has the detail. Its budget, at most:
// verdict 2, changes and notes 5 + 1, the first screen 4 + 16 rows + 3,
// worst cells and findings 3 + 3 + 1 + 1, the closing line 1.
constexpr std::size_t kWorstInSummary = 3;  // on one line
constexpr std::size_t kChangesInSummary = 3;
constexpr std::size_t kFindingsInSummary = 3;

// Where the page's template takes the libraries and the document.
constexpr std::string_view kLibrariesMark = "<!--DEPTHBENCH:LIBRARIES-->";
constexpr std::string_view kDataMark = "/*DEPTHBENCH:DATA*/null";

// Bits lost; a figure that is not finite means every bit is lost.
std::string Bits(const Figure& bits) { return bits ? fmt::format("{:.1f}", *bits) : "all"; }
std::string Number(const Figure& x) { return x ? Readable(*x) : "-"; }
// A length in metres, in the unit that reads best: "0.31 mm", "4.2 cm", "1.5 m".
std::string Metres(const Figure& x) {
  if (!x) return "-";
  if (*x < 0.01) return Readable(*x * 1e3, 2) + " mm";
  if (*x < 1.0) return Readable(*x * 1e2, 2) + " cm";
  if (*x < 1e3) return Readable(*x, 2) + " m";
  return Readable(*x * 1e-3, 2) + " km";
}

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
  const std::vector<HistorySection::WorseCell>& worse = h.worse_cells;
  out += fmt::format(
      "**Verdict: {}** since {}: {} cells worse, {} better, {} unchanged of {} (tolerance {} bit at "
      "p99.9, {} bit at the maximum).\n\n",
      worse.empty() ? "nothing got worse" : fmt::format("{} cell(s) got worse", worse.size()),
      fmt::join(previous, ", "), worse.size(), h.better_cells, h.unchanged_cells, report.headline.size(),
      h.tolerance_p999_bits, h.tolerance_max_bits);
  for (std::size_t shown = 0; shown < worse.size(); ++shown) {
    if (shown == kChangesInSummary) {
      out += fmt::format("- ... and {} more: see report.html\n", worse.size() - kChangesInSummary);
      break;
    }
    const std::vector<std::string>& bands = worse[shown].bands;
    const std::size_t kBandsShown = 3;
    std::vector<std::string> first(bands.begin(), bands.begin() + std::min(bands.size(), kBandsShown));
    out += fmt::format("- `{}` on {}: {}{}\n", worse[shown].cell, worse[shown].backend,
                       Escape(fmt::format("{}", fmt::join(first, "; "))),
                       bands.size() > kBandsShown ? fmt::format(" (+{} bands)", bands.size() - kBandsShown) : "");
  }
  // The comparison's notes, folded into one item of the same list.
  if (!h.notes.empty()) out += fmt::format("- note: {}\n", Escape(fmt::format("{}", fmt::join(h.notes, "; "))));
  if (!worse.empty() || !h.notes.empty()) out += "\n";
}

// What to use: the report's first screen (Report::recommendations), one
// line per finite convention and format; a convention's infinite-far
// form (standard-inf beside standard, ...) folds into its line, in the
// last two columns. The page keeps one row each.
void WhatToUse(const Report& report, std::string& out) {
  if (report.recommendations.empty()) return;
  const RecommendationRow& first = report.recommendations.front();
  // The finite convention an infinite-far one is the limit of; itself for
  // the others (and for a name not in the catalogue).
  const auto finite_form = [](const std::string& convention) {
    const Expected<Convention> parsed = ParseConvention(convention);
    if (!parsed.ok() || (Info(*parsed).bits & catalog::kInf) == 0) return convention;
    for (const ConventionInfo& c : AllConventions()) {
      if (c.hardware && c.bits == (Info(*parsed).bits & ~catalog::kInf)) return std::string(c.name);
    }
    return convention;
  };
  struct Line {
    std::string convention, format;
    const RecommendationRow *finite = nullptr, *infinite = nullptr;
  };
  std::vector<Line> lines;
  for (const RecommendationRow& r : report.recommendations) {
    const std::string convention = finite_form(r.convention);
    const bool infinite = convention != r.convention;
    auto it = std::find_if(lines.begin(), lines.end(),
                           [&](const Line& l) { return l.convention == convention && l.format == r.format; });
    if (it == lines.end()) it = lines.insert(lines.end(), Line{convention, r.format});
    (infinite ? it->infinite : it->finite) = &r;
  }
  const auto use = [](const RecommendationRow* r) {
    if (r == nullptr) return std::string("-");
    if (r->keeps_nothing) return std::string("**do not use**: keeps nothing");
    std::string text = "`" + r->variants.front() + "`";
    if (r->variants.size() > 1) {
      text +=
          fmt::format(" (= {})", fmt::join(std::vector<std::string>(r->variants.begin() + 1, r->variants.end()), ", "));
    }
    return text;
  };
  const auto bits = [](const RecommendationRow* r) {
    if (r == nullptr) return std::string("-");
    const std::string interval =
        r->bits_low && r->bits_high ? fmt::format(" [{:.1f}, {:.1f}]", *r->bits_low, *r->bits_high) : "";
    return Bits(r->bits) + interval;
  };
  const auto proven = [](const RecommendationRow* r) {
    return r == nullptr ? std::string("-") : r->proven_bits ? Bits(r->proven_bits) : std::string("none");
  };
  out += fmt::format("## What to use: the convention and format first ({} backend; cost in {})\n\n", first.backend,
                     first.cost_unit);
  out +=
      "| convention | format | use | f/n | bits lost [95%] | proven, any device | far plane at 100 m | at 10 km | B/px "
      "| cost | f/n for 1e-3 | f/n for 1e-6 | infinite far: use | bits lost [95%] | proven, any device |\n";
  out += "|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|\n";
  for (const Line& l : lines) {
    const RecommendationRow* f = l.finite;
    out += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", l.convention,
                       l.format, use(f), f ? f->ratio : "-", bits(f), proven(f), f ? Metres(f->error_far_100m) : "-",
                       f ? Metres(f->error_far_10km) : "-", f ? std::to_string(f->bytes_per_pixel) : "-",
                       f ? Number(f->cost) : "-", f ? Budget(f->ratio_for_1e3) : "-",
                       f ? Budget(f->ratio_for_1e6) : "-", use(l.infinite), bits(l.infinite), proven(l.infinite));
  }
  // The lever in one sentence, from the rows themselves.
  const auto find = [&](const char* convention) -> const RecommendationRow* {
    for (const RecommendationRow& r : report.recommendations)
      if (r.convention == convention && r.format == "d32_sfloat" && r.bits) return &r;
    return nullptr;
  };
  const RecommendationRow *reversed = find("reversed"), *standard = find("standard");
  const std::string lever =
      reversed && standard ? fmt::format(" (with D32F at f/n {}, reversed Z loses {} bits at the far plane where "
                                         "standard Z loses {})",
                                         reversed->ratio, Bits(reversed->bits), Bits(standard->bits))
                           : "";
  out += fmt::format(
      "\nThe combinations that keep the most bits first: the convention and format are the lever{}; the variant "
      "moves it by a bit or less. Use: the cheapest variant within {} bit of the most precise (= tied ones); 'do not use' where even the "
      "interval's lower end keeps less than one bit. Bits lost at p99.9 at the far plane at that far/near, with the "
      "model's 95% interval; proven, any device: the most bits the variant can lose anywhere at that far/near (every "
      "depth, pixel and lens, the camera at the origin) on any conformant Vulkan device (`depthbench bound`; none: "
      "no bound holds), a guarantee for devices nobody measured, at or above the worst any sample shows; that error in world units with the far plane at 100 m (near 1 cm) and 10 km (near "
      "1 m); B/px: the depth bytes a frame moves per pixel (no stencil); f/n for 1e-3 and 1e-6: the far/near up to "
      "which the upper end of the far plane's interval keeps that relative error; infinite far: the convention's "
      "-inf form, at its far end.\n\n",
      lever, kResolvedBits);
}

// The scene's first screen (report --scene): per convention and format its
// best candidate and whether it meets the scene's requirement.
void YourScene(const Report& report, std::string& out) {
  if (!report.scene) return;
  const SceneSection& s = *report.scene;
  out += fmt::format("## Your scene: {} ({}; {} backend; cost in {})\n\n", s.name, s.requirement, s.backend,
                     s.cost_unit);
  out += fmt::format("| convention | format | measured (upper) |{} far end | B/px | cost | use |\n",
                     s.proven ? " proven, any device |" : "");
  out += fmt::format("|---|---|---:|{}---:|---:|---:|---|\n", s.proven ? "---:|" : "");
  for (const SceneRow& r : s.rows) {
    const std::string use =
        r.meets ? "`" + r.variant + "`" : fmt::format("**do not use**: {:.3g}x the limit", r.times_limit);
    const std::string proven = s.proven ? fmt::format(" {} |", r.proven ? Number(r.proven) : "none") : "";
    out += fmt::format("| {} | {} | {} |{} {} | {} | {} | {} |\n", r.convention, r.format, Number(r.measured), proven,
                       Number(r.far_end), r.bytes_per_pixel > 0 ? std::to_string(r.bytes_per_pixel) : "-",
                       Number(r.cost), use);
  }
  if (s.capture) {
    const auto& c = *s.capture;
    out += fmt::format("![bits lost per pixel]({})\n\nBits lost per pixel of `{}` by `{}` on {} ({} pixels judged: "
                       "median {:.1f}, p99.9 {:.1f}, worst {:.1f}; grey: nothing drawn). The bar under it runs from 0 "
                       "to 24 bits lost, a tick every 4.\n\n",
                       c.image, c.source, c.cell, c.backend, c.pixels, c.median_bits, c.p999_bits, c.worst_bits);
  }
  for (const std::string& w : s.what_ifs) out += "- what if " + w + "\n";
  for (const std::string& n : s.not_candidates) out += "- not a candidate: " + n + "\n";
  out += "\nMeasured: the upper end of the 95% interval at the requirement's level and depth, in its unit; far end: "
         "measured at the scene's far end; each convention and format by its best variant as `depthbench choose` "
         "ranks them.";
  if (s.proven) {
    out += " Proven: the most the candidate can lose at the requirement's depth on any conformant Vulkan device "
           "(`depthbench bound`), which decides whether it meets the requirement.";
  }
  out += "\n\n";
}

// The worst cells over the default domain and the NaN/Inf findings by
// cause, a few lines each: the page lists them all.
void Problems(const Report& report, std::string& out) {
  out += "## Worst cells and NaN/Inf findings\n\n";
  std::vector<std::string> worst_text;
  for (std::size_t k = 0; k < report.worst_cells.size() && k < kWorstInSummary; ++k) {
    const HeadlineRow& row = report.headline[report.worst_cells[k].row];
    worst_text.push_back(fmt::format("`{}` on {} ({}, {})", row.cell.Name(),
                                     fmt::join(report.worst_cells[k].backends, ", "), Bits(row.measured->p999_bits),
                                     Bits(row.measured->max_bits)));
  }
  if (!worst_text.empty()) {
    out += fmt::format("- worst (bits lost at p99.9 and at the maximum over the default domain): {}\n",
                       fmt::join(worst_text, "; "));
  }
  const std::vector<FindingGroup>& groups = report.finding_groups;
  if (groups.empty()) out += "- no cell produced a NaN or an infinity where the true point is finite\n";
  for (std::size_t i = 0; i < groups.size() && i < kFindingsInSummary; ++i) {
    const FindingGroup& g = groups[i];
    out += fmt::format("- cause: `{}` returns {}: {} outputs in {} (cell, backend, sweep) rows ({}; {}); first: `{}`\n",
                       g.variant, NonFiniteKindName(g.kind), g.outputs, g.rows, fmt::join(g.sweeps, ", "),
                       fmt::join(g.backends, ", "), g.command);
  }
  if (groups.size() > kFindingsInSummary) {
    out += fmt::format("- ... and {} more causes of NaN/Inf outputs: see report.html\n",
                       groups.size() - kFindingsInSummary);
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

namespace {

// Where the template takes the libraries and the data: the libraries' mark
// first. An error names the file.
Expected<std::pair<std::size_t, std::size_t>> TemplateMarks(const std::string& page,
                                                            const std::filesystem::path& template_file) {
  const std::size_t libraries_at = page.find(kLibrariesMark);
  const std::size_t data_at = page.find(kDataMark);
  if (libraries_at == std::string::npos || data_at == std::string::npos || data_at < libraries_at) {
    return InvalidArgument(fmt::format("{}: not a report template (it lacks {} before {})", template_file.string(),
                                       kLibrariesMark, kDataMark));
  }
  return std::pair{libraries_at, data_at};
}

}  // namespace

Status CheckReportTemplate(const std::filesystem::path& template_file) {
  DB_ASSIGN_OR_RETURN(const std::string page, ReadFile(template_file, kMaxSourceFileBytes));
  return TemplateMarks(page, template_file).status();
}

Expected<std::string> RenderHtml(const Report& report, const std::filesystem::path& template_file,
                                 const PlotLibrary& library) {
  DB_RETURN_IF_ERROR(library.Check());
  DB_ASSIGN_OR_RETURN(std::string page, ReadFile(template_file, kMaxSourceFileBytes));
  DB_ASSIGN_OR_RETURN(const auto marks, TemplateMarks(page, template_file));
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

  // The data first: it comes after the libraries' mark, which keeps its place.
  page.replace(marks.second, kDataMark.size(), data);
  page.replace(marks.first, kLibrariesMark.size(), scripts);
  return page;
}

std::string RenderMarkdown(const Report& report) {
  const ReportEnvironment& env = report.environment;
  std::string out;
  Verdict(report, out);
  YourScene(report, out);
  WhatToUse(report, out);
  Problems(report, out);
  std::vector<std::string> devices;
  for (const auto& [name, device] : env.backends) devices.push_back(fmt::format("{} ({})", name, device.name));
  out += fmt::format(
      "depthbench precision report · {} · commit `{}` · {} · {} samples per far/near, {} default-domain{} · "
      "{:.0f} s. Detail (plots of bits lost against far/near, the speed/accuracy front, GPU against CPU, every "
      "finding with its replay command): `report.html` beside this file; every figure: `results.json`.\n",
      env.started_at, env.commit.substr(0, 12), fmt::join(devices, ", "),
      ShortCount(static_cast<double>(env.fit_sweeps.samples_per_ratio)),
      ShortCount(static_cast<double>(env.default_sweep.samples)), env.quick ? " (quick)" : "",
      env.seconds.value_or(0.0));
  return out;
}

}  // namespace depthbench
