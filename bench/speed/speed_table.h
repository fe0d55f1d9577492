// The human-readable view of speed results. Formats only: every figure and
// every mark (rank, tie, front) is computed before (speed_run.h, trade.h).
// Tables print in the output's style; the lines around them go to its text
// stream.
#pragma once

#include <ostream>

#include "bench/base/text_table.h"
#include "bench/speed/speed_results.h"

namespace depthbench {

// Device, driver, timestamp period, settings, and what the figures mean.
void PrintSpeedHeader(const SpeedResults& results, std::ostream& out);
// Two tables, one row per cell: per resolution, the memory-bound µs per
// frame with its memory-bound floor and whether it is bandwidth-bound;
// then the ALU-bound reconstructions per second; each with its spread and
// rank.
void PrintGpuTable(const SpeedResults& results, const TextOutput& out);
// One row per variant: the instruction mix of its reconstruction.
void PrintStaticTable(const SpeedResults& results, const TextOutput& out);
void PrintCpuTable(const SpeedResults& results, const TextOutput& out);
// Per convention and format: cost against p99.9 bits lost, front marked.
void PrintTradeTable(const SpeedResults& results, const TextOutput& out);
void PrintSkipped(const SpeedResults& results, std::ostream& out);
void PrintRankingComparison(const RankingComparison& comparison, std::ostream& out);

}  // namespace depthbench
