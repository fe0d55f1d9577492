// VulkanContext: one Vulkan device ready for compute work, and for drawing
// where the device can. It owns the instance, the validation messenger (when
// validation is on), the chosen physical device, a logical device with one
// compute-capable queue (that can also draw, where one can), and a command
// pool for that queue, and it hands out host-visible buffers and
// device-local images.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <vulkan/vulkan.h>

#include "bench/base/status.h"
#include "bench/pipeline/device_info.h"

namespace depthbench {

// "VK_ERROR_DEVICE_LOST" for error messages.
std::string VkResultName(VkResult result);
// Unavailable("<what> failed: <VkResult name>") unless `result` is VK_SUCCESS.
Status CheckVk(VkResult result, const std::string& what);
// "cpu", "integrated gpu", "discrete gpu", "virtual gpu" or "other".
std::string DeviceTypeName(VkPhysicalDeviceType type);
// "1.3.230".
std::string VulkanVersionString(std::uint32_t version);

struct VulkanContextOptions {
  // Picks the device whose name contains this, ignoring case. Empty prefers
  // Mesa's lavapipe (a CPU implementation, here everywhere), else the first.
  std::string device;
  // Enables VK_LAYER_KHRONOS_validation and records what it reports. The
  // environment variable DEPTHBENCH_VALIDATION=1 turns it on as well.
  bool validation = false;
};

// What `depthbench list` shows about a device.
struct VulkanDeviceSummary {
  std::string name;    // "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string type;    // "cpu", "integrated gpu", "discrete gpu", "virtual gpu", "other"
  std::string driver;  // "llvmpipe Mesa 22.3.6 (LLVM 15.0.6)"
  std::string api;     // "1.3.230"
};

// Every Vulkan device the loader finds.
Expected<std::vector<VulkanDeviceSummary>> ListVulkanDevices();

// The properties of the chosen device that the backends use.
struct VulkanDeviceProperties {
  std::string name;
  std::string driver_name;  // VkPhysicalDeviceDriverProperties; empty before Vulkan 1.2
  std::string driver_info;
  VkDriverId driver_id = static_cast<VkDriverId>(0);
  std::uint32_t api_version = 0;
  std::uint32_t driver_version = 0;  // vendor-specific encoding
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  VkPhysicalDeviceLimits limits{};  // timestampPeriod, timestampComputeAndGraphics, dispatch and buffer limits
  std::uint32_t queue_family = 0;
  std::uint32_t queue_timestamp_valid_bits = 0;  // 0: the queue cannot write timestamps
  bool queue_graphics = false;                   // the queue can also draw

  // "<driverName> <driverInfo>", or the driver version where the device
  // does not report its driver.
  std::string DriverString() const;
};

// What results record about a Vulkan device (the backend's and the speed
// run's), with glslang as the shaders' compiler.
DeviceInfo DeviceInfoOf(const VulkanDeviceProperties& properties);

// Warnings and errors the validation layer reported. Shared between the
// context and its observers so that what the layer says while the context
// is destroyed (leaked objects) can still be read afterwards.
class ValidationLog {
 public:
  void Record(bool is_error, std::string message);
  std::vector<std::string> TakeMessages();
  // Errors recorded since the log was created; never decreases, so a caller
  // can tell whether errors arrived during an operation.
  std::uint64_t error_count() const;
  std::string last_error() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
  std::uint64_t error_count_ = 0;
  std::string last_error_;
};

// A Vulkan handle owned by a device: destroyed with the device's vkDestroy*
// (or vkFreeMemory) function when the owner goes away.
template <class Handle>
class DeviceObject {
 public:
  using Destroy = void (*)(VkDevice, Handle, const VkAllocationCallbacks*);

  DeviceObject() = default;
  DeviceObject(VkDevice device, Handle handle, Destroy destroy) : device_(device), handle_(handle), destroy_(destroy) {}
  DeviceObject(DeviceObject&& other) noexcept { *this = std::move(other); }
  DeviceObject& operator=(DeviceObject&& other) noexcept {
    if (this != &other) {
      Reset();
      device_ = std::exchange(other.device_, VK_NULL_HANDLE);
      handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
      destroy_ = std::exchange(other.destroy_, nullptr);
    }
    return *this;
  }
  DeviceObject(const DeviceObject&) = delete;
  DeviceObject& operator=(const DeviceObject&) = delete;
  ~DeviceObject() { Reset(); }

  Handle get() const { return handle_; }

  void Reset() {
    if (handle_ != VK_NULL_HANDLE) destroy_(device_, handle_, nullptr);
    handle_ = VK_NULL_HANDLE;
  }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  Handle handle_ = VK_NULL_HANDLE;
  Destroy destroy_ = nullptr;
};

// A buffer in host-visible memory, mapped for its whole life.
class VulkanBuffer {
 public:
  VulkanBuffer() = default;
  VulkanBuffer(VulkanBuffer&& other) noexcept;
  VulkanBuffer& operator=(VulkanBuffer&& other) noexcept;

  VkBuffer handle() const { return buffer_.get(); }
  VkDeviceSize size() const { return size_; }
  void* mapped() const { return mapped_; }

  // Make host writes visible to the device, and device writes (after a
  // host-read barrier and a fence) visible to the host; no-ops on coherent
  // memory.
  Status FlushHostWrites() const;
  Status InvalidateForHostReads() const;

 private:
  friend class VulkanContext;

  // Declared before the buffer so that the buffer is destroyed first.
  DeviceObject<VkDeviceMemory> memory_;
  DeviceObject<VkBuffer> buffer_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
  bool coherent_ = false;
};

// A 2D image of one mip level and layer in device-local memory, with a
// view of its whole `aspect`. Members are destroyed view first; Reset an
// image before assigning another to it (a move assigns the memory first).
struct VulkanImage {
  DeviceObject<VkDeviceMemory> memory;
  DeviceObject<VkImage> image;
  DeviceObject<VkImageView> view;
  VkExtent2D extent{};
  VkImageAspectFlags aspect = 0;

  void Reset() {
    view.Reset();
    image.Reset();
    memory.Reset();
  }
};

// What the raster form of the backend draws with, as the device offers it
// (each is enabled on the context's device where offered).
struct RasterFeatures {
  bool graphics_queue = false;          // the chosen queue can draw
  bool dynamic_rendering = false;       // Vulkan 1.3: drawing without render pass objects
  bool multi_viewport = false;          // pass 2a: every sample its own viewport
  bool viewport_index = false;          // shaderOutputViewportIndex: the vertex stage picks it
  bool depth_clamp = false;             // light volumes drawn without near and far clipping
  bool fragment_stores = false;         // fragmentStoresAndAtomics: positions written from the fragment stage
  bool depth_clip_control = false;      // VK_EXT_depth_clip_control: GL-style clip depth [-1, 1]
};

// What the speed timer's probe of the shader stages (GpuPassTimer::
// MeasureStages) can see on the device (each enabled where offered).
struct StageProbeFeatures {
  // vertexPipelineStoresAndAtomics: the vertex stage can count its own
  // invocations.
  bool vertex_stores = false;
  // VK_NV_shader_sm_builtins' shaderSMCount: how many processors the device
  // has, whose number each invocation can read (gl_SMIDNV); 0 where the
  // device does not name them.
  std::uint32_t processors = 0;
};

// How the host uses a buffer, which decides the memory type it lives in.
enum class HostAccess {
  kUpload,    // written by the host, read by shaders: coherent write-combined memory is best
  kReadback,  // written by shaders, read by the host: cached memory is much faster to read
  kNone,      // shaders' and transfer commands' alone: device-local memory, not mapped
};

class VulkanContext {
 public:
  static Expected<std::unique_ptr<VulkanContext>> Create(const VulkanContextOptions& options);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  VkCommandPool command_pool() const { return command_pool_; }
  const VulkanDeviceProperties& properties() const { return properties_; }
  // Whether shaders may use float64 (enabled wherever the device has it).
  bool shader_float64() const { return shader_float64_; }
  // Whether shaders may use 64-bit integers and their atomics on storage
  // buffers (enabled wherever the device has them).
  bool int64_atomics() const { return int64_atomics_; }
  const RasterFeatures& raster_features() const { return raster_features_; }
  const StageProbeFeatures& stage_probe_features() const { return stage_probe_features_; }

  bool validation_enabled() const { return validation_enabled_; }
  // The validation layer's warnings and errors since the last call.
  std::vector<std::string> TakeValidationMessages() { return validation_log_->TakeMessages(); }
  std::shared_ptr<ValidationLog> validation_log() const { return validation_log_; }

  // The first memory type allowed by `type_bits` that has every flag of the
  // earliest satisfiable entry of `candidates` (most preferred first).
  Expected<std::uint32_t> FindMemoryType(std::uint32_t type_bits,
                                         std::initializer_list<VkMemoryPropertyFlags> candidates) const;
  // A buffer of `size` bytes (> 0) in memory suited to `access`, mapped
  // unless the host has no access.
  Expected<VulkanBuffer> CreateHostBuffer(VkDeviceSize size, VkBufferUsageFlags usage, HostAccess access) const;
  // Makes `buffer` hold at least `bytes`: a larger one replaces it when it
  // holds fewer (its contents are lost), grown geometrically so that
  // batches that vary a little rarely reallocate. The device must not be
  // using the old buffer.
  Status GrowHostBuffer(VulkanBuffer& buffer, VkDeviceSize bytes, VkBufferUsageFlags usage, HostAccess access) const;
  // Memory for `requirements`, device-local where the device has it.
  Expected<DeviceObject<VkDeviceMemory>> AllocateDeviceLocal(const VkMemoryRequirements& requirements) const;
  // A sampler for texelFetch, which ignores filtering and addressing: it
  // only has to exist.
  Expected<DeviceObject<VkSampler>> CreateTexelSampler() const;
  // An optimally tiled image (layout undefined) and its view.
  Expected<VulkanImage> CreateImage(VkFormat format, VkExtent2D extent, VkImageUsageFlags usage,
                                    VkImageAspectFlags aspect) const;

 private:
  VulkanContext() = default;

  Status CreateInstance(bool validation);
  Status PickPhysicalDevice(const std::string& wanted);
  Status CreateDevice();

  std::shared_ptr<ValidationLog> validation_log_ = std::make_shared<ValidationLog>();
  bool validation_enabled_ = false;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VulkanDeviceProperties properties_;
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  bool shader_float64_ = false;
  bool int64_atomics_ = false;
  RasterFeatures raster_features_;
  StageProbeFeatures stage_probe_features_;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
};

// Watches the validation layer over one operation: Check fails with
// Internal, naming how many errors it reported and the last, when any
// arrived since the scope was made.
class ValidationScope {
 public:
  explicit ValidationScope(const VulkanContext& context);
  Status Check(std::string_view operation) const;

 private:
  std::shared_ptr<ValidationLog> log_;
  std::uint64_t errors_before_;
};

}  // namespace depthbench
