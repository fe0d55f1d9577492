#include "bench/results/results_table.h"

#include <set>

#include <fmt/format.h>

#include "bench/base/text_table.h"

namespace depthbench {
namespace {

std::string Bits(double relative) { return fmt::format("{:.1f}", BitsLost(relative)); }

// A p99.9 with the larger half of its 95% interval, or what it lacks.
std::string P999(const Summary& s) {
  if (!s.p999_supported) return "few";
  const double bits = BitsLost(s.p999);
  const double spread = std::max(bits - BitsLost(s.p999_interval.low), BitsLost(s.p999_interval.high) - bits);
  return fmt::format("{:.1f}±{:.1f}", bits, spread);
}
constexpr const char* kNoFigure = "-";
std::string Count(std::uint64_t n) { return n == 0 ? "0" : fmt::format("{}", n); }

}  // namespace

void PrintRunHeader(const Results& results, std::ostream& out) {
  const RunInfo& run = results.run;
  out << fmt::format("depthbench {} (commit {}), seed {}, {} samples, {} constants", run.version, run.commit, run.seed,
                     run.samples, ConstantsModelName(run.domain.constants));
  if (!(run.shards.size() == 1 && run.shards[0].count == 1)) {
    out << fmt::format(" (shards {})", ShardList(run.shards));
  }
  out << "\n";
  const std::vector<Shard> missing = MissingShards(run.shards);
  if (run.shards.size() == 1 && run.shards[0].count > 1) {
    // One shard run on its own, as a scheduler's job does: expected.
    out << fmt::format("shard {} of a sweep: the figures are of its samples; depthbench merge adds the shards up\n",
                       run.shards[0].ToString());
  } else if (!missing.empty()) {
    out << fmt::format("PARTIAL: missing shards {}; these figures are of the other shards' samples only\n",
                       ShardList(missing));
  }
  if (run.partial) {
    out << fmt::format("PARTIAL: interrupted; {} of the shards' samples were judged, the figures are of those only\n",
                       run.samples_judged);
  }
  out << "domain: " << run.domain.Describe() << "\n";
  for (const auto& b : run.backends) {
    out << fmt::format("backend {}: {} [{}; {}; {}]", b.name, b.device.name, b.device.driver, b.device.api,
                       b.device.compiler);
    if (BackendKindOf(b.name) == BackendKind::kVulkan) {
      if (b.device.kind == DeviceKind::kCpu) out << " (software rasterizer on the CPU)";
      out << fmt::format(", shaders {} ({})", b.program.shaders, b.program.hash);
    }
    out << "\n";
  }
  if (run.seconds > 0) {
    out << fmt::format("{} reconstructions verified in {:.2f} s: {}/s\n", ShortCount(run.reconstructions), run.seconds,
                       ShortCount(run.reconstructions / run.seconds));
  }
  if (!run.stages.empty()) {
    const StageSeconds& t = run.stages;
    out << fmt::format("time: setup {:.2f} s, build {:.2f} s, run and judge {:.2f} s", t.setup, t.build, t.judging);
    if (t.device_waited > 0) out << fmt::format(" ({:.2f} s waiting for the device)", t.device_waited);
    if (t.build_waited > 0) out << fmt::format("; the build waited {:.2f} s", t.build_waited);
    out << "\n";
    const auto list = [&](const char* title, const std::vector<std::pair<std::string, double>>& entries) {
      if (entries.empty()) return;
      out << title;
      const char* separator = " ";
      for (const auto& [name, seconds] : entries) {
        out << fmt::format("{}{} {:.3f} s", separator, name, seconds);
        separator = ", ";
      }
      out << "\n";
    };
    list("device passes:", t.device_passes);
    list("the device judge's thread:", t.judge_host_steps);
  }
  out << "bits lost = log2(relative error / 2^-24), from 0 (float32's own rounding) to 24 (nothing left); relative "
         "to the distance from the camera\n\n";
}

void PrintResultsTable(const Results& results, const TextOutput& out) {
  using Align = TextTable::Align;
  TextTable table({{"cell", Align::kLeft},
                   {"backend", Align::kLeft},
                   {"judged", Align::kRight, true},
                   {"p50", Align::kRight, true},
                   {"p99", Align::kRight, true},
                   {"p99.9"},
                   {"max"},
                   {"prod"},
                   {"stor"},
                   {"shader"},
                   {"abs p99.9"},
                   {"abs max", Align::kRight, true},
                   {"NaN"},
                   {"Inf"},
                   // Expected, not findings: the first to go when a long
                   // cell name (a user's variant) needs the room.
                   {"stored inf", Align::kRight, true}});
  for (const CellResult& c : results.cells) {
    const BandStats all = c.stats.All();
    const Summary total = Summarize(all, Metric::kTotal);
    const Summary absolute = Summarize(all, Metric::kAbsolute);
    // A figure of no samples is no figure (an all-NaN cell lost every bit, not 0.0 of them).
    const auto measured = [&](Metric m, std::string text) {
      return all.metrics[static_cast<int>(m)].Count() == 0 ? std::string(kNoFigure) : text;
    };
    const bool no_output = all.finite == 0;
    table.AddRow(
        {c.cell.Name(), c.backend, no_output && all.nan + all.inf > 0 ? "none finite" : Count(all.finite),
         measured(Metric::kTotal, Bits(total.p50)), measured(Metric::kTotal, Bits(total.p99)),
         measured(Metric::kTotal, P999(total)), measured(Metric::kTotal, Bits(total.max)),
         measured(Metric::kProduction, Bits(Summarize(all, Metric::kProduction).p999)),
         measured(Metric::kStorage, Bits(Summarize(all, Metric::kStorage).p999)),
         measured(Metric::kArith, Bits(Summarize(all, Metric::kArith).p999)),
         measured(Metric::kAbsolute, fmt::format("{}{:.2g}", absolute.p999_below_range ? "<=" : "", absolute.p999)),
         measured(Metric::kAbsolute, fmt::format("{:.2g}", absolute.max)), Count(all.nan), Count(all.inf),
         Count(all.stored_nonfinite)});
  }
  out.text << "The domain's natural distribution (log-uniform eye depth, uniform pixels). Bits lost of the total error\n"
           << fmt::format(
                  "(p50 / p99 / p99.9 with its 95% sampling interval, 'few' below {} samples / max) and, at p99.9, of its\n",
                  MinimumSamples(Level::kP999))
           << 
         "three causes: prod (the depth the pipeline produced), stor (the format's rounding and fetch), shader (the\n"
         "variant's float32 arithmetic); the absolute error in world units ('<=': below the histogram's range of\n"
         "2^-48, so only bounded); NaN and Inf outputs where exact arithmetic on the shader's inputs is finite\n"
         "(findings), and 'stored inf', non-finite outputs of stored values that denote infinity or the camera\n"
         "(expected); '-': no sample to measure ('none finite': every output was NaN or Inf)\n";
  table.Print(out);
}

void PrintBandTable(const Results& results, BandFamily family, const TextOutput& out) {
  std::set<int> bands;
  for (const CellResult& c : results.cells) {
    if (family == BandFamily::kDistance) {
      for (const auto& [band, stats] : c.stats.distance) bands.insert(band);
    } else {
      for (const auto& [band, stats] : c.stats.joint)
        bands.insert(family == BandFamily::kRatio ? RatioOfJoint(band) : DepthOfJoint(band));
    }
  }
  const char* title = family == BandFamily::kRatio   ? "far/near ratio"
                      : family == BandFamily::kDepth ? "eye depth / near"
                                                     : "camera distance from the origin";
  std::vector<TextTable::Column> columns{{"cell", TextTable::Align::kLeft}, {"backend", TextTable::Align::kLeft}};
  for (int band : bands) {
    columns.push_back({family == BandFamily::kRatio   ? RatioBandName(band)
                       : family == BandFamily::kDepth ? DepthBandName(band)
                                                      : DistanceBandName(band)});
  }
  TextTable table(columns);
  for (const CellResult& c : results.cells) {
    std::vector<std::string> row{c.cell.Name(), c.backend};
    for (int band : bands) {
      BandStats s = family == BandFamily::kRatio   ? c.stats.ForRatio(band)
                    : family == BandFamily::kDepth ? c.stats.ForDepth(band)
                                                   : c.stats.ForDistance(band);
      const Summary total = Summarize(s, Metric::kTotal);
      std::string text = s.finite == 0 ? "-" : total.p999_supported ? Bits(total.p999) : "few";
      if (s.nan + s.inf > 0) text += "!";
      row.push_back(text);
    }
    table.AddRow(std::move(row));
  }
  out.text << fmt::format(
      "\np99.9 bits lost by {} band ('!': NaN or Inf in the band; '-': no samples; 'few': under {})\n", title,
      MinimumSamples(Level::kP999));
  table.Print(out);
}

void PrintRasterAgreement(const Results& results, std::ostream& out) {
  for (const BackendRecord& backend : results.run.backends) {
    if (backend.raster_agreement.empty()) continue;
    out << fmt::format(
        "\n{}'s rasterized depths against the host's model of a rasterizer (texels that differ; "
        "the largest difference in codes, ulps for float formats):\n",
        backend.name);
    for (const RasterAgreement& a : backend.raster_agreement) {
      out << fmt::format("  {}/{}: {} of {} differ ({:.3g}%), at most {}{}\n", Info(a.encoding.convention).name,
                         Info(a.encoding.format).name, a.differing, a.texels,
                         a.texels == 0 ? 0.0 : 100.0 * static_cast<double>(a.differing) / static_cast<double>(a.texels),
                         a.max_code_distance,
                         a.uncovered == 0 ? "" : fmt::format("; {} left uncovered, not judged", a.uncovered));
    }
  }
}

}  // namespace depthbench
