#include "bench/backends/vulkan/compute_pass.h"

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

namespace depthbench {

void RecordMemoryBarrier(VkCommandBuffer commands, VkPipelineStageFlags from_stage, VkAccessFlags from_access,
                         VkPipelineStageFlags to_stage, VkAccessFlags to_access) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = from_access;
  barrier.dstAccessMask = to_access;
  vkCmdPipelineBarrier(commands, from_stage, to_stage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

void RecordImageBarrier(VkCommandBuffer commands, const VulkanImage& image, VkImageLayout from, VkImageLayout to,
                        VkPipelineStageFlags from_stage, VkAccessFlags from_access, VkPipelineStageFlags to_stage,
                        VkAccessFlags to_access) {
  VkImageMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  barrier.srcAccessMask = from_access;
  barrier.dstAccessMask = to_access;
  barrier.oldLayout = from;
  barrier.newLayout = to;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image.image.get();
  barrier.subresourceRange = {image.aspect, 0, 1, 0, 1};
  vkCmdPipelineBarrier(commands, from_stage, to_stage, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

Expected<DeviceObject<VkShaderModule>> CreateShaderModule(VkDevice device, std::span<const std::uint32_t> spirv,
                                                          const std::string& what) {
  VkShaderModuleCreateInfo module_info{};
  module_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  module_info.codeSize = spirv.size() * sizeof(std::uint32_t);
  module_info.pCode = spirv.data();
  VkShaderModule module = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(
      CheckVk(vkCreateShaderModule(device, &module_info, nullptr, &module), "vkCreateShaderModule for " + what));
  return DeviceObject<VkShaderModule>(device, module, vkDestroyShaderModule);
}

Expected<std::unique_ptr<ComputePass>> ComputePass::Create(std::shared_ptr<VulkanContext> context,
                                                           std::span<const VkDescriptorSetLayoutBinding> bindings,
                                                           std::uint32_t push_constant_bytes, VkShaderStageFlags stages,
                                                           std::uint32_t sets, std::uint32_t slots) {
  if (context == nullptr) return InvalidArgument("a compute pass needs a Vulkan context");
  std::unique_ptr<ComputePass> pass(new ComputePass(std::move(context), stages));
  DB_RETURN_IF_ERROR(pass->CreateLayout(bindings, push_constant_bytes, sets));
  DB_RETURN_IF_ERROR(pass->CreateCommandObjects(std::max(slots, 1u)));
  return pass;
}

ComputePass::~ComputePass() {
  // Nothing is left in flight: no command buffer is pending.
  for (std::uint32_t slot = 0; slot < pending_.size(); ++slot) (void)Wait(slot);
  for (VkCommandBuffer& commands : command_buffers_) {
    if (commands != VK_NULL_HANDLE) vkFreeCommandBuffers(device(), context_->command_pool(), 1, &commands);
  }
}

Status ComputePass::CreateLayout(std::span<const VkDescriptorSetLayoutBinding> bindings,
                                 std::uint32_t push_constant_bytes, std::uint32_t sets) {
  push_constant_bytes_ = push_constant_bytes;
  VkDescriptorSetLayoutCreateInfo set_layout_info{};
  set_layout_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  set_layout_info.bindingCount = static_cast<std::uint32_t>(bindings.size());
  set_layout_info.pBindings = bindings.data();
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateDescriptorSetLayout(device(), &set_layout_info, nullptr, &set_layout),
                             "vkCreateDescriptorSetLayout"));
  set_layout_ = DeviceObject<VkDescriptorSetLayout>(device(), set_layout, vkDestroyDescriptorSetLayout);

  const VkPushConstantRange push_constants{stages_, 0, push_constant_bytes};
  VkPipelineLayoutCreateInfo pipeline_layout_info{};
  pipeline_layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pipeline_layout_info.setLayoutCount = 1;
  pipeline_layout_info.pSetLayouts = &set_layout;
  pipeline_layout_info.pushConstantRangeCount = push_constant_bytes > 0 ? 1 : 0;
  pipeline_layout_info.pPushConstantRanges = &push_constants;
  VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreatePipelineLayout(device(), &pipeline_layout_info, nullptr, &pipeline_layout),
                             "vkCreatePipelineLayout"));
  pipeline_layout_ = DeviceObject<VkPipelineLayout>(device(), pipeline_layout, vkDestroyPipelineLayout);

  // The pool holds exactly what the sets need, type by type.
  std::vector<VkDescriptorPoolSize> sizes;
  for (const VkDescriptorSetLayoutBinding& b : bindings) {
    auto it = std::find_if(sizes.begin(), sizes.end(), [&](const auto& s) { return s.type == b.descriptorType; });
    if (it == sizes.end()) {
      sizes.push_back({b.descriptorType, b.descriptorCount * sets});
    } else {
      it->descriptorCount += b.descriptorCount * sets;
    }
  }
  VkDescriptorPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  pool_info.maxSets = sets;
  pool_info.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
  pool_info.pPoolSizes = sizes.data();
  VkDescriptorPool pool = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateDescriptorPool(device(), &pool_info, nullptr, &pool), "vkCreateDescriptorPool"));
  pool_ = DeviceObject<VkDescriptorPool>(device(), pool, vkDestroyDescriptorPool);

  const std::vector<VkDescriptorSetLayout> layouts(sets, set_layout);
  sets_.resize(sets);
  VkDescriptorSetAllocateInfo set_info{};
  set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  set_info.descriptorPool = pool;
  set_info.descriptorSetCount = sets;
  set_info.pSetLayouts = layouts.data();
  DB_RETURN_IF_ERROR(CheckVk(vkAllocateDescriptorSets(device(), &set_info, sets_.data()), "vkAllocateDescriptorSets"));
  return Status::Ok();
}

Status ComputePass::CreateCommandObjects(std::uint32_t slots) {
  command_buffers_.assign(slots, VK_NULL_HANDLE);
  pending_.assign(slots, false);
  VkCommandBufferAllocateInfo command_info{};
  command_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  command_info.commandPool = context_->command_pool();
  command_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  command_info.commandBufferCount = 1;
  for (VkCommandBuffer& commands : command_buffers_) {
    DB_RETURN_IF_ERROR(
        CheckVk(vkAllocateCommandBuffers(device(), &command_info, &commands), "vkAllocateCommandBuffers"));
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence handle = VK_NULL_HANDLE;
    DB_RETURN_IF_ERROR(CheckVk(vkCreateFence(device(), &fence_info, nullptr, &handle), "vkCreateFence"));
    fences_.emplace_back(device(), handle, vkDestroyFence);
  }
  return Status::Ok();
}

Expected<DeviceObject<VkPipeline>> ComputePass::CreatePipeline(std::span<const std::uint32_t> spirv,
                                                               const VkSpecializationInfo& specialization,
                                                               const std::string& what) const {
  // The pipeline keeps what it needs; the module goes when this returns.
  DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> module, CreateShaderModule(device(), spirv, what));

  VkComputePipelineCreateInfo pipeline_info{};
  pipeline_info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  pipeline_info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  pipeline_info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipeline_info.stage.module = module.get();
  pipeline_info.stage.pName = "main";
  pipeline_info.stage.pSpecializationInfo = &specialization;
  pipeline_info.layout = pipeline_layout_.get();
  VkPipeline pipeline = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateComputePipelines(device(), VK_NULL_HANDLE, 1, &pipeline_info, nullptr, &pipeline),
                             "vkCreateComputePipelines for " + what));
  return DeviceObject<VkPipeline>(device(), pipeline, vkDestroyPipeline);
}

void ComputePass::WriteDescriptors(std::span<VkWriteDescriptorSet> writes, std::uint32_t set) const {
  for (VkWriteDescriptorSet& write : writes) {
    write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    write.dstSet = sets_[set];
    if (write.descriptorCount == 0) write.descriptorCount = 1;
  }
  vkUpdateDescriptorSets(device(), static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

void ComputePass::Bind(VkCommandBuffer commands, VkPipeline pipeline, VkPipelineBindPoint bind_point,
                       std::uint32_t set) const {
  if (pipeline != VK_NULL_HANDLE) vkCmdBindPipeline(commands, bind_point, pipeline);
  vkCmdBindDescriptorSets(commands, bind_point, pipeline_layout_.get(), 0, 1, &sets_[set], 0, nullptr);
}

void ComputePass::PushConstants(VkCommandBuffer commands, const void* data, std::uint32_t bytes) const {
  vkCmdPushConstants(commands, pipeline_layout_.get(), stages_, 0, std::min(bytes, push_constant_bytes_), data);
}

Status ComputePass::Submit(const std::function<void(VkCommandBuffer)>& record, std::uint32_t slot) {
  DB_RETURN_IF_ERROR(SubmitWithoutWaiting(record, slot));
  return Wait(slot);
}

Status ComputePass::SubmitWithoutWaiting(const std::function<void(VkCommandBuffer)>& record, std::uint32_t slot) {
  DB_RETURN_IF_ERROR(Wait(slot));
  VkCommandBuffer commands = command_buffers_[slot];
  VkCommandBufferBeginInfo begin_info{};
  begin_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin_info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  DB_RETURN_IF_ERROR(CheckVk(vkBeginCommandBuffer(commands, &begin_info), "vkBeginCommandBuffer"));
  record(commands);
  DB_RETURN_IF_ERROR(CheckVk(vkEndCommandBuffer(commands), "vkEndCommandBuffer"));
  const VkFence fence = fences_[slot].get();
  DB_RETURN_IF_ERROR(CheckVk(vkResetFences(device(), 1, &fence), "vkResetFences"));
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands;
  DB_RETURN_IF_ERROR(CheckVk(vkQueueSubmit(context_->queue(), 1, &submit, fence), "vkQueueSubmit"));
  pending_[slot] = true;
  return Status::Ok();
}

Status ComputePass::Wait(std::uint32_t slot) {
  if (!pending_[slot]) return Status::Ok();
  pending_[slot] = false;
  const VkFence fence = fences_[slot].get();
  const Status waited = CheckVk(
      vkWaitForFences(device(), 1, &fence, VK_TRUE, std::numeric_limits<std::uint64_t>::max()), "vkWaitForFences");
  // A wait that failed may leave the work running: drain the queue, so that
  // nothing it uses is destroyed under it.
  if (!waited.ok()) vkQueueWaitIdle(context_->queue());
  return waited;
}

}  // namespace depthbench
