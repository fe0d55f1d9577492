#include "bench/backends/vulkan/graphics_pipeline.h"

#include <array>

namespace depthbench {

Expected<DeviceObject<VkPipeline>> CreateGraphicsPipeline(VkDevice device, VkPipelineLayout layout,
                                                          const DrawState& state, const std::string& what) {
  std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
  for (VkPipelineShaderStageCreateInfo& stage : stages) {
    stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stage.pName = "main";
  }
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = state.vertex;
  stages[0].pSpecializationInfo = state.vertex_constants;
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = state.fragment;
  stages[1].pSpecializationInfo = state.fragment_constants;

  VkPipelineVertexInputStateCreateInfo vertex_input{};  // the shaders fetch their own vertices
  vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
  VkPipelineInputAssemblyStateCreateInfo assembly{};
  assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
  assembly.topology = state.topology;

  VkPipelineViewportDepthClipControlCreateInfoEXT clip_control{};
  clip_control.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_DEPTH_CLIP_CONTROL_CREATE_INFO_EXT;
  clip_control.negativeOneToOne = VK_TRUE;
  VkPipelineViewportStateCreateInfo viewport{};
  viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
  viewport.pNext = state.clip_minus_one ? &clip_control : nullptr;
  viewport.viewportCount = state.viewports;
  viewport.scissorCount = viewport.viewportCount;

  VkPipelineRasterizationStateCreateInfo rasterization{};
  rasterization.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
  rasterization.rasterizerDiscardEnable = state.rasterizer_discard ? VK_TRUE : VK_FALSE;
  rasterization.depthClampEnable = state.light_volume ? VK_TRUE : VK_FALSE;
  rasterization.polygonMode = VK_POLYGON_MODE_FILL;
  // The cube's faces are counter-clockwise seen from outside, in NDC with y
  // up; the viewport's negative height keeps that counter-clockwise in
  // framebuffer coordinates, so culling front faces leaves the back ones.
  rasterization.cullMode = state.light_volume ? VK_CULL_MODE_FRONT_BIT : VK_CULL_MODE_NONE;
  rasterization.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rasterization.lineWidth = 1.0f;

  VkPipelineMultisampleStateCreateInfo multisample{};
  multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;

  const bool has_depth = state.depth != VK_FORMAT_UNDEFINED;
  VkPipelineDepthStencilStateCreateInfo depth{};
  depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
  depth.depthTestEnable = has_depth ? VK_TRUE : VK_FALSE;
  depth.depthWriteEnable = has_depth ? VK_TRUE : VK_FALSE;
  depth.depthCompareOp = VK_COMPARE_OP_ALWAYS;  // one triangle a texel: whatever it rasterizes is stored

  std::vector<VkPipelineColorBlendAttachmentState> attachments(state.colors.size());
  for (VkPipelineColorBlendAttachmentState& attachment : attachments) {
    attachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT;
  }
  VkPipelineColorBlendStateCreateInfo blend{};
  blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
  blend.attachmentCount = static_cast<std::uint32_t>(attachments.size());
  blend.pAttachments = attachments.data();

  // Set per draw: the raster form's atlas viewport follows the batch's
  // size, and pass 2a's viewports are the samples'.
  const std::array<VkDynamicState, 2> dynamic_states = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic{};
  dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
  dynamic.dynamicStateCount = static_cast<std::uint32_t>(dynamic_states.size());
  dynamic.pDynamicStates = dynamic_states.data();

  VkPipelineRenderingCreateInfo rendering{};
  rendering.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
  rendering.colorAttachmentCount = static_cast<std::uint32_t>(state.colors.size());
  rendering.pColorAttachmentFormats = state.colors.data();
  rendering.depthAttachmentFormat = state.depth;

  VkGraphicsPipelineCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  info.pNext = &rendering;
  info.stageCount = static_cast<std::uint32_t>(stages.size());
  info.pStages = stages.data();
  info.pVertexInputState = &vertex_input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport;
  info.pRasterizationState = &rasterization;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blend;
  info.pDynamicState = &dynamic;
  info.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline),
                             "vkCreateGraphicsPipelines for " + what));
  return DeviceObject<VkPipeline>(device, pipeline, vkDestroyPipeline);
}

}  // namespace depthbench
