#include "bench/choose/frame_cost.h"

#include <cmath>
#include <map>

#include <fmt/format.h>

namespace depthbench {
namespace {

double Pixels(Resolution r) { return static_cast<double>(r.width) * r.height; }

// The cell's ALU-bound timing at the timed resolution nearest the frame in
// pixels: a time per reconstruction hardly moves with the image's size
// once the image fills the device.
const GpuTiming* AluTiming(const SpeedResults& speed, const Cell& cell, Resolution frame) {
  const GpuTiming* best = nullptr;
  for (const GpuTiming& t : speed.gpu) {
    if (t.cell != cell || t.regime != Regime::kAlu || !(t.ns_per_pass.median > 0.0)) continue;
    const double distance = std::abs(std::log(t.pixels() / Pixels(frame)));
    if (best == nullptr || distance < std::abs(std::log(best->pixels() / Pixels(frame)))) best = &t;
  }
  return best;
}

}  // namespace

std::uint32_t AttachmentBytes(Format format, bool stencil) {
  if (Info(format).stores != DepthInput::kHardware || !stencil) return TexelBytes(format);
  return format == Format::kX8D24Unorm ? 4u : 2u * TexelBytes(format);
}

FrameBytes FrameBytesOf(const Cell& cell, bool stencil) {
  if (Info(cell.format).stores == DepthInput::kHardware) return {AttachmentBytes(cell.format, stencil), 0};
  return {AttachmentBytes(kLinearTestAttachment, stencil), TexelBytes(cell.format)};
}

Status CheckFrameCostable(const SpeedResults& speed, const std::string& source) {
  if (speed.bandwidth && speed.bandwidth->bytes_per_second() > 0.0) return Status();
  return InvalidArgument(fmt::format(
      "{}: this speed file has no bandwidth probe, so the bytes a format makes a frame move cannot be costed on "
      "{}; make a new one there: depthbench speed --quick --json FILE (about a minute on lavapipe)",
      source, speed.run.device.name));
}

Expected<FrameCost> FrameCostModel::Cost(const Cell& cell) const {
  DB_RETURN_IF_ERROR(CheckFrameCostable(*speed, source));
  const GpuTiming* alu = AluTiming(*speed, cell, frame);
  if (alu == nullptr) {
    return NotFound(fmt::format("{}: no ALU-bound timing of {}", source, cell.Name()));
  }
  FrameCost cost;
  cost.bytes = FrameBytesOf(cell, stencil);
  const double pixels = Pixels(frame);
  const BandwidthProbe& probe = *speed->bandwidth;
  cost.memory_us = cost.bytes.moved() * pixels / probe.bytes_per_second() * 1e6;
  cost.alu_us = alu->ns_per_reconstruction() * pixels * 1e-3;
  const double probe_relative_spread = probe.ns_per_pass.spread() / probe.ns_per_pass.median;
  cost.spread_us = alu->spread_ns_per_pixel() / alu->taps * pixels * 1e-3 + cost.memory_us * probe_relative_spread;
  return cost;
}

std::string FrameCostModel::Unit() const {
  return fmt::format("µs per {} frame on {}", ResolutionName(frame), speed->run.device.name);
}

CostLookup FrameCostLookup(FrameCostModel model) {
  const std::string unit = model.Unit();
  // The ALU part is a compute pass's; where the device draws far slower,
  // the cost's source says so.
  std::string source = model.source;
  if (model.speed->stages) {
    if (const std::optional<double> share = model.speed->stages->drawn_share(); share && *share < kSlowDrawnShare) {
      source += fmt::format(
          "; ALU from compute passes: a pass drawn by the rasterizer computes at {:.2g}% of their rate on this "
          "device (speed's stage probe)",
          100.0 * *share);
    }
  }
  return [model, unit, source](const Cell& cell) -> std::optional<CandidateCost> {
    Expected<FrameCost> cost = model.Cost(cell);
    if (!cost.ok()) return std::nullopt;
    CandidateCost c;
    c.value = cost->total_us();
    c.spread = cost->spread_us;
    c.unit = unit;
    c.source = source;
    c.bytes_per_pixel = cost->bytes.moved();
    c.parts = fmt::format("{} B/px moved: {:.3g} µs memory + {:.3g} µs ALU", cost->bytes.moved(), cost->memory_us,
                          cost->alu_us);
    return c;
  };
}

Expected<std::shared_ptr<const SpeedResults>> SpeedFileFor(const DeviceInfo& device, const std::string& named,
                                                           const Catalogue& catalogue, std::string& source) {
  if (!named.empty()) {
    DB_ASSIGN_OR_RETURN(SpeedResults speed, ReadSpeedResults(named, catalogue));
    DB_RETURN_IF_ERROR(CheckFrameCostable(speed, named));
    source = named;
    return std::make_shared<const SpeedResults>(std::move(speed));
  }
  DB_ASSIGN_OR_RETURN(const std::vector<std::filesystem::path> files, CommittedSpeedFiles());
  const DeviceInfo devices[] = {device};
  for (const std::filesystem::path& path : files) {
    DB_ASSIGN_OR_RETURN(SpeedResults speed, ReadSpeedResults(path, catalogue));
    if (!SpeedFileApplies(speed, false, devices) || !CheckFrameCostable(speed, path.string()).ok()) continue;
    source = path.string();
    return std::make_shared<const SpeedResults>(std::move(speed));
  }
  return std::shared_ptr<const SpeedResults>();
}

}  // namespace depthbench
