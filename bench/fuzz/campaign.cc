#include "bench/fuzz/campaign.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/interrupt.h"
#include "bench/pipeline/stats.h"

namespace depthbench {
namespace {

using Clock = std::chrono::steady_clock;

// A point whose every unit sits at 0 or at the top of its range with
// probability `snap`, elsewhere uniform: the extremes catalogue's corners.
FuzzPoint RandomPoint(std::mt19937_64& rng, double snap) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  FuzzPoint p;
  for (int k = 0; k < kFuzzUnits; ++k) {
    const double r = unit(rng);
    UnitOf(p, k) = r < snap / 2 ? 0.0 : r < snap ? 1.0 - 0x1.0p-53 : unit(rng);
  }
  return p;
}

// Moves a few units of a point: small steps in log scale, or a jump to an end.
FuzzPoint Mutate(FuzzPoint p, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> which(0, kFuzzUnits - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int moves = 1 + static_cast<int>(unit(rng) * 3);
  for (int m = 0; m < moves; ++m) {
    double& u = UnitOf(p, which(rng));
    const double r = unit(rng);
    if (r < 0.1) {
      u = r < 0.05 ? 0.0 : 1.0 - 0x1.0p-53;
    } else {
      const double step = std::exp2(-2.0 - 30.0 * unit(rng)) * (unit(rng) < 0.5 ? -1.0 : 1.0);
      u = std::clamp(u + step, 0.0, 1.0 - 0x1.0p-53);
    }
  }
  return p;
}

std::string Sanitized(std::string text) {
  for (char& c : text) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '_';
  }
  return text;
}

// Evaluates one case for one (cell, backend) pair.
Expected<Judgement> CheckOne(CaseChecker& checker, const FuzzCase& c) {
  CaseSource source(c);
  DB_RETURN_IF_ERROR(checker.Evaluate(source, 0, 1));
  return checker.At(0, 0, 0);
}

// Whether a shrunk case still lies in the domain the campaign drew from (a
// finding outside it would be about another question).
bool InDomain(const FuzzCase& c, const Domain& d) {
  const Frame& f = c.frame;
  const bool ratio_ok = d.far ? d.far->Contains(f.far) : d.ratio.Contains(f.ratio());
  return d.fov_degrees.Contains(f.fov_y_degrees) && d.aspect.Contains(f.aspect) && d.near.Contains(f.near) &&
         (!f.finite() || ratio_ok) && f.camera_distance() <= d.camera_distance.max &&
         (c.sample.pick != DepthPick::kEyeDepth ||
          (c.sample.eye_depth >= f.near && c.sample.eye_depth <= f.depth_limit));
}

// Simplifications tried in order; each is kept when the case stays in the
// domain and still fails with the same kind. What remains is the simplest
// failing case found.
Expected<FuzzCase> Shrink(CaseChecker& checker, FuzzCase c, FindingKind kind, const Domain& domain) {
  auto still_fails = [&](const FuzzCase& candidate) -> Expected<bool> {
    if (!InDomain(candidate, domain)) return false;
    DB_ASSIGN_OR_RETURN(Judgement j, CheckOne(checker, candidate));
    return j.violates() && j.kind() == kind;
  };
  auto round_to = [](double x, int digits) {
    if (!std::isfinite(x) || x == 0.0) return x;
    return std::stod(fmt::format("{:.{}g}", x, digits));
  };
  using Edit = std::function<void(FuzzCase&)>;
  const std::vector<Edit> edits = {
      [](FuzzCase& t) { t.frame.camera_position = glm::dvec3(0.0); },
      [](FuzzCase& t) { t.frame.rotation = glm::dmat3(1.0); },
      [](FuzzCase& t) {
        t.sample.x = t.frame.width / 2;
        t.sample.y = t.frame.height / 2;
      },
      [](FuzzCase& t) {
        t.sample.x = 0;
        t.sample.y = 0;
      },
      [](FuzzCase& t) {
        t.sample.x = static_cast<std::uint32_t>(std::uint64_t{t.sample.x} * 64 / t.frame.width);
        t.sample.y = static_cast<std::uint32_t>(std::uint64_t{t.sample.y} * 64 / t.frame.height);
        t.frame.width = t.frame.height = 64;
      },
      [](FuzzCase& t) { t.frame.volume_depth = t.frame.depth_limit; },
  };
  for (const Edit& edit : edits) {
    FuzzCase candidate = c;
    edit(candidate);
    CompleteFrame(candidate.frame, std::nullopt);
    DB_ASSIGN_OR_RETURN(bool fails, still_fails(candidate));
    if (fails) c = candidate;
  }
  // Fewer significant digits, from 1 up, for each number of the case.
  auto numbers = [](FuzzCase& t) -> std::vector<double*> {
    std::vector<double*> out = {&t.frame.fov_y_degrees, &t.frame.aspect, &t.frame.near, &t.frame.far,
                                &t.sample.eye_depth};
    for (int k = 0; k < 3; ++k) out.push_back(&t.frame.camera_position[k]);
    return out;
  };
  for (std::size_t n = 0; n < numbers(c).size(); ++n) {
    for (int digits = 1; digits <= 6; ++digits) {
      FuzzCase candidate = c;
      double* x = numbers(candidate)[n];
      *x = round_to(*x, digits);
      if (n >= 5) *x = static_cast<float>(*x);  // camera components stay float32 values
      if (!(candidate.frame.far > candidate.frame.near)) continue;
      CompleteFrame(candidate.frame, std::nullopt);
      candidate.frame.volume_depth =
          std::clamp(candidate.frame.volume_depth, candidate.frame.near, candidate.frame.depth_limit);
      DB_ASSIGN_OR_RETURN(bool fails, still_fails(candidate));
      if (fails) {
        c = candidate;
        break;
      }
    }
  }
  return c;
}

// Writes a finding's reproducer file: its case as found, or once shrunk.
Status WriteFinding(const CampaignFinding& finding) {
  ReproFile file;
  file.fuzz_case = finding.shrunk;
  file.cells = {finding.cell};
  file.backends = {finding.backend};
  const Judgement& j = finding.judgement;
  file.finding = {{"signature", finding.signature},
                  {"kind", FindingKindName(finding.kind)},
                  {"hits", finding.hits},
                  {"arith_error", JsonNumber(j.arith)},
                  {"bound", JsonNumber(j.bound)},
                  {"arith_bits_lost", JsonNumber(std::isfinite(j.arith) ? BitsLost(j.arith) : NAN)},
                  {"bound_bits_lost", JsonNumber(BitsLost(j.bound))}};
  return WriteReproFile(finding.file, file);
}

}  // namespace

Expected<std::vector<FuzzPoint>> ReadCorpus(const std::vector<std::filesystem::path>& paths) {
  std::vector<FuzzPoint> points;
  for (const auto& path : paths) {
    std::error_code ec;
    std::vector<std::filesystem::path> files;
    if (std::filesystem::is_directory(path, ec)) {
      for (const auto& entry : std::filesystem::directory_iterator(path, ec)) {
        if (entry.is_regular_file()) files.push_back(entry.path());
      }
      std::sort(files.begin(), files.end());
    } else {
      DB_RETURN_IF_ERROR(CheckReadableFile(path, kMaxSourceFileBytes).WithContext("--corpus"));
      files.push_back(path);
    }
    for (const auto& file : files) {
      DB_ASSIGN_OR_RETURN(std::string bytes, ReadFile(file, kMaxSourceFileBytes));
      points.push_back(DecodePoint({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}));
    }
  }
  return points;
}

// Shrinks each finding on its own cell and backend, then rewrites its file
// with the shrunk case and the final hit count. A signal stops this after
// the file in hand; the findings not reached keep the case as found.
Status ShrinkFindings(const CampaignOptions& options, const std::vector<Backend*>& backend_list,
                      CampaignResult& result) {
  for (CampaignFinding& finding : result.findings) {
    if (Interrupted()) break;
    Backend* backend = *std::find_if(backend_list.begin(), backend_list.end(),
                                     [&](Backend* b) { return b->name() == finding.backend; });
    DB_ASSIGN_OR_RETURN(CaseChecker one, CaseChecker::Make({finding.cell}, {backend}, 1));
    if (!options.proven.empty()) {
      const auto c = static_cast<std::size_t>(std::find(options.cells.begin(), options.cells.end(), finding.cell) -
                                              options.cells.begin());
      const auto b =
          static_cast<std::size_t>(std::find(backend_list.begin(), backend_list.end(), backend) - backend_list.begin());
      one.SetProvenBounds({options.proven[c * backend_list.size() + b]});
    }
    one.SetSampleBound(options.sample_bound);
    DB_ASSIGN_OR_RETURN(finding.shrunk, Shrink(one, finding.first, finding.kind, options.domain));
    DB_ASSIGN_OR_RETURN(finding.judgement, CheckOne(one, finding.shrunk));
    if (!options.out.empty()) DB_RETURN_IF_ERROR(WriteFinding(finding));
  }
  return Status::Ok();
}

namespace {

// One batch: each frame's point comes from one source (the corpus first,
// then mutations of the inputs closest to their bound, points near the
// domain's extremes, random points); its 64 samples vary the point's sample
// units (the first keeps them). Pinned units keep their values throughout.
PointBatch NextBatch(const CampaignOptions& options, std::uint32_t frames, const std::vector<FuzzPoint>& corpus,
                     std::size_t& corpus_next, const std::vector<std::pair<double, FuzzPoint>>& elite,
                     std::mt19937_64& rng, CampaignResult& result) {
  PointBatch batch(options.domain);
  for (std::uint32_t f = 0; f < frames; ++f) {
    FuzzPoint base;
    if (corpus_next < corpus.size()) {
      base = corpus[corpus_next++];
      ++result.from_corpus;
    } else {
      const double r = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      if (!elite.empty() && r < 0.5) {
        base = Mutate(elite[std::uniform_int_distribution<std::size_t>(0, elite.size() - 1)(rng)].second, rng);
        ++result.from_mutation;
      } else if (r < 0.75) {
        base = RandomPoint(rng, 0.5);
        ++result.from_extremes;
      } else {
        base = RandomPoint(rng, 0.0);
        ++result.from_random;
      }
    }
    for (const auto& [unit, value] : options.pinned) UnitOf(base, unit) = value;
    batch.AddFrame(base, [&](std::uint32_t s) {
      FuzzPoint p = base;
      if (s > 0) p.sample = (s % 2 ? Mutate(base, rng) : RandomPoint(rng, 0.3)).sample;
      for (const auto& [unit, value] : options.pinned) UnitOf(p, unit) = value;
      return p;
    });
  }
  return batch;
}

}  // namespace

Expected<CampaignResult> RunCampaign(const CampaignOptions& options, std::span<Backend* const> backends) {
  DB_RETURN_IF_ERROR(options.domain.Validate());
  if (options.seconds <= 0 && options.cases == 0)
    return InvalidArgument("give a time (--seconds) or a count (--cases)");
  DB_ASSIGN_OR_RETURN(std::vector<FuzzPoint> corpus, ReadCorpus(options.corpus));
  std::vector<Backend*> backend_list(backends.begin(), backends.end());
  DB_ASSIGN_OR_RETURN(CaseChecker checker, CaseChecker::Make(options.cells, backend_list));
  if (!options.proven.empty() && options.proven.size() != options.cells.size() * backend_list.size()) {
    return Internal("proven bounds for a different number of cells and backends");
  }
  checker.SetProvenBounds(options.proven);
  checker.SetSampleBound(options.sample_bound);
  if (!options.out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.out, ec);
    if (ec) return InvalidArgument(fmt::format("--out: cannot create '{}': {}", options.out.string(), ec.message()));
  }

  CampaignResult result;
  std::mt19937_64 rng(options.seed);
  std::map<std::string, std::size_t> by_signature;
  // The inputs that came closest to their bound, to mutate (ratio, point).
  std::vector<std::pair<double, FuzzPoint>> elite;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  std::size_t corpus_next = 0;
  const std::uint32_t frames = std::max<std::uint32_t>(1, options.frames_per_batch);

  // SIGINT or SIGTERM ends the campaign after the batch or the file in hand.
  while (!Interrupted()) {
    const double t = elapsed();
    if (options.seconds > 0 && t >= options.seconds) break;
    if (options.cases > 0 && result.cases >= options.cases) break;
    const PointBatch batch = NextBatch(options, frames, corpus, corpus_next, elite, rng, result);
    const CaseSource source = batch.Source();
    const std::uint32_t count = batch.count();
    DB_RETURN_IF_ERROR(checker.Evaluate(source, 0, count));
    result.cases += count;

    const std::size_t findings_before = result.findings.size();
    for (std::size_t c = 0; c < checker.cells().size(); ++c) {
      for (std::size_t b = 0; b < backend_list.size(); ++b) {
        for (std::uint32_t i = 0; i < count; ++i) {
          const Judgement& j = checker.At(c, b, i);
          if (!j.checked) continue;
          ++result.checks;
          if (!j.violates()) {
            const double ratio = j.arith / j.bound;
            if (ratio > result.closest) {
              result.closest = ratio;
              result.closest_cell = checker.cells()[c].Name();
            }
            if (ratio > 0.05) {
              elite.emplace_back(ratio, batch.point(i));
            }
            continue;
          }
          const std::string signature =
              fmt::format("{} {} {}", checker.cells()[c].Name(), backend_list[b]->name(), FindingKindName(j.kind()));
          auto [it, fresh] = by_signature.try_emplace(signature, result.findings.size());
          if (!fresh) {
            ++result.findings[it->second].hits;
            continue;
          }
          CampaignFinding finding;
          finding.signature = signature;
          finding.cell = checker.cells()[c];
          finding.backend = backend_list[b]->name();
          finding.kind = j.kind();
          finding.hits = 1;
          finding.first = batch.CaseOf(i);
          finding.first.sample.index = 0;
          // Until it is shrunk, the case as found is the reproducer.
          finding.shrunk = finding.first;
          finding.judgement = j;
          result.findings.push_back(std::move(finding));
        }
      }
    }
    // New findings are written at once, as found, so that a campaign
    // stopped later keeps them; shrinking waits for the end (it prepares
    // the shared backends for one cell at a time).
    for (std::size_t k = findings_before; k < result.findings.size() && !options.out.empty(); ++k) {
      CampaignFinding& finding = result.findings[k];
      finding.file = options.out / (Sanitized(finding.signature) + ".json");
      DB_RETURN_IF_ERROR(WriteFinding(finding));
    }
    // Keep the closest inputs only.
    if (elite.size() > 256) {
      std::partial_sort(elite.begin(), elite.begin() + 128, elite.end(),
                        [](const auto& a, const auto& b) { return a.first > b.first; });
      elite.resize(128);
    }
    if (options.progress) {
      const double fraction = options.seconds > 0 ? std::min(1.0, elapsed() / options.seconds)
                                                  : static_cast<double>(result.cases) / options.cases;
      options.progress(fraction, fmt::format("{} inputs, {} findings, {:.0f} inputs/s", result.cases,
                                             result.findings.size(), result.cases / std::max(elapsed(), 1e-9)));
    }
  }
  result.seconds = elapsed();
  result.sample_bound_reach = checker.sample_bound_reach();

  DB_RETURN_IF_ERROR(ShrinkFindings(options, backend_list, result));
  return result;
}

}  // namespace depthbench
