#include "bench/report/report_render.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "bench/base/files.h"

namespace depthbench {
namespace {

using json = nlohmann::json;

constexpr std::size_t kWorstInSummary = 10;
constexpr std::size_t kChangesInSummary = 20;
constexpr std::size_t kFindingsInSummary = 10;

// Where the page's template takes the libraries and the document.
constexpr std::string_view kLibrariesMark = "<!--DEPTHBENCH:LIBRARIES-->";
constexpr std::string_view kDataMark = "/*DEPTHBENCH:DATA*/null";

double NumberOr(const json& j, const char* key, double fallback) {
  auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : fallback;
}

std::string Text(const json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return "-";
  if (it->is_string()) return it->get<std::string>();
  if (it->is_number_integer() || it->is_number_unsigned()) return it->dump();
  if (it->is_number()) return fmt::format("{:.3g}", it->get<double>());
  return it->dump();
}

std::string Bits(const json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end()) return "-";
  if (it->is_null()) return "all";  // not finite: every bit lost
  return fmt::format("{:.1f}", it->get<double>());
}

std::string CellName(const json& row) {
  return fmt::format("{}/{}/{}", row.value("variant", ""), row.value("convention", ""), row.value("format", ""));
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

std::string GpuBackend(const json& report) {
  std::string chosen;
  for (const json& b : report["environment"]["backends"]) {
    const std::string name = b.value("name", "");
    if (chosen.empty() || name != "cpu") chosen = name;
  }
  return chosen;
}

void Changes(const json& report, std::string& out) {
  out += "## Since the last report\n\n";
  const json& h = report["history"];
  if (h.is_null()) {
    out += "No history was kept for this run (`--no-history`).\n\n";
    return;
  }
  if (h["previous"].empty()) {
    out += fmt::format("First run of this sample plan on this device in `{}`: nothing to compare with yet.\n\n",
                       h.value("database", ""));
    return;
  }
  std::vector<std::string> previous;
  for (const json& p : h["previous"]) {
    previous.push_back(fmt::format("{}: run {} of {} (commit `{}`)", p.value("backend", ""), p.value("run", 0),
                                   p.value("made_at", ""), p.value("commit", "").substr(0, 12)));
  }
  out += fmt::format("Compared with {}; tolerance {} bit at p99.9 and {} bit at the maximum.\n\n",
                     fmt::join(previous, ", "), h["tolerance"].value("p999_bits", 0.0),
                     h["tolerance"].value("max_bits", 0.0));
  // Worse first, grouped by cell and backend.
  std::map<std::pair<std::string, std::string>, std::vector<std::string>> worse;
  std::set<std::pair<std::string, std::string>> better;
  for (const json& c : h["changes"]) {
    const std::pair<std::string, std::string> key{c.value("cell", ""), c.value("backend", "")};
    if (c.value("direction", "") == "worse") {
      std::vector<std::string> reasons = c["reasons"].get<std::vector<std::string>>();
      worse[key].push_back(fmt::format("{}: {}", c.value("band", ""), fmt::join(reasons, ", ")));
    } else {
      better.insert(key);
    }
  }
  if (worse.empty()) {
    out += "**Nothing got worse.**";
  } else {
    out += fmt::format("**{} cell(s) got worse:**\n\n", worse.size());
    std::size_t shown = 0;
    for (const auto& [key, bands] : worse) {
      if (shown++ == kChangesInSummary) {
        out += fmt::format("- ... and {} more (see report.html)\n", worse.size() - kChangesInSummary);
        break;
      }
      const std::size_t kBandsShown = 3;
      std::vector<std::string> first(bands.begin(), bands.begin() + std::min(bands.size(), kBandsShown));
      out +=
          fmt::format("- `{}` on {}: {}{}\n", key.first, key.second, Escape(fmt::format("{}", fmt::join(first, "; "))),
                      bands.size() > kBandsShown ? fmt::format(" (+{} bands)", bands.size() - kBandsShown) : "");
    }
  }
  if (!better.empty()) out += fmt::format("\n{} cell(s) got better.", better.size());
  out += "\n\n";
  for (const json& note : h["notes"]) out += fmt::format("Note: {}\n\n", note.get<std::string>());
}

// Per convention and format, on the GPU backend: the variant that keeps
// the most bits at the far plane of f/n = 1e8 (or an infinite far plane).
void Headline(const json& report, std::string& out) {
  const std::string backend = GpuBackend(report);
  std::map<std::pair<std::string, std::string>, const json*> best;
  auto far_bits = [](const json& row) {
    const json& p = row["predicted_bits"];
    const char* key = row.value("infinite_far", false) ? "inf" : "1e8";
    return p.contains(key) && p[key].is_number() ? p[key].get<double>() : INFINITY;
  };
  std::vector<std::pair<std::string, std::string>> order;
  for (const json& row : report["headline"]) {
    if (row.value("backend", "") != backend) continue;
    const std::pair<std::string, std::string> key{row.value("convention", ""), row.value("format", "")};
    auto [it, added] = best.try_emplace(key, &row);
    if (added)
      order.push_back(key);
    else if (far_bits(row) < far_bits(*it->second))
      it->second = &row;
  }
  out += fmt::format(
      "## Headline ({})\n\nPer convention and format, the variant that keeps the most bits at the far plane; "
      "bits lost at p99.9 of the relative error, from the fitted model.\n\n",
      backend);
  out +=
      "| convention | format | best variant | bits lost per doubling of f/n | at 1e4 | at 1e8 | at inf | f/n for 1e-3 "
      "| f/n for 1e-6 |\n";
  out += "|---|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& key : order) {
    const json& row = *best[key];
    const json& p = row["predicted_bits"];
    auto predicted = [&](const char* at) { return p.contains(at) ? Bits(p, at) : std::string("-"); };
    const std::string slope = row["slope"].is_null()
                                  ? "-"
                                  : fmt::format("{:.2f} [{:.2f}, {:.2f}]", NumberOr(row, "slope", 0),
                                                NumberOr(row, "slope_low", NAN), NumberOr(row, "slope_high", NAN));
    out += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", key.first, key.second,
                       row.value("variant", ""), slope, predicted("1e4"), predicted("1e8"), predicted("inf"),
                       Text(row, "ratio_for_1e-3"), Text(row, "ratio_for_1e-6"));
  }
  out += "\n";
}

void Worst(const json& report, std::string& out) {
  out +=
      "## Worst cells\n\nHighest p99.9 bits lost over the default domain (every projection, pose and depth the "
      "sampler draws).\n\n";
  out += "| cell | backend | p99.9 bits lost | max bits lost | NaN | Inf |\n|---|---|---:|---:|---:|---:|\n";
  std::vector<std::string> worst = WorstCells(report, kWorstInSummary);
  for (const std::string& name : worst) {
    for (const json& row : report["headline"]) {
      if (CellName(row) + " on " + row.value("backend", "") != name) continue;
      out += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", CellName(row), row.value("backend", ""),
                         Bits(row, "p999_bits"), Bits(row, "max_bits"), Text(row, "nan"), Text(row, "inf"));
    }
  }
  out += "\n";
}

void Findings(const json& report, std::string& out) {
  const json& rows = report["findings"]["nonfinite"];
  out += "## NaN and Inf\n\n";
  if (rows.empty()) {
    out += "No cell produced a NaN or an infinity where the true point is finite.\n\n";
    return;
  }
  out += fmt::format("{} (cell, backend, sweep) with NaN or Inf outputs:\n\n", rows.size());
  std::size_t shown = 0;
  for (const json& row : rows) {
    if (shown++ == kFindingsInSummary) {
      out += fmt::format("- ... and {} more (see report.html)\n", rows.size() - kFindingsInSummary);
      break;
    }
    out += fmt::format("- `{}` on {}, {}: {} NaN, {} Inf of {}; first: `{}`\n", CellName(row), row.value("backend", ""),
                       row.value("sweep", ""), Text(row, "nan"), Text(row, "inf"), Text(row, "judged"),
                       row.value("command", ""));
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

Expected<std::string> RenderHtml(const json& report, const std::filesystem::path& template_file,
                                 const PlotLibrary& library) {
  DB_RETURN_IF_ERROR(library.Check());
  DB_ASSIGN_OR_RETURN(std::string page, ReadFile(template_file));
  std::string scripts;
  for (const std::filesystem::path& bundle : library.Bundles()) {
    DB_ASSIGN_OR_RETURN(std::string code, ReadFile(bundle));
    // The page is offline: drop the pointer to a source map it cannot load.
    const std::size_t map = code.rfind("//# sourceMappingURL=");
    if (map != std::string::npos) code.erase(map);
    if (code.find("</script") != std::string::npos) {
      return InvalidArgument(bundle.string() + ": contains \"</script\" and cannot be inlined in the page");
    }
    scripts += fmt::format("<script>/* {} */\n{}\n</script>\n", bundle.filename().string(), code);
  }
  // JSON holds '<' only inside strings, where "<\/" means the same.
  std::string data = report.dump();
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

std::string RenderMarkdown(const json& report) {
  const json& env = report["environment"];
  std::string out = "# depthbench precision report\n\n";
  std::vector<std::string> devices;
  for (const json& b : env["backends"]) {
    devices.push_back(fmt::format("{} ({})", b.value("name", ""), b["device"].value("name", "")));
  }
  out +=
      fmt::format("{} · commit `{}` · {} · {} samples per far/near ratio, {} default-domain samples{} · {:.0f} s\n\n",
                  env.value("started_at", ""), env.value("commit", "").substr(0, 12), fmt::join(devices, ", "),
                  env["fit_sweeps"].value("samples_per_ratio", 0), env["default_sweep"].value("samples", 0),
                  env.value("quick", false) ? " (quick)" : "", NumberOr(env, "seconds", 0.0));
  Changes(report, out);
  Headline(report, out);
  Worst(report, out);
  Findings(report, out);
  out += "The whole report, with plots: `report.html`; every figure it shows: `results.json`.\n";
  return out;
}

std::vector<std::string> WorstCells(const json& report, std::size_t count) {
  struct Row {
    double p999, max;
    std::string name;
  };
  std::vector<Row> rows;
  for (const json& row : report["headline"]) {
    if (!row.contains("p999_bits")) continue;
    rows.push_back({NumberOr(row, "p999_bits", INFINITY), NumberOr(row, "max_bits", INFINITY),
                    CellName(row) + " on " + row.value("backend", "")});
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const Row& a, const Row& b) { return a.p999 != b.p999 ? a.p999 > b.p999 : a.max > b.max; });
  std::vector<std::string> names;
  for (std::size_t i = 0; i < rows.size() && i < count; ++i) names.push_back(rows[i].name);
  return names;
}

}  // namespace depthbench
