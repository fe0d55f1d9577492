#include "bench/speed/speed_table.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "bench/base/text_table.h"

namespace depthbench {
namespace {

using Align = TextTable::Align;

// "2.41 ±0.031": the median and its spread, three significant digits.
std::string WithSpread(double value, double spread) {
  return fmt::format("{} ±{}", Readable(value, 3), Readable(spread, 2));
}

// A rank, with '=' where another member of the group shares it.
std::string RankText(const SpeedResults& results, const GpuTiming& timing) {
  int sharing = 0;
  for (const GpuTiming& other : results.gpu) {
    if (SameGroup(other, timing) && other.rank == timing.rank) ++sharing;
  }
  return fmt::format("{}{}", sharing > 1 ? "=" : "", timing.rank);
}

std::string Count(const OpCount& c) {
  if (c.instructions == 0) return "0";
  return c.instructions == c.lanes ? fmt::format("{}", c.instructions)
                                   : fmt::format("{} ({})", c.instructions, c.lanes);
}

// "3.1%": two significant digits.
std::string Percent(double share) { return Readable(100.0 * share, 2) + "%"; }

// A stage's rate, its share of the compute stage's and the processors it
// ran on, a line each; then, where a drawing stage computes at under half
// the compute rate, what that means for the timings below.
void PrintStageProbe(const StageProbe& probe, std::ostream& out) {
  out << fmt::format("shader stages: {} multiply-adds an invocation, {} invocations a pass ({}):\n",
                     probe.fma_per_invocation, probe.invocations,
                     probe.processors > 0 ? "processors named by VK_NV_shader_sm_builtins"
                                          : "the device does not name its processors");
  const StageRate* const compute = probe.compute();
  for (const StageRate& stage : probe.stages) {
    std::string line =
        fmt::format("  {:<9}{} G multiply-adds/s", stage.stage, Readable(probe.fma_per_second(stage) * 1e-9, 3));
    if (&stage != compute) {
      line += fmt::format(", {} of compute's", Percent(probe.fma_per_second(stage) / probe.fma_per_second(*compute)));
    }
    if (probe.processors > 0) line += fmt::format(", on {} of {} processors", stage.processors_used, probe.processors);
    out << line << "\n";
  }
  for (const std::string& reason : probe.left_out) out << "  not measured: " << reason << "\n";
  if (const std::optional<double> share = probe.drawn_share(); share && *share < kSlowDrawnShare) {
    out << fmt::format(
        "  note: the timings below are compute passes; a reconstruction drawn by the rasterizer (an engine's "
        "full-screen pass, --pipeline raster) computes at {} of their rate on this device\n",
        Percent(*share));
  }
}

}  // namespace

void PrintSpeedHeader(const SpeedResults& results, std::ostream& out) {
  const SpeedRunInfo& run = results.run;
  out << fmt::format("depthbench {} speed (commit {}) on {} [{}; {}; {}]\n", run.version, run.commit, run.device.name,
                     run.device_type, run.device.driver, run.device.api);
  out << fmt::format(
      "timestamps: period {} ns, {} valid bits; {} warm-up passes (and more up to 20 ms), {} "
      "repetitions; ALU-bound regime: {} taps per pixel\n",
      run.timestamp_period_ns, run.timestamp_valid_bits, run.warmup, run.repetitions, run.alu_taps);
  out << "note: " << run.note << "\n";
  if (const std::optional<BandwidthProbe>& b = results.bandwidth) {
    out << fmt::format("memory bandwidth: {} GB/s ±{} (read and written; {}; median of {})\n",
                       Readable(b->bytes_per_second() * 1e-9, 3),
                       Readable(b->bytes_per_second() * 1e-9 * b->ns_per_pass.spread() / b->ns_per_pass.median, 2),
                       b->method, b->ns_per_pass.count);
  }
  if (const std::optional<StageProbe>& probe = results.stages) {
    PrintStageProbe(*probe, out);
  }
  if (const std::optional<PassCostSplit> split = SplitPassCost(results.gpu)) {
    if (split->fixed_ns >= 0.0) {
      out << fmt::format(
          "fixed cost per pass: {} µs, apart from {} ps per pixel (memory-bound passes, the line through {} and {}; "
          "median of {} cells): what a pass costs whatever its size\n",
          Readable(split->fixed_ns * 1e-3, 2), Readable(split->ns_per_pixel * 1e3, 3), ResolutionName(split->smallest),
          ResolutionName(split->largest), split->cells);
    } else {
      // A negative intercept is no cost: the smaller frame ran faster per
      // pixel than the larger (its image and output may stay in the
      // device's cache from pass to pass), and the line says nothing about
      // a pass's fixed cost.
      out << fmt::format(
          "fixed cost per pass: not measurable here: the {} passes took less per pixel than the {} ones (the line "
          "through them meets 0 pixels at {} µs; median of {} cells), as when a smaller frame stays in the "
          "device's cache from pass to pass\n",
          ResolutionName(split->smallest), ResolutionName(split->largest), Readable(split->fixed_ns * 1e-3, 2),
          split->cells);
    }
  }
  out << "figures are medians ±spread (interquartile range); a rank is 1 + the variants of the same convention, "
         "format, resolution and regime that are faster by more than the spread; '=' marks a rank shared with "
         "an indistinguishable variant\n\n";
}

void PrintGpuTable(const SpeedResults& results, const TextOutput& out) {
  std::vector<Cell> cells;
  for (const GpuTiming& t : results.gpu) {
    if (std::find(cells.begin(), cells.end(), t.cell) == cells.end()) cells.push_back(t.cell);
  }
  // One table per regime: the memory-bound one with each pass's floor
  // beside it, the ALU-bound one in reconstructions per second.
  for (const Regime regime : {Regime::kMemory, Regime::kAlu}) {
    const bool memory = regime == Regime::kMemory;
    std::vector<TextTable::Column> columns = {
        {"variant", Align::kLeft}, {"convention", Align::kLeft}, {"format", Align::kLeft}};
    for (const Resolution& r : results.run.resolutions) {
      if (memory) {
        columns.push_back({fmt::format("{} µs/frame", ResolutionName(r))});
        columns.push_back({"floor"});
        columns.push_back({"bound", Align::kLeft});
      } else {
        columns.push_back({fmt::format("{} G recon/s", ResolutionName(r))});
      }
      columns.push_back({"rank", Align::kRight, true});
    }
    TextTable table(columns);
    Encoding previous{};
    bool first = true;
    for (const Cell& cell : cells) {
      if (!first && cell.encoding() != previous) table.AddSeparator();
      first = false;
      previous = cell.encoding();
      std::vector<std::string> row = {std::string(cell.variant_info().name), std::string(Info(cell.convention).name),
                                      std::string(Info(cell.format).short_name)};
      for (const Resolution& r : results.run.resolutions) {
        const GpuTiming* t = results.FindGpu(cell, r, regime);
        if (t == nullptr) {
          row.insert(row.end(), memory ? 4 : 2, "-");
          continue;
        }
        if (memory) {
          // A whole frame, one reconstruction per pixel, in microseconds,
          // beside the floor of its format and resolution.
          row.push_back(WithSpread(t->ns_per_pass.median * 1e-3, t->ns_per_pass.spread() * 1e-3));
          const MemoryFloor* floor = results.FindFloor(cell.format, r);
          row.push_back(floor != nullptr ? Readable(floor->ns_per_pass * 1e-3, 3) : "-");
          const std::optional<double> times = results.TimesFloor(*t);
          row.push_back(!times                            ? "-"
                        : *times <= kBandwidthBoundFactor ? "bandwidth"
                                                          : fmt::format("{}x floor", Readable(*times, 2)));
        } else {
          // 10^9 reconstructions per second (the spread carried over to
          // first order: d(1/x) = dx / x^2).
          const double ns = t->ns_per_reconstruction(), spread = t->spread_ns_per_pixel() / t->taps;
          row.push_back(WithSpread(1.0 / ns, spread / (ns * ns)));
        }
        row.push_back(RankText(results, *t));
      }
      table.AddRow(row);
    }
    if (memory) {
      out.text << "GPU time of a whole frame, memory-bound (one reconstruction per pixel: reading the depth image and "
                  "writing positions), in µs";
      if (results.bandwidth) {
        out.text << fmt::format(
            "; floor: the least time the pass's bytes take at the device's measured bandwidth ({} GB/s, see "
            "above): (bytes of a texel + 4 written) per pixel; bound: 'bandwidth' where the pass takes at most "
            "{}x its floor (it is bound by memory bandwidth), else how many times its floor it takes (bound by "
            "something else: arithmetic, latency, the texture path, or on a CPU device the code itself)\n",
            Readable(results.bandwidth->bytes_per_second() * 1e-9, 3), Readable(kBandwidthBoundFactor, 2));
      } else {
        out.text << "; no floor: the device's bandwidth was not measured\n";
      }
    } else {
      out.text << "Reconstructions per second when ALU-bound (" << results.run.alu_taps
               << " per pixel), in 10^9: where the variants' arithmetic differs\n";
    }
    table.Print(out);
    out.text << "\n";
  }
}

void PrintStaticTable(const SpeedResults& results, const TextOutput& out) {
  TextTable table({{"variant", Align::kLeft},
                   {"fdiv"},
                   {"fmul"},
                   {"fadd/fsub"},
                   {"fma"},
                   {"dot"},
                   {"mat*vec"},
                   {"extended", Align::kLeft},
                   {"calls"},
                   {"instructions"}});
  for (const StaticCost& s : results.static_costs) {
    std::string extended;
    for (const auto& [name, count] : s.mix.extended_by_name) {
      extended += fmt::format("{}{} {}", extended.empty() ? "" : ", ", name, Count(count));
    }
    table.AddRow({std::string(results.variant_info(s.variant).name), Count(s.mix.fdiv), Count(s.mix.fmul),
                  Count(s.mix.fadd), Count(s.mix.fma), Count(s.mix.dot), Count(s.mix.matrix_vector),
                  extended.empty() ? "-" : extended, fmt::format("{}", s.mix.function_calls),
                  fmt::format("{}", s.mix.total_instructions)});
  }
  out.text << "Static cost: SPIR-V instructions of one reconstruction (lanes in parentheses where vector), counted "
              "in the compiled module\n";
  table.Print(out);
  out.text << "\n";
}

void PrintCpuTable(const SpeedResults& results, const TextOutput& out) {
  TextTable table({{"cell", Align::kLeft}, {"ns/recon"}, {"runs x samples"}});
  for (const CpuCost& c : results.cpu) {
    table.AddRow({c.cell.Name(), WithSpread(c.ns_per_reconstruction.median, c.ns_per_reconstruction.spread()),
                  fmt::format("{} x {}", c.runs_per_repetition, c.samples_per_run)});
  }
  out.text << "CPU backend (" << results.run.cpu_compiler << ", 8 float32 lanes, one thread), ns per reconstruction\n";
  table.Print(out);
  out.text << "\n";
}

void PrintTradeTable(const SpeedResults& results, const TextOutput& out) {
  if (results.trade.empty()) return;
  TextTable table({{"convention", Align::kLeft},
                   {"format", Align::kLeft},
                   {"variant", Align::kLeft},
                   {"p99.9 bits"},
                   {"gpu µs/frame"},
                   {"gpu front", Align::kLeft},
                   {"cpu ns/recon"},
                   {"cpu front", Align::kLeft},
                   {"NaN/Inf"}});
  // The ALU-bound cost of one reconstruction for every pixel of a frame.
  const double pixels = static_cast<double>(results.run.trade_resolution.width) * results.run.trade_resolution.height;
  bool first = true;
  for (const TradeFront& front : results.trade) {
    if (!first) table.AddSeparator();
    first = false;
    for (const TradePoint& p : front.points) {
      table.AddRow({std::string(Info(front.convention).name), std::string(Info(front.format).short_name),
                    std::string(results.variant_info(p.variant).name), fmt::format("{:.1f}", p.p999_bits_lost),
                    WithSpread(p.gpu_ns_per_reconstruction * pixels * 1e-3, p.gpu_spread_ns * pixels * 1e-3),
                    p.on_gpu_front ? "*" : "",
                    p.has_cpu_cost() ? WithSpread(p.cpu_ns_per_reconstruction, p.cpu_spread_ns) : "-",
                    p.on_cpu_front ? "*" : "", fmt::format("{}", p.nonfinite)});
    }
  }
  out.text << fmt::format(
      "The trade at {} and on the CPU: cost against p99.9 bits lost ({} backend, {}). GPU cost: the ALU-bound "
      "time of one reconstruction per pixel of a frame; * = on the Pareto front of its convention and format (no "
      "variant is as cheap, to the spread, and as accurate, to 1/4 bit, and better in one)\n",
      ResolutionName(results.run.trade_resolution), results.run.accuracy_backend, results.run.accuracy_source);
  table.Print(out);
  out.text << "\n";
}

void PrintSkipped(const SpeedResults& results, std::ostream& out) {
  for (const std::string& line : results.skipped) out << "not measured: " << line << "\n";
  if (!results.skipped.empty()) out << "\n";
}

void PrintRankingComparison(const RankingComparison& c, std::ostream& out) {
  out << fmt::format(
      "Repeatability: {} pairs of variants compared; {} in the same order in both runs, {} indistinguishable in "
      "both, {} distinguishable in one run only, {} in opposite orders\n",
      c.pairs, c.agree, c.both_ties, c.one_sided, c.contradictions.size());
  for (const std::string& line : c.contradictions) out << "  opposite: " << line << "\n";
}

}  // namespace depthbench
