#include "bench/pipeline/batch.h"

#include <algorithm>
#include <array>
#include <limits>

#include "bench/pipeline/bands.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/raster_model.h"
#include "bench/pipeline/shader_constants.h"

namespace depthbench {

RunLayout MakeRunLayout(std::span<const Cell> cells) {
  RunLayout layout;
  for (const Cell& cell : cells) {
    auto it = std::find(layout.encodings.begin(), layout.encodings.end(), cell.encoding());
    auto slot = static_cast<std::uint32_t>(it - layout.encodings.begin());
    if (it == layout.encodings.end()) layout.encodings.push_back(cell.encoding());
    std::uint32_t convention_slot = Info(cell.convention).hardware ? DepthSlot(cell.convention) : 0u;
    layout.cells.push_back({cell, slot, convention_slot});
  }
  return layout;
}

std::vector<std::uint32_t> PipelineOfSlots(std::span<const Encoding> encodings) {
  std::vector<std::uint32_t> pipeline_of_slot;
  std::vector<std::uint32_t> first_slots;  // of each pipeline
  for (std::uint32_t s = 0; s < encodings.size(); ++s) {
    auto shares = [&](std::uint32_t k) {
      const Encoding a = encodings[first_slots[k]], b = encodings[s];
      return a.convention == b.convention && Info(a.format).stores == Info(b.format).stores;
    };
    std::uint32_t k = 0;
    while (k < first_slots.size() && !shares(k)) ++k;
    if (k == first_slots.size()) first_slots.push_back(s);
    pipeline_of_slot.push_back(k);
  }
  return pipeline_of_slot;
}

namespace {

// The pipeline's float of the n samples whose entry in `floats` is NaN (in
// the raster form, where the model of the rasterizer had no geometry),
// gathered so that the four-lane production runs over them alone, as it
// would over contiguous samples: each lane's result is its own.
template <std::size_t kMost>
void ProduceWhereNaN(Encoding encoding, ProductionModel model, const DepthMappings& mapping, const double* eye_depth,
                     std::size_t n, float* floats) {
  // (Only the first m elements are read; the compiler cannot tell.)
  std::array<std::uint32_t, kMost> at{};
  std::array<double, kMost> near{}, far{}, a{}, b{}, depth{};
  std::array<float, kMost> produced{};
  std::size_t m = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (floats[i] == floats[i]) continue;
    at[m] = static_cast<std::uint32_t>(i);
    near[m] = mapping.near[i];
    far[m] = mapping.far[i];
    a[m] = mapping.a[i];
    b[m] = mapping.b[i];
    depth[m] = eye_depth[i];
    ++m;
  }
  PipelineFloats(encoding, model, {near.data(), far.data(), a.data(), b.data()}, depth.data(), m, produced.data());
  for (std::size_t j = 0; j < m; ++j) floats[at[j]] = produced[j];
}

}  // namespace

BatchBuilder::BatchBuilder(const SampleSource& sampler, std::vector<Encoding> encodings, Isa isa)
    : sampler_(sampler),
      encodings_(std::move(encodings)),
      model_(sampler.production()),
      isa_(isa),
      pipeline_of_slot_(PipelineOfSlots(encodings_)) {
  for (std::uint32_t s = 0; s < encodings_.size(); ++s) {
    if (pipeline_of_slot_[s] == pipeline_slots_.size()) pipeline_slots_.push_back(s);
  }
}

bool BatchBuilder::DevicesCanDraw() const {
  return sampler_.device_draw_seed().has_value() && model_ == ProductionModel::kFloat32;
}

void BatchBuilder::Build(std::uint64_t first, std::uint32_t count, Batch& batch, ThreadPool& pool, BatchFor judge,
                         DeviceJudgeInputs* device) const {
  const std::size_t slots = encodings_.size();
  const bool for_host = judge == BatchFor::kHostJudge;
  const bool device_draws = judge == BatchFor::kDeviceDraws && device != nullptr && DevicesCanDraw();
  if (device != nullptr) device->draw_seed = device_draws ? sampler_.device_draw_seed() : std::nullopt;
  batch.first_index = first;
  batch.count = count;
  batch.first_offset = static_cast<std::uint32_t>(first % kSamplesPerFrame);
  const std::uint64_t first_frame = first / kSamplesPerFrame;
  const std::size_t frames =
      count == 0 ? 0 : static_cast<std::size_t>((first + count - 1) / kSamplesPerFrame - first_frame + 1);

  // Frames: exact parameters and the shader constants computed from them.
  batch.frames.resize(frames);
  batch.distance_bands.resize(frames);
  batch.frame_params.resize(frames);
  batch.depth_params.resize(frames * kHardwareConventionCount);
  // Each chunk holds whole groups of the frames whose constants are
  // computed at once (only the batch's last group may be short).
  constexpr std::size_t kGroup = kShaderConstantsLanes;
  pool.ParallelFor((frames + kGroup - 1) / kGroup, [&](std::size_t begin, std::size_t end, unsigned) {
    const std::size_t first_f = begin * kGroup, end_f = std::min(frames, end * kGroup);
    for (std::size_t f = first_f; f < end_f; ++f) {
      Frame& frame = batch.frames[f];
      frame = sampler_.FrameAt(first_frame + f);
      batch.distance_bands[f] = static_cast<std::uint8_t>(DistanceBand(frame.camera_distance()));
    }
    const std::size_t n = end_f - first_f;
    BuildShaderConstants(
        std::span<const Frame>(batch.frames).subspan(first_f, n), sampler_.constants(),
        std::span(batch.frame_params).subspan(first_f, n),
        std::span(batch.depth_params).subspan(first_f * kHardwareConventionCount, n * kHardwareConventionCount));
  });

  // Samples: pixel, ray and depth pick; for the raster pipeline, the
  // geometry drawn, whose point under the pixel is the truth.
  // (None where the device draws them.)
  const bool raster = model_ == ProductionModel::kRaster;
  const std::uint32_t drawn = device_draws ? 0 : count;
  batch.raster.assign(raster ? count : 0, f32::RasterSample{});
  batch.pixels.resize(drawn);
  for (auto* v : {&batch.ray_x, &batch.ray_y, &batch.ray_z}) v->resize(drawn);
  const bool orthographic = !batch.frames.empty() && batch.frames.front().orthographic;  // a domain's are all alike
  for (auto* v : {&batch.offset_x, &batch.offset_y, &batch.offset_z}) v->resize(orthographic ? drawn : 0);
  // (A judge on the device produces float32 depths itself, and computes
  // from the frame and the ray what the reference needs beyond what was
  // drawn.)
  const bool host_produces = for_host || model_ != ProductionModel::kFloat32;
  const SampleFields fields = host_produces ? SampleFields::kAll : SampleFields::kDrawn;
  batch.samples.Resize(drawn, fields);
  pool.ParallelFor(
      drawn,
      [&](std::size_t begin, std::size_t end, unsigned) {
        std::uint32_t draw_of = std::numeric_limits<std::uint32_t>::max();  // the frame `draw` is of
        draw::DrawFrame draw;
        for (std::size_t i = begin; i < end; ++i) {
          const std::uint32_t frame_index = batch.FrameOf(static_cast<std::uint32_t>(i));
          const Frame& frame = batch.frames[frame_index];
          if (frame_index != draw_of) {
            draw = DrawFrameOf(frame);
            draw_of = frame_index;
          }
          PixelSample sample = sampler_.SampleAt(first + i, frame);
          if (raster) {
            const RasterGeometry geometry = MakeRasterGeometry(frame, sample);
            batch.raster[i] = geometry.sample;
            if (geometry.rendered_depth) sample.eye_depth = *geometry.rendered_depth;
          }
          batch.pixels[i] = sample.x | (sample.y << 16);
          const glm::dvec3 ray =
              orthographic ? -frame.rotation[2] : draw::draw_pixel_ray(sample.x, sample.y, draw);
          batch.ray_x[i] = ray.x;
          batch.ray_y[i] = ray.y;
          batch.ray_z[i] = ray.z;
          double offset_sq = 0.0;
          if (orthographic) {
            const glm::dvec3 offset = draw::draw_pixel_point(sample.x, sample.y, draw, 0.0);
            batch.offset_x[i] = offset.x;
            batch.offset_y[i] = offset.y;
            batch.offset_z[i] = offset.z;
            offset_sq = glm::dot(offset, offset);
          }
          if (fields == SampleFields::kAll) {
            batch.samples.Set(i, frame, sample, ray, offset_sq);
          } else {
            batch.samples.SetDrawn(i, frame, sample);
          }
        }
      },
      256);

  // What each frame and depth slot stores for the stored-value picks: the
  // edges of a hardware or linear format are the same in every frame;
  // view z's depend on the frame's far plane.
  std::vector<std::array<StoredDepth, 4>> fixed_edges(frames == 0 ? 0 : slots);
  for (std::size_t s = 0; s < fixed_edges.size(); ++s) {
    for (int pick = 1; pick <= 4; ++pick) {
      fixed_edges[s][pick - 1] = EncodeEdge(encodings_[s], batch.frames.front(), static_cast<DepthPick>(pick));
    }
  }
  edges_.resize(frames * slots * 4);
  if (device != nullptr) device->edge_texels.resize(edges_.size());
  pool.ParallelFor(frames, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t f = begin; f < end; ++f) {
      for (std::size_t s = 0; s < slots; ++s) {
        const bool per_frame = Info(encodings_[s].format).stores == DepthInput::kViewZ;
        for (int pick = 1; pick <= 4; ++pick) {
          const std::size_t at = (f * slots + s) * 4 + pick - 1;
          edges_[at] = per_frame ? EncodeEdge(encodings_[s], batch.frames[f], static_cast<DepthPick>(pick))
                                 : fixed_edges[s][pick - 1];
          if (device != nullptr) device->edge_texels[at] = edges_[at].fetched;
        }
      }
    }
  });

  // The samples of each chunk that pick a stored value (a few percent),
  // listed once for every depth slot's loop below, where the host stores
  // the texels: [chunk * kChunk + k].
  const std::size_t chunks = (count + kChunk - 1) / kChunk;
  // The host stores the texels where it judges, and for the raster form,
  // whose device counts its own texels against the host's model's.
  const bool host_stores = for_host || raster;
  pick_samples_.resize(host_stores ? chunks * kChunk : 0);
  pick_counts_.resize(host_stores ? chunks : 0);
  pool.ParallelFor(host_stores ? chunks : 0, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t c = begin; c < end; ++c) {
      std::uint32_t* list = pick_samples_.data() + c * kChunk;
      std::uint32_t listed = 0;
      for (std::size_t i = c * kChunk; i < std::min<std::size_t>(count, (c + 1) * kChunk); ++i) {
        list[listed] = static_cast<std::uint32_t>(i);
        listed += batch.samples.pick[i] != DepthPick::kEyeDepth ? 1 : 0;
      }
      pick_counts_[c] = listed;
    }
  });

  // Encodings, in chunks of samples, each loop over arrays: per pipeline
  // (shared by a convention's formats) the mapping's float32 constants, the
  // pipeline's floats and the depths they denote; then per depth slot the
  // stored texels, their decode and the reference.
  const SampleArrays& samples = batch.samples;
  const std::size_t pipelines = pipeline_slots_.size();
  for (auto* v : {&mapping_a_, &mapping_b_}) v->resize(host_produces ? pipelines * count : 0);
  produced_.resize(for_host ? pipelines * count : 0);
  batch.pipeline_floats.resize(host_produces ? pipelines * count : 0);
  if (raster) {
    // The host's model of the rasterizer, where there is geometry; NaN
    // elsewhere, where the loop below keeps the compute form's float (such
    // a sample is not judged). One model per sample serves every pipeline.
    pool.ParallelFor(
        count,
        [&](std::size_t begin, std::size_t end, unsigned) {
          for (std::size_t i = begin; i < end; ++i) {
            const std::uint32_t frame = batch.FrameOf(static_cast<std::uint32_t>(i));
            RasterTexelModel model(batch.frame_params[frame], batch.pixels[i] & 0xffffu, batch.pixels[i] >> 16,
                                   batch.raster[i]);
            for (std::size_t k = 0; k < pipelines; ++k) {
              const Encoding encoding = encodings_[pipeline_slots_[k]];
              // Linear and view-z targets are drawn with the first convention's matrix.
              const std::size_t drawn_with =
                  Info(encoding.format).stores == DepthInput::kHardware ? DepthSlot(encoding.convention) : 0;
              batch.pipeline_floats[k * count + i] =
                  model.Value(encoding, batch.depth_params[frame * kHardwareConventionCount + drawn_with]);
            }
          }
        },
        256);
  }
  pool.ParallelFor(host_produces ? pipelines * chunks : 0, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t job = begin; job < end; ++job) {
      const std::size_t k = job / chunks;
      const std::size_t lo = (job % chunks) * kChunk, n = std::min<std::size_t>(count - lo, kChunk);
      const Encoding encoding = encodings_[pipeline_slots_[k]];
      const std::size_t convention = DepthSlot(encoding.convention);  // its DepthParams slot
      const DepthInput stores = Info(encoding.format).stores;
      // One frame's samples at a time: they share its constants.
      for (std::size_t i = lo; i < lo + n;) {
        const std::uint32_t frame = batch.FrameOf(static_cast<std::uint32_t>(i));
        const std::size_t frame_end =
            std::min<std::size_t>(lo + n, std::size_t{frame + 1} * kSamplesPerFrame - batch.first_offset);
        double a = 0.0, b = 0.0;
        if (stores == DepthInput::kHardware) {
          const f32::DepthParams& depth = batch.depth_params[frame * kHardwareConventionCount + convention];
          a = depth.coefficients.x;
          b = depth.coefficients.y;
        } else if (stores == DepthInput::kLinear) {
          a = batch.frame_params[frame].camera_position.w;
        }
        std::fill(mapping_a_.begin() + k * count + i, mapping_a_.begin() + k * count + frame_end, a);
        std::fill(mapping_b_.begin() + k * count + i, mapping_b_.begin() + k * count + frame_end, b);
        i = frame_end;
      }
      const DepthMappings mapping = MappingOf(batch, k).At(lo);
      float* floats = batch.pipeline_floats.data() + k * count + lo;
      if (raster) {
        ProduceWhereNaN<kChunk>(encoding, model_, mapping, samples.eye_depth.data() + lo, n, floats);
      } else {
        PipelineFloats(encoding, model_, mapping, samples.eye_depth.data() + lo, n, floats);
      }
      if (for_host) {
        DecodeEyeDepths(encoding, model_, mapping, floats, n, produced_.data() + k * count + lo, nullptr, isa_);
      }
    }
  });

  batch.depth_slots = static_cast<std::uint32_t>(slots);
  batch.depths.resize(host_stores ? slots * count : 0);
  batch.codes.resize(host_stores ? slots * count : 0);
  batch.reference.Resize(for_host ? slots * count : 0);
  pool.ParallelFor(host_stores ? slots * chunks : 0, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t job = begin; job < end; ++job) {
      const std::size_t s = job / chunks, chunk = job % chunks;
      const std::size_t lo = chunk * kChunk, n = std::min<std::size_t>(count - lo, kChunk);
      const std::size_t at = s * count + lo;
      StoreFloats(encodings_[s].format, batch.pipeline_floats.data() + pipeline_of_slot_[s] * count + lo, n,
                  batch.codes.data() + at, batch.depths.data() + at);
      for (std::uint32_t k = 0; k < pick_counts_[chunk]; ++k) {
        const std::uint32_t i = pick_samples_[chunk * kChunk + k];
        const StoredDepth& edge =
            edges_[(batch.FrameOf(i) * slots + s) * 4 + static_cast<std::size_t>(samples.pick[i]) - 1];
        batch.codes[s * count + i] = edge.code;
        batch.depths[s * count + i] = edge.fetched;
      }
      if (for_host) ReferenceChunk(batch, s, lo, n);
    }
  });
}

DepthMappings BatchBuilder::MappingOf(const Batch& batch, std::size_t pipeline) const {
  return {batch.samples.near.data(), batch.samples.far.data(), mapping_a_.data() + pipeline * batch.count,
          mapping_b_.data() + pipeline * batch.count};
}

void BatchBuilder::ReferenceChunk(Batch& batch, std::size_t slot, std::size_t lo, std::size_t n) const {
  std::array<double, kChunk> denoted{};  // (every element is written below; the compiler cannot tell)
  const std::size_t count = batch.count, at = slot * count + lo, pipeline = pipeline_of_slot_[slot];
  const Encoding encoding = encodings_[slot];
  const DepthMappings mapping = MappingOf(batch, pipeline).At(lo);
  // A stored value that is its pipeline's float, bit for bit (a float32
  // texel's, but for stored-value picks and a device's texels), denotes
  // the depth that float does, decoded already under the same mapping:
  // only the others are decoded, gathered, four lanes at a time as ever.
  const float* stored = batch.depths.data() + at;
  const float* produced_floats = batch.pipeline_floats.data() + pipeline * count + lo;
  std::array<std::uint32_t, kChunk> other;
  std::size_t others = 0;
  for (std::size_t i = 0; i < n; ++i) {
    other[others] = static_cast<std::uint32_t>(i);
    others += std::bit_cast<std::uint32_t>(stored[i]) != std::bit_cast<std::uint32_t>(produced_floats[i]) ? 1 : 0;
  }
  if (2 * others > n) {
    DecodeEyeDepths(encoding, model_, mapping, stored, n, denoted.data(), nullptr, isa_);
  } else {
    std::copy_n(produced_.data() + pipeline * count + lo, n, denoted.begin());
    if (others > 0) {
      std::array<float, kChunk> values;
      std::array<std::array<double, kChunk>, 4> gathered;
      const double* arrays[] = {mapping.near, mapping.far, mapping.a, mapping.b};
      for (std::size_t j = 0; j < others; ++j) {
        values[j] = stored[other[j]];
        for (int p = 0; p < 4; ++p) gathered[p][j] = arrays[p][other[j]];
      }
      std::array<double, kChunk> decoded;
      DecodeEyeDepths(encoding, model_,
                      {gathered[0].data(), gathered[1].data(), gathered[2].data(), gathered[3].data()}, values.data(),
                      others, decoded.data(), nullptr, isa_);
      for (std::size_t j = 0; j < others; ++j) denoted[other[j]] = decoded[j];
    }
  }
  References(encoding, batch.samples, lo, n, denoted.data(), produced_.data() + pipeline * count + lo, batch.reference,
             at, isa_);
  // Raster samples with nothing drawn have no point to judge.
  for (std::size_t i = lo; !batch.raster.empty() && i < lo + n; ++i) {
    if (batch.raster[i].triangle0.w == 0.0f) {
      batch.reference.status[at + i - lo] = ReferenceStatus::kDegenerate;
      batch.reference.inverse_distance_sq[at + i - lo] = 0.0;
    }
  }
}

void BatchBuilder::AdoptStoredDepths(Batch& batch, std::span<const std::uint32_t> codes, std::span<const float> fetched,
                                     std::span<const std::uint8_t> drawn, ThreadPool& pool) const {
  const std::size_t count = batch.count, slots = encodings_.size();
  for (std::size_t s = 0; s < slots; ++s) {
    for (std::size_t i = 0; i < count; ++i) {
      if (batch.raster[i].triangle0.w == 0.0f) continue;
      batch.codes[s * count + i] = codes[s * count + i];
      batch.depths[s * count + i] = fetched[s * count + i];
    }
  }
  const std::size_t chunks = (count + kChunk - 1) / kChunk;
  pool.ParallelFor(slots * chunks, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t job = begin; job < end; ++job) {
      const std::size_t lo = (job % chunks) * kChunk;
      const std::size_t slot = job / chunks, n = std::min<std::size_t>(count - lo, kChunk);
      ReferenceChunk(batch, slot, lo, n);
      // A texel the rasterizer left as cleared holds no depth of the
      // sample's: not judged, and counted apart.
      if (drawn.empty()) continue;
      for (std::size_t i = lo; i < lo + n; ++i) {
        if (drawn[slot * count + i] == 0) batch.reference.status[slot * count + i] = ReferenceStatus::kUndrawn;
      }
    }
  });
}

}  // namespace depthbench
