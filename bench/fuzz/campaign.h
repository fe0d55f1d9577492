// The GPU fuzz campaign (depthbench fuzz): batches of adversarial inputs run
// through every backend together, checked against the invariants of
// case_check.h. Inputs come from the committed corpus (fuzz/corpus/formulas),
// from the ends of every range of the fuzz domain (the extremes catalogue),
// from random points, and from mutations of the inputs that came closest to
// their bound. Findings are deduplicated by signature (cell, backend, kind),
// shrunk to the simplest case that still fails the same way, and written as
// reproducer files that `depthbench run --repro FILE` replays, each as soon
// as it is found: SIGINT or SIGTERM ends the campaign after the batch or
// the file in hand, and what was found is kept.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/fuzz/case_check.h"
#include "bench/fuzz/fuzz_case.h"

namespace depthbench {

struct CampaignOptions {
  double seconds = 10.0;    // stop after this long (0: no limit)
  std::uint64_t cases = 0;  // or after this many cases (0: no limit)
  std::uint64_t seed = 1;
  std::vector<Cell> cells;
  std::vector<std::filesystem::path> corpus;  // files of FuzzPoint bytes, or folders of them
  // Where reproducer files go ("" = none written). Each is written when its
  // finding is first seen (the case as found, the hits so far), and
  // rewritten at the end with the shrunk case and the campaign's count.
  std::filesystem::path out;
  Domain domain = FuzzDomain();
  std::uint32_t frames_per_batch = 64;  // x 64 samples
  // Units held at a value in every input (index into the 18 units of a
  // FuzzPoint, value): how a named extreme pins a depth pick or a pixel.
  std::vector<std::pair<int, double>> pinned;
  // Proven bounds of the shader part, per (cell, backend) in that order
  // (cells major), over `domain` (empty: none): a judged sample beyond its
  // bound is a finding of its own kind (FindingKind::kBeyondProven).
  std::vector<double> proven;
  // The proven bound at single samples (CaseChecker::SetSampleBound), or
  // empty: each batch's worst samples are held against it too.
  SampleBound sample_bound;
  std::function<void(double fraction, const std::string& line)> progress;
};

struct CampaignFinding {
  std::string signature;  // "divide/standard/d32_sfloat cpu beyond_bound"
  Cell cell;
  std::string backend;
  FindingKind kind = FindingKind::kBeyondBound;
  std::uint64_t hits = 0;  // cases that failed with this signature
  FuzzCase first;          // as found
  FuzzCase shrunk;         // the simplest that still fails the same way
  Judgement judgement;     // of the shrunk case
  std::filesystem::path file;
};

struct CampaignResult {
  std::uint64_t cases = 0;   // inputs run (each through every cell and backend)
  std::uint64_t checks = 0;  // (cell, backend, input) triples checked
  std::uint64_t from_corpus = 0, from_extremes = 0, from_random = 0, from_mutation = 0;
  double seconds = 0.0;
  double closest = 0.0;  // the largest arithmetic error / bound seen that was no finding
  std::string closest_cell;
  // Where CampaignOptions::sample_bound was given (CaseChecker's).
  CaseChecker::SampleBoundReach sample_bound_reach;
  std::vector<CampaignFinding> findings;
};

Expected<CampaignResult> RunCampaign(const CampaignOptions& options, std::span<Backend* const> backends);

// Reads FuzzPoints from files and folders of files.
Expected<std::vector<FuzzPoint>> ReadCorpus(const std::vector<std::filesystem::path>& paths);

}  // namespace depthbench
