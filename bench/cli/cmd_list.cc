// depthbench list: the catalog (variants with their seeds, conventions,
// formats, cells) and the Vulkan devices this machine has.
#include <algorithm>

#include <fmt/format.h>

#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/text_table.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/pipeline/projection_matrix.h"

namespace depthbench::cli {
namespace {

const char* InputName(DepthInput input) {
  switch (input) {
    case DepthInput::kHardware: return "hardware depth";
    case DepthInput::kLinear: return "linear depth z/far";
    case DepthInput::kViewZ: return "view-space z";
  }
  return "?";
}

Expected<int> List(const CommandContext& context) {
  const TextOutput& out = context.output;
  using Align = TextTable::Align;
  TextTable variants({{"variant", Align::kLeft},
                      {"source", Align::kLeft},
                      {"reads", Align::kLeft},
                      {"projection", Align::kLeft},
                      {"frustum", Align::kLeft},
                      {"idea", Align::kLeft}});
  for (const auto& v : context.catalogue.variants()) {
    const char* projection = v.projections == Projections::kBoth           ? "both"
                             : v.projections == Projections::kOrthographic ? "orthographic"
                                                                           : "perspective";
    variants.AddRow({std::string(v.name), std::string(v.source), InputName(v.input), projection,
                     v.assumes_symmetric_frustum ? "symmetric" : "any", std::string(v.idea)});
  }
  out.text << "Variants (their sources: docs/sources.md)\n";
  variants.Print(out);

  out.text << "frustum: 'symmetric' variants put NDC (0, 0) on the view axis, as their sources write them, and are "
              "wrong for an off-centre frustum (a VR eye, TAA jitter); 'any' follow the frustum's own corners or "
              "matrix; projection: the projections the formula is written for (an orthographic one, --ortho or a "
              "matrix, runs the ortho-* conventions)\n";

  TextTable conventions({{"convention", Align::kLeft}, {"meaning", Align::kLeft}});
  for (const auto& c : AllConventions()) conventions.AddRow({std::string(c.name), std::string(c.description)});
  out.text << "\nDepth conventions\n";
  conventions.Print(out);
  out.text << "\nWhat each graphics API must do to store them\n";
  for (const auto& c : AllConventions()) out.text << fmt::format("  {}: {}\n", c.name, ApiRecipe(c.id));

  TextTable formats(
      {{"format", Align::kLeft}, {"short", Align::kLeft}, {"Vulkan", Align::kLeft}, {"stores", Align::kLeft}});
  for (const auto& f : AllFormats()) {
    formats.AddRow({std::string(f.name), std::string(f.short_name), std::string(f.vulkan_name), InputName(f.stores)});
  }
  out.text << "\nStorage formats\n";
  formats.Print(out);
  const std::vector<Cell> cells = context.catalogue.Cells();
  const auto orthographic = std::count_if(cells.begin(), cells.end(),
                                          [](const Cell& c) { return Info(c.convention).orthographic(); });
  out.text << fmt::format(
      "\n{} cells (variant/convention/format) per backend, {} of them perspective (a perspective domain runs them) "
      "and {} orthographic (an orthographic one does); backends: cpu, vulkan\n",
      cells.size(), cells.size() - static_cast<std::size_t>(orthographic), orthographic);

  out.text << "\nVulkan devices\n";
  auto devices = ListVulkanDevices();
  if (!devices.ok()) {
    out.text << "  none usable: " << devices.status().message() << "\n";
    return kExitOk;
  }
  TextTable table({{"name", Align::kLeft}, {"type", Align::kLeft}, {"driver", Align::kLeft}, {"api", Align::kLeft}});
  for (const auto& d : *devices) table.AddRow({d.name, d.type, d.driver, d.api});
  table.Print(out);
  return kExitOk;
}

}  // namespace

void AddListCommand(CLI::App& app, CommandAction& action) {
  CLI::App* cmd =
      app.add_subcommand("list", "List variants (with their seeds), conventions, formats and Vulkan devices");
  cmd->callback([&action] { action = List; });
}

}  // namespace depthbench::cli
