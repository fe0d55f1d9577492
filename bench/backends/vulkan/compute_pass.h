// ComputePass: what every compute pass of the bench owns and does the same
// way, the backend's reconstruction pass and the speed timer's timed passes
// alike: one descriptor set with its layouts and push constants, compute
// pipelines over that layout, and a command buffer that is recorded,
// submitted and waited for.
//
// Lifecycle: Create(context, bindings, push-constant bytes); point the set
// at resources with WriteDescriptors; CreatePipeline once per shader; then
// Submit(record) any number of times. Submit returns only when the device
// has finished (or failed) the work, so no work is in flight when the pass
// or the resources its commands used are destroyed.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include <vulkan/vulkan.h>

#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/status.h"

namespace depthbench {

// Records a global memory barrier: writes of `from_access` in `from_stage`
// made visible to `to_access` in `to_stage`.
void RecordMemoryBarrier(VkCommandBuffer commands, VkPipelineStageFlags from_stage, VkAccessFlags from_access,
                         VkPipelineStageFlags to_stage, VkAccessFlags to_access);

class ComputePass {
 public:
  static Expected<std::unique_ptr<ComputePass>> Create(std::shared_ptr<VulkanContext> context,
                                                       std::span<const VkDescriptorSetLayoutBinding> bindings,
                                                       std::uint32_t push_constant_bytes);
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

  // Points bindings of the set at resources: each write names its binding,
  // type and resource; the set is filled in here.
  void WriteDescriptors(std::span<VkWriteDescriptorSet> writes) const;

  // Binds the set, and `pipeline` unless it is null, for dispatches.
  void Bind(VkCommandBuffer commands, VkPipeline pipeline) const;
  // Pushes `bytes` of push constants (at most what Create reserved).
  void PushConstants(VkCommandBuffer commands, const void* data, std::uint32_t bytes) const;

  // Records commands through `record`, submits them and waits for the
  // device. Should the wait fail, the queue is drained before returning.
  Status Submit(const std::function<void(VkCommandBuffer)>& record);

 private:
  explicit ComputePass(std::shared_ptr<VulkanContext> context) : context_(std::move(context)) {}
  Status CreateLayout(std::span<const VkDescriptorSetLayoutBinding> bindings, std::uint32_t push_constant_bytes);
  Status CreateCommandObjects();

  std::shared_ptr<VulkanContext> context_;  // first: everything below belongs to its device
  DeviceObject<VkDescriptorSetLayout> set_layout_;
  DeviceObject<VkPipelineLayout> pipeline_layout_;
  DeviceObject<VkDescriptorPool> pool_;
  VkDescriptorSet set_ = VK_NULL_HANDLE;  // freed with the pool
  DeviceObject<VkFence> fence_;
  VkCommandBuffer command_buffer_ = VK_NULL_HANDLE;  // from the context's pool; freed by the destructor
  std::uint32_t push_constant_bytes_ = 0;
};

}  // namespace depthbench
