// Sweep: the run loop. Draws the samples of a shard in batches, runs every
// cell on every backend, judges the outputs against the reference, and
// streams the errors into fixed-size statistics, so memory stays flat
// however many samples run. RunSweep checks the options, prepares the
// backends, makes each backend's judging stage (judging_stage.h), plans
// the run (sweep_plan.h) and follows the plan.
#pragma once

#include <span>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/results/results.h"
#include "bench/sweep/sweep_options.h"

namespace depthbench {

// The cells of `cells` that the domain can exercise (finite-far cells need
// finite frames, infinite-far cells need the domain to allow them).
std::vector<Cell> CellsForDomain(std::span<const Cell> cells, const Domain& domain);

// The backend whose rendered depths every backend reconstructs from: the
// first that renders its own (Backend::renders_depths), under the raster
// production model; null otherwise.
Backend* DepthRenderer(ProductionModel production, std::span<Backend* const> backends);
// Renders the batch's depths on `renderer` and adopts them into the batch
// (BatchBuilder::AdoptStoredDepths).
Status AdoptRenderedDepths(Backend& renderer, const BatchBuilder& builder, Batch& batch, ThreadPool& pool);

// Runs the sweep on each backend (prepared by this call) and returns the
// results, one CellResult per (cell, backend). Invalid options fail before
// anything runs, naming the violated constraint (SweepOptions::Validate).
Expected<Results> RunSweep(const SweepOptions& options, std::span<Backend* const> backends);

}  // namespace depthbench
