// The report's two renderings, both drawn from the typed report alone
// (report_model.h): a self-contained HTML page with interactive Vega-Lite
// plots, and a short Markdown summary for a CI job page.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/report/report_model.h"

namespace depthbench {

// The plotting library the page embeds: Vega, Vega-Lite and vega-embed,
// as npm installs them (reports/package.json) into `node_modules`.
struct PlotLibrary {
  std::filesystem::path node_modules;
  // The three bundles, in load order.
  std::vector<std::filesystem::path> Bundles() const;
  // NotFound with what to run when a bundle is missing.
  Status Check() const;
};

// The page: `template_file` (reports/report_template.html) with the
// library bundles and the report's JSON document inlined, so that it opens
// offline.
// Whether `template_file` is a report template RenderHtml can fill: for
// checking before the work.
Status CheckReportTemplate(const std::filesystem::path& template_file);

Expected<std::string> RenderHtml(const Report& report, const std::filesystem::path& template_file,
                                 const PlotLibrary& library);

// The Markdown summary: what changed since the last comparable run, the
// headline per convention and format, the worst cells, NaN/Inf findings.
std::string RenderMarkdown(const Report& report);

}  // namespace depthbench
