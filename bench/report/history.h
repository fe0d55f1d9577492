// History: the headline figures of every report run, kept in a SQLite
// database, so that a report can show each cell's trend across nights and
// say what got worse since the previous run.
//
// One row per (run, backend, cell, band) holds the gate's figures of that
// band (baseline.h: bits lost of the total and arithmetic error at p99.9
// and max, NaN and Inf counts, the worst sample). Runs are compared only
// with runs of the same sample plan on the same device: with a fixed seed,
// anything that moves between two such runs is a change in the code, the
// driver or the compiler, never noise.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/gate/baseline.h"

struct sqlite3;

namespace depthbench {

struct HistoryRun {
  std::int64_t id = 0;  // set by Record
  std::string made_at;  // ISO 8601 UTC
  std::string commit;
  std::string host;
  std::string version;
  bool quick = false;
  double seconds = 0.0;
};

// One cell's "all"-samples figures in one run: a point of its trend.
struct TrendPoint {
  std::int64_t run = 0;
  std::string made_at;
  std::string commit;
  std::string backend;
  std::string cell;
  double total_p999 = 0.0, total_max = 0.0;
  std::uint64_t nonfinite = 0;
};

class History {
 public:
  // Opens the database, creating it (and its folder) when missing. Refuses
  // a file that is not a depthbench history, one of a newer version, a
  // damaged one and one that cannot be written: all before any work.
  static Expected<History> Open(const std::filesystem::path& path);
  History(History&&) noexcept;
  History& operator=(History&&) noexcept;
  ~History();

  // Records one run: one baseline per backend, all of one sample plan, in
  // a transaction that stays open: Commit() keeps the run (once the report
  // it belongs to is written); without it, nothing is kept.
  Expected<std::int64_t> Record(HistoryRun run, std::span<const Baseline> baselines);
  Status Commit();

  // The latest run before `run_id` with the same plan as `like` on the
  // same backend and device, as a baseline (nullopt when there is none).
  Expected<std::optional<std::pair<HistoryRun, Baseline>>> Previous(std::int64_t run_id, const Baseline& like);

  // The "all" band of every cell of `like`'s backend, over the last `limit`
  // runs (up to `run_id`) of the same plan and device, oldest first.
  Expected<std::vector<TrendPoint>> Trend(std::int64_t run_id, const Baseline& like, int limit);

  // Runs recorded in total.
  Expected<std::int64_t> RunCount();

  const std::filesystem::path& path() const { return path_; }

 private:
  History(sqlite3* db, std::filesystem::path path) : db_(db), path_(std::move(path)) {}
  Status Exec(const char* sql);
  sqlite3* db_ = nullptr;
  std::filesystem::path path_;
};

}  // namespace depthbench
