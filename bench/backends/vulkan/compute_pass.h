// ComputePass: what every pass of the bench owns and does the same way, the
// backend's reconstruction pass, its raster form and the speed timer's timed
// passes alike: a descriptor set (or several of one layout) with its
// layouts and push constants,
// pipelines over that layout (compute pipelines made here; the raster form
// makes graphics pipelines over the same layout), and a command buffer that
// is recorded, submitted and waited for.
//
// Lifecycle: Create(context, bindings, push-constant bytes, stages); point
// the set at resources with WriteDescriptors; CreatePipeline once per
// shader; then Submit(record) any number of times. Submit returns only when the device
// has finished (or failed) the work, so no work is in flight when the pass
// or the resources its commands used are destroyed. SubmitWithoutWaiting
// returns at once; the wait is then owed: Wait() pays it, and so do the
// next submission and the destructor, before they touch what the work uses.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/status.h"

namespace depthbench {

// Records a global memory barrier: writes of `from_access` in `from_stage`
// made visible to `to_access` in `to_stage`.
void RecordMemoryBarrier(VkCommandBuffer commands, VkPipelineStageFlags from_stage, VkAccessFlags from_access,
                         VkPipelineStageFlags to_stage, VkAccessFlags to_access);
// The same, for one image (its first mip level and layer), moving it from
// layout `from` to layout `to`.
void RecordImageBarrier(VkCommandBuffer commands, const VulkanImage& image, VkImageLayout from, VkImageLayout to,
                        VkPipelineStageFlags from_stage, VkAccessFlags from_access, VkPipelineStageFlags to_stage,
                        VkAccessFlags to_access);

// A shader module of `spirv`; `what` names the shader in errors.
Expected<DeviceObject<VkShaderModule>> CreateShaderModule(VkDevice device, std::span<const std::uint32_t> spirv,
                                                          const std::string& what);

class ComputePass {
 public:
  // `stages`: those that read the push constants. `sets`: how many sets of
  // the layout to hold (a pass that binds different resources per draw).
  // `slots`: how many submissions may be in flight at once, each with its
  // own command buffer and fence (the submitting calls name theirs).
  static Expected<std::unique_ptr<ComputePass>> Create(std::shared_ptr<VulkanContext> context,
                                                       std::span<const VkDescriptorSetLayoutBinding> bindings,
                                                       std::uint32_t push_constant_bytes,
                                                       VkShaderStageFlags stages = VK_SHADER_STAGE_COMPUTE_BIT,
                                                       std::uint32_t sets = 1, std::uint32_t slots = 1);
  ~ComputePass();
  ComputePass(const ComputePass&) = delete;
  ComputePass& operator=(const ComputePass&) = delete;

  VulkanContext& context() const { return *context_; }
  VkDevice device() const { return context_->device(); }
  VkPipelineLayout pipeline_layout() const { return pipeline_layout_.get(); }

  // A compute pipeline running `main` of `spirv` over this pass's layout;
  // `what` names the shader in errors.
  Expected<DeviceObject<VkPipeline>> CreatePipeline(std::span<const std::uint32_t> spirv,
                                                    const VkSpecializationInfo& specialization,
                                                    const std::string& what) const;

  // Points bindings of set `set` at resources: each write names its
  // binding, type and resource; the set is filled in here.
  void WriteDescriptors(std::span<VkWriteDescriptorSet> writes, std::uint32_t set = 0) const;

  // Binds the set, and `pipeline` unless it is null, for dispatches (or for
  // draws, with the graphics bind point).
  void Bind(VkCommandBuffer commands, VkPipeline pipeline,
            VkPipelineBindPoint bind_point = VK_PIPELINE_BIND_POINT_COMPUTE, std::uint32_t set = 0) const;
  // Pushes `bytes` of push constants (at most what Create reserved).
  void PushConstants(VkCommandBuffer commands, const void* data, std::uint32_t bytes) const;

  // Records commands through `record` into slot `slot`'s command buffer
  // (first waiting for its last submission), submits them and waits for
  // the device. Should the wait fail, the queue is drained before
  // returning.
  Status Submit(const std::function<void(VkCommandBuffer)>& record, std::uint32_t slot = 0);
  // The same, returning once the work is queued: the host may meanwhile
  // write other memory, and a later submission to the queue may wait for
  // it with a barrier. The descriptors and resources the commands use stay
  // untouched until Wait(slot).
  Status SubmitWithoutWaiting(const std::function<void(VkCommandBuffer)>& record, std::uint32_t slot = 0);
  // Waits for the work SubmitWithoutWaiting queued in `slot`, if any (at
  // once if the device has finished it). Should the wait fail, the queue
  // is drained.
  Status Wait(std::uint32_t slot = 0);
  // Whether `slot` holds work not yet waited for.
  bool pending(std::uint32_t slot = 0) const { return pending_[slot]; }

 private:
  ComputePass(std::shared_ptr<VulkanContext> context, VkShaderStageFlags stages)
      : context_(std::move(context)), stages_(stages) {}
  Status CreateLayout(std::span<const VkDescriptorSetLayoutBinding> bindings, std::uint32_t push_constant_bytes,
                      std::uint32_t sets);
  Status CreateCommandObjects(std::uint32_t slots);

  std::shared_ptr<VulkanContext> context_;  // first: everything below belongs to its device
  DeviceObject<VkDescriptorSetLayout> set_layout_;
  DeviceObject<VkPipelineLayout> pipeline_layout_;
  DeviceObject<VkDescriptorPool> pool_;
  std::vector<VkDescriptorSet> sets_;  // freed with the pool
  // Per slot: its fence, its command buffer (from the context's pool;
  // freed by the destructor), and whether it was queued by
  // SubmitWithoutWaiting and not waited for.
  std::vector<DeviceObject<VkFence>> fences_;
  std::vector<VkCommandBuffer> command_buffers_;
  std::vector<bool> pending_;
  VkShaderStageFlags stages_;
  std::uint32_t push_constant_bytes_ = 0;
};

}  // namespace depthbench
