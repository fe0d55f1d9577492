// The human-readable view of run results: one row per cell and backend
// with the headline figures, and optional tables split by band. Formats
// only; every figure comes from the statistics. Tables print in the
// output's style; the lines around them go to its text stream.
#pragma once

#include <ostream>

#include "bench/base/text_table.h"
#include "bench/results/results.h"

namespace depthbench {

enum class BandFamily { kRatio, kDepth, kDistance };

void PrintResultsTable(const Results& results, const TextOutput& out);
// p99.9 bits lost (total error) per cell and band of one family.
void PrintBandTable(const Results& results, BandFamily family, const TextOutput& out);
// The one-paragraph header: seed, samples, domain, devices, throughput.
void PrintRunHeader(const Results& results, std::ostream& out);
// How the depths each raster backend rendered compare with the host's model
// of a rasterizer (bench/pipeline/raster_model.h), per encoding; nothing
// where no backend rendered its own.
void PrintRasterAgreement(const Results& results, std::ostream& out);

}  // namespace depthbench
