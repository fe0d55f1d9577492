#include "bench/report/history.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <sqlite3.h>

namespace depthbench {
namespace {

// 'DBHs': marks the file as a depthbench history (PRAGMA application_id).
constexpr int kApplicationId = 0x44424873;
constexpr int kSchemaVersion = 1;
constexpr std::uint64_t kNoIndex = std::numeric_limits<std::uint64_t>::max();

constexpr const char* kSchema = R"sql(
CREATE TABLE runs(
  id INTEGER PRIMARY KEY,
  made_at TEXT NOT NULL,
  commit_id TEXT NOT NULL,
  host TEXT NOT NULL,
  version TEXT NOT NULL,
  quick INTEGER NOT NULL,
  seconds REAL NOT NULL);
CREATE TABLE run_backends(
  run_id INTEGER NOT NULL REFERENCES runs(id),
  backend TEXT NOT NULL,
  device_name TEXT NOT NULL,
  device TEXT NOT NULL,   -- JSON, as in the results files
  plan TEXT NOT NULL,     -- JSON of the sample plan: seed, samples, domain
  PRIMARY KEY(run_id, backend));
CREATE TABLE figures(
  run_id INTEGER NOT NULL,
  backend TEXT NOT NULL,
  cell TEXT NOT NULL,
  band TEXT NOT NULL,     -- "all", "ratio 1e3", "depth 1e2", "distance <1", ...
  total_p999 REAL, total_max REAL, arith_p999 REAL, arith_max REAL,  -- bits lost
  judged INTEGER NOT NULL, nan INTEGER NOT NULL, inf INTEGER NOT NULL,
  worst_index INTEGER, first_nonfinite_index INTEGER,
  PRIMARY KEY(run_id, backend, cell, band),
  FOREIGN KEY(run_id, backend) REFERENCES run_backends(run_id, backend));
CREATE INDEX figures_by_cell ON figures(backend, cell, band);
)sql";

// A prepared statement, finalized on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK) stmt_ = nullptr;
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  bool ok() const { return stmt_ != nullptr; }
  Statement& Bind(int i, const std::string& v) {
    sqlite3_bind_text(stmt_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Statement& Bind(int i, std::int64_t v) {
    sqlite3_bind_int64(stmt_, i, v);
    return *this;
  }
  // NaN is stored as NULL (SQLite has no NaN); infinities are kept.
  Statement& BindReal(int i, double v) {
    if (std::isnan(v)) {
      sqlite3_bind_null(stmt_, i);
    } else {
      sqlite3_bind_double(stmt_, i, v);
    }
    return *this;
  }
  Statement& BindIndex(int i, std::uint64_t v) {
    if (v == kNoIndex) {
      sqlite3_bind_null(stmt_, i);
    } else {
      sqlite3_bind_int64(stmt_, i, static_cast<std::int64_t>(v));
    }
    return *this;
  }
  // SQLITE_ROW, SQLITE_DONE or an error code.
  int Step() { return sqlite3_step(stmt_); }
  void Reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  std::string Text(int c) const {
    const unsigned char* t = sqlite3_column_text(stmt_, c);
    return t == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(t));
  }
  std::int64_t Int(int c) const { return sqlite3_column_int64(stmt_, c); }
  double Real(int c) const {
    return sqlite3_column_type(stmt_, c) == SQLITE_NULL ? std::numeric_limits<double>::quiet_NaN()
                                                        : sqlite3_column_double(stmt_, c);
  }
  std::uint64_t Index(int c) const {
    return sqlite3_column_type(stmt_, c) == SQLITE_NULL ? kNoIndex
                                                        : static_cast<std::uint64_t>(sqlite3_column_int64(stmt_, c));
  }

 private:
  sqlite3_stmt* stmt_ = nullptr;
};

Status DbError(sqlite3* db, const std::filesystem::path& path, const std::string& what) {
  return IoError(fmt::format("{}: {}: {}", path.string(), what, sqlite3_errmsg(db)));
}

std::string PlanKey(const SamplePlan& plan) { return SamplePlanToJson(plan).dump(); }

}  // namespace

Expected<History> History::Open(const std::filesystem::path& path) {
  std::error_code ec;
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), ec);
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) != SQLITE_OK) {
    Status error = DbError(db, path, "cannot open the history database");
    sqlite3_close(db);
    return error;
  }
  History history(db, path);
  sqlite3_busy_timeout(db, 10000);  // two reports at once: the second waits for the first's write
  // Reading the header fails here when the file is not SQLite at all.
  Statement probe(db,
                  "SELECT (SELECT application_id FROM pragma_application_id),"
                  " (SELECT user_version FROM pragma_user_version),"
                  " (SELECT count(*) FROM sqlite_schema)");
  if (!probe.ok() || probe.Step() != SQLITE_ROW) {
    return DbError(db, path, "not a SQLite database (give --history another file)");
  }
  const std::int64_t application = probe.Int(0), version = probe.Int(1), objects = probe.Int(2);
  if (objects == 0) {
    DB_RETURN_IF_ERROR(history.Exec("BEGIN"));
    DB_RETURN_IF_ERROR(history.Exec(kSchema));
    DB_RETURN_IF_ERROR(history.Exec(
        fmt::format("PRAGMA application_id = {}; PRAGMA user_version = {}", kApplicationId, kSchemaVersion).c_str()));
    DB_RETURN_IF_ERROR(history.Exec("COMMIT"));
  } else if (application != kApplicationId) {
    return InvalidArgument(fmt::format(
        "{}: a SQLite database, but not a depthbench history (give --history another file)", path.string()));
  } else if (version != kSchemaVersion) {
    return InvalidArgument(fmt::format("{}: history schema version {}; this depthbench reads version {}", path.string(),
                                       version, kSchemaVersion));
  }
  // Damage anywhere in the file, and a file that cannot be written (a
  // read-only file or file system), are found now, not after the sweeps.
  {
    Statement check(db, "PRAGMA quick_check");
    if (!check.ok() || check.Step() != SQLITE_ROW || check.Text(0) != "ok") {
      return DbError(db, path, "the history database is damaged (PRAGMA quick_check); give --history another file");
    }
  }
  if (sqlite3_db_readonly(db, "main") == 1 || !history.Exec("BEGIN IMMEDIATE").ok() || !history.Exec("ROLLBACK").ok()) {
    return DbError(db, path, "the history database cannot be written");
  }
  return history;
}

History::History(History&& other) noexcept : db_(other.db_), path_(std::move(other.path_)) { other.db_ = nullptr; }

History& History::operator=(History&& other) noexcept {
  if (this != &other) {
    sqlite3_close(db_);
    db_ = other.db_;
    path_ = std::move(other.path_);
    other.db_ = nullptr;
  }
  return *this;
}

History::~History() { sqlite3_close(db_); }

Status History::Exec(const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    Status error = IoError(fmt::format("{}: {}", path_.string(), message ? message : "SQLite error"));
    sqlite3_free(message);
    return error;
  }
  return Status::Ok();
}

Expected<std::int64_t> History::Record(HistoryRun run, std::span<const Baseline> baselines) {
  DB_RETURN_IF_ERROR(Exec("BEGIN IMMEDIATE"));
  auto fail = [&](const std::string& what) {
    Status error = DbError(db_, path_, what);
    (void)Exec("ROLLBACK");  // the first error is the one to report
    return error;
  };
  Statement insert_run(db_, "INSERT INTO runs(made_at, commit_id, host, version, quick, seconds) VALUES(?,?,?,?,?,?)");
  if (!insert_run.ok()) return fail("cannot record the run");
  insert_run.Bind(1, run.made_at).Bind(2, run.commit).Bind(3, run.host).Bind(4, run.version);
  insert_run.Bind(5, std::int64_t{run.quick}).BindReal(6, run.seconds);
  if (insert_run.Step() != SQLITE_DONE) return fail("cannot record the run");
  run.id = sqlite3_last_insert_rowid(db_);

  Statement insert_backend(db_,
                           "INSERT INTO run_backends(run_id, backend, device_name, device, plan) VALUES(?,?,?,?,?)");
  Statement insert_band(db_,
                        "INSERT INTO figures(run_id, backend, cell, band, total_p999, total_max, arith_p999,"
                        " arith_max, judged, nan, inf, worst_index, first_nonfinite_index)"
                        " VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?)");
  if (!insert_backend.ok() || !insert_band.ok()) return fail("cannot record the figures");
  for (const Baseline& b : baselines) {
    insert_backend.Reset();
    insert_backend.Bind(1, run.id).Bind(2, b.backend).Bind(3, b.device.name);
    insert_backend.Bind(4, DeviceToJson(b.device).dump()).Bind(5, PlanKey(b.plan));
    if (insert_backend.Step() != SQLITE_DONE) return fail("cannot record backend " + b.backend);
    for (const auto& [cell, bands] : b.cells) {
      for (const auto& [band, f] : bands) {
        insert_band.Reset();
        insert_band.Bind(1, run.id).Bind(2, b.backend).Bind(3, cell).Bind(4, band);
        insert_band.BindReal(5, f.total_p999).BindReal(6, f.total_max).BindReal(7, f.arith_p999);
        insert_band.BindReal(8, f.arith_max);
        insert_band.Bind(9, static_cast<std::int64_t>(f.judged)).Bind(10, static_cast<std::int64_t>(f.nan));
        insert_band.Bind(11, static_cast<std::int64_t>(f.inf));
        insert_band.BindIndex(12, f.worst_index).BindIndex(13, f.first_nonfinite_index);
        if (insert_band.Step() != SQLITE_DONE) return fail("cannot record the figures of " + cell);
      }
    }
  }
  return run.id;
}

Status History::Commit() { return Exec("COMMIT"); }

Expected<std::optional<std::pair<HistoryRun, Baseline>>> History::Previous(std::int64_t run_id, const Baseline& like) {
  Statement find(db_,
                 "SELECT r.id, r.made_at, r.commit_id, r.host, r.version, r.quick, r.seconds, b.device"
                 " FROM runs r JOIN run_backends b ON b.run_id = r.id"
                 " WHERE r.id < ? AND b.backend = ? AND b.device_name = ? AND b.plan = ?"
                 " ORDER BY r.id DESC LIMIT 1");
  if (!find.ok()) return DbError(db_, path_, "cannot read the history");
  find.Bind(1, run_id).Bind(2, like.backend).Bind(3, like.device.name).Bind(4, PlanKey(like.plan));
  const int step = find.Step();
  if (step == SQLITE_DONE) return std::optional<std::pair<HistoryRun, Baseline>>();
  if (step != SQLITE_ROW) return DbError(db_, path_, "cannot read the history");

  HistoryRun run{find.Int(0), find.Text(1), find.Text(2), find.Text(3), find.Text(4), find.Int(5) != 0, find.Real(6)};
  Baseline b;
  b.backend = like.backend;
  b.plan = like.plan;
  b.version = run.version;
  b.commit = run.commit;
  b.made_at = run.made_at;
  const std::string source = fmt::format("{} (run {})", path_.string(), run.id);
  DB_ASSIGN_OR_RETURN(nlohmann::json device_json, JsonReader::Parse(find.Text(7), source));
  DB_ASSIGN_OR_RETURN(b.device, DeviceFromJson(JsonReader(device_json, source)));

  Statement bands(db_,
                  "SELECT cell, band, total_p999, total_max, arith_p999, arith_max, judged, nan, inf,"
                  " worst_index, first_nonfinite_index FROM figures WHERE run_id = ? AND backend = ?");
  if (!bands.ok()) return DbError(db_, path_, "cannot read the history");
  bands.Bind(1, run.id).Bind(2, like.backend);
  int row;
  while ((row = bands.Step()) == SQLITE_ROW) {
    BandFigures f;
    f.total_p999 = bands.Real(2);
    f.total_max = bands.Real(3);
    f.arith_p999 = bands.Real(4);
    f.arith_max = bands.Real(5);
    f.judged = static_cast<std::uint64_t>(bands.Int(6));
    f.nan = static_cast<std::uint64_t>(bands.Int(7));
    f.inf = static_cast<std::uint64_t>(bands.Int(8));
    f.worst_index = bands.Index(9);
    f.first_nonfinite_index = bands.Index(10);
    b.cells[bands.Text(0)][bands.Text(1)] = f;
  }
  if (row != SQLITE_DONE) return DbError(db_, path_, "cannot read the history");
  return std::optional<std::pair<HistoryRun, Baseline>>(std::pair{std::move(run), std::move(b)});
}

Expected<std::vector<TrendPoint>> History::Trend(std::int64_t run_id, const Baseline& like, int limit) {
  Statement trend(db_,
                  "WITH chosen AS (SELECT r.id FROM runs r JOIN run_backends b ON b.run_id = r.id"
                  "   WHERE r.id <= ?1 AND b.backend = ?2 AND b.device_name = ?3 AND b.plan = ?4"
                  "   ORDER BY r.id DESC LIMIT ?5)"
                  " SELECT r.id, r.made_at, r.commit_id, f.cell, f.total_p999, f.total_max, f.nan + f.inf"
                  " FROM figures f JOIN runs r ON r.id = f.run_id"
                  " WHERE f.run_id IN chosen AND f.backend = ?2 AND f.band = 'all'"
                  " ORDER BY r.id, f.cell");
  if (!trend.ok()) return DbError(db_, path_, "cannot read the history");
  trend.Bind(1, run_id).Bind(2, like.backend).Bind(3, like.device.name).Bind(4, PlanKey(like.plan));
  trend.Bind(5, std::int64_t{limit});
  std::vector<TrendPoint> points;
  int row;
  while ((row = trend.Step()) == SQLITE_ROW) {
    points.push_back({trend.Int(0), trend.Text(1), trend.Text(2), like.backend, trend.Text(3), trend.Real(4),
                      trend.Real(5), static_cast<std::uint64_t>(trend.Int(6))});
  }
  if (row != SQLITE_DONE) return DbError(db_, path_, "cannot read the history");
  return points;
}

Expected<std::int64_t> History::RunCount() {
  Statement count(db_, "SELECT count(*) FROM runs");
  if (!count.ok() || count.Step() != SQLITE_ROW) return DbError(db_, path_, "cannot read the history");
  return count.Int(0);
}

}  // namespace depthbench
