// The device judge's workgroup shape, chosen from what the device allows
// (device_judge.cc defines it; its tests read the choice alone).
#pragma once

#include <cstdint>

#include <vulkan/vulkan.h>

#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/device_judge/device_judge.h"

namespace depthbench {

// judge.comp's specialization constants: its invocations, the consecutive
// samples of one accumulator it judges, the entries of its table of bins
// in shared memory, and whether it adds bins there first.
struct JudgeGroups {
  std::uint32_t invocations = 0;
  std::uint32_t samples = 0;
  std::uint32_t table_entries = 0;
  VkBool32 use_table = VK_FALSE;
  std::uint32_t candidates_per_row = 0;
};

JudgeGroups ChooseJudgeGroups(const VulkanDeviceProperties& device, DeviceJudgeTuning tuning);

// The 32-bit words of shared memory a workgroup of that shape declares
// (judge.glsl: the table, and a word per (slot, metric) of its running
// maxima).
std::uint32_t JudgeSharedWords(const JudgeGroups& groups);

}  // namespace depthbench
