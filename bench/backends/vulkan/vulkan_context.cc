#include "bench/backends/vulkan/vulkan_context.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "bench/backends/vulkan/shader_compiler.h"

namespace depthbench {
namespace {

constexpr char kValidationLayer[] = "VK_LAYER_KHRONOS_validation";
constexpr char kValidationEnvironment[] = "DEPTHBENCH_VALIDATION";
// The SPIR-V the shaders compile to (1.3) needs Vulkan 1.1. The instance asks
// for 1.3 so that devices that have it report their driver's name and can
// render without render passes (the raster form, dynamic rendering).
constexpr std::uint32_t kMinimumDeviceApi = VK_API_VERSION_1_1;
constexpr std::uint32_t kInstanceApi = VK_API_VERSION_1_3;
constexpr char kDriverHint[] =
    "install mesa-vulkan-drivers for lavapipe (Mesa's CPU implementation), or point VK_ICD_FILENAMES "
    "at a driver's ICD manifest (e.g. /usr/share/vulkan/icd.d/lvp_icd.x86_64.json)";

std::string Lower(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower;
}

// DEPTHBENCH_VALIDATION: 1 on, 0 or unset off; anything else is refused
// ("yes" meant off, silently).
Expected<bool> ValidationRequestedByEnvironment() {
  const char* value = std::getenv(kValidationEnvironment);
  if (value == nullptr || std::string_view(value) == "0") return false;
  if (std::string_view(value) == "1") return true;
  return InvalidArgument(fmt::format("{}='{}': use 1 (validation on) or 0 (off)", kValidationEnvironment, value));
}

VKAPI_ATTR VkBool32 VKAPI_CALL RecordValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                       VkDebugUtilsMessageTypeFlagsEXT,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                       void* user_data) {
  const bool is_error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
  const char* message = data != nullptr && data->pMessage != nullptr ? data->pMessage : "(no message)";
  static_cast<ValidationLog*>(user_data)->Record(is_error,
                                                 fmt::format("[{}] {}", is_error ? "error" : "warning", message));
  // VK_FALSE: the call that triggered the message proceeds as the API says.
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT MessengerInfo(ValidationLog* log) {
  VkDebugUtilsMessengerCreateInfoEXT info{};
  info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = RecordValidationMessage;
  info.pUserData = log;
  return info;
}

Status CheckValidationLayerInstalled() {
  std::uint32_t count = 0;
  DB_RETURN_IF_ERROR(
      CheckVk(vkEnumerateInstanceLayerProperties(&count, nullptr), "vkEnumerateInstanceLayerProperties"));
  std::vector<VkLayerProperties> layers(count);
  DB_RETURN_IF_ERROR(
      CheckVk(vkEnumerateInstanceLayerProperties(&count, layers.data()), "vkEnumerateInstanceLayerProperties"));
  for (const VkLayerProperties& layer : layers) {
    if (std::strcmp(layer.layerName, kValidationLayer) == 0) return Status::Ok();
  }
  return Unavailable(
      fmt::format("Vulkan validation was requested (--validate or {}=1) but the layer {} is not "
                  "installed; install the Debian package vulkan-validationlayers",
                  kValidationEnvironment, kValidationLayer));
}

// An instance; with `messenger_info`, one with the validation layer whose
// messages during vkCreateInstance and vkDestroyInstance go to that
// messenger too.
Expected<VkInstance> NewInstance(const VkDebugUtilsMessengerCreateInfoEXT* messenger_info) {
  VkApplicationInfo application{};
  application.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  application.pApplicationName = "depthbench";
  application.pEngineName = "depthbench";
  application.apiVersion = kInstanceApi;

  const char* const layers[] = {kValidationLayer};
  const char* const extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pApplicationInfo = &application;
  if (messenger_info != nullptr) {
    info.pNext = messenger_info;
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = layers;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = extensions;
  }
  VkInstance instance = VK_NULL_HANDLE;
  const VkResult result = vkCreateInstance(&info, nullptr, &instance);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
    return Unavailable(
        fmt::format("no Vulkan driver found (vkCreateInstance: {}); {}", VkResultName(result), kDriverHint));
  }
  DB_RETURN_IF_ERROR(CheckVk(result, "vkCreateInstance"));
  return instance;
}

Expected<std::vector<VkPhysicalDevice>> EnumerateDevices(VkInstance instance) {
  std::uint32_t count = 0;
  DB_RETURN_IF_ERROR(CheckVk(vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices"));
  std::vector<VkPhysicalDevice> devices(count);
  DB_RETURN_IF_ERROR(
      CheckVk(vkEnumeratePhysicalDevices(instance, &count, devices.data()), "vkEnumeratePhysicalDevices"));
  devices.resize(count);
  if (devices.empty()) return Unavailable(fmt::format("no Vulkan devices found; {}", kDriverHint));
  return devices;
}

std::vector<VkQueueFamilyProperties> QueueFamilies(VkPhysicalDevice device) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  return families;
}

// The queue family the context uses: the first that can run compute,
// preferring one that can also draw (the raster form) and then one that can
// write timestamps.
std::optional<std::uint32_t> ChooseComputeQueueFamily(const std::vector<VkQueueFamilyProperties>& families) {
  std::optional<std::uint32_t> chosen;
  int best = -1;
  for (std::uint32_t i = 0; i < families.size(); ++i) {
    if ((families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) continue;
    const int score = ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) != 0 ? 2 : 0) +
                      (families[i].timestampValidBits > 0 ? 1 : 0);
    if (score > best) {
      best = score;
      chosen = i;
    }
  }
  return chosen;
}

// Fills `properties` (a structure of vkGetPhysicalDeviceProperties2's
// chain, its sType set) for `device`.
template <class Properties>
void QueryMoreProperties(VkPhysicalDevice device, Properties& properties) {
  VkPhysicalDeviceProperties2 chain{};
  chain.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  chain.pNext = &properties;
  vkGetPhysicalDeviceProperties2(device, &chain);
}

bool HasDeviceExtension(VkPhysicalDevice device, std::string_view name) {
  std::uint32_t count = 0;
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> extensions(count);
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data()) != VK_SUCCESS) return false;
  return std::any_of(extensions.begin(), extensions.end(),
                     [&](const VkExtensionProperties& e) { return name == e.extensionName; });
}

struct DeviceCandidate {
  VkPhysicalDevice handle = VK_NULL_HANDLE;
  VulkanDeviceProperties properties;
  bool has_compute_queue = false;
};

DeviceCandidate DescribeDevice(VkPhysicalDevice device) {
  DeviceCandidate candidate;
  candidate.handle = device;
  VulkanDeviceProperties& properties = candidate.properties;

  VkPhysicalDeviceProperties basic{};
  vkGetPhysicalDeviceProperties(device, &basic);
  properties.name = basic.deviceName;
  properties.api_version = basic.apiVersion;
  properties.driver_version = basic.driverVersion;
  properties.type = basic.deviceType;
  properties.limits = basic.limits;
  if (basic.apiVersion >= VK_API_VERSION_1_2) {
    VkPhysicalDeviceDriverProperties driver{};
    driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
    QueryMoreProperties(device, driver);
    properties.driver_id = driver.driverID;
    properties.driver_name = driver.driverName;
    properties.driver_info = driver.driverInfo;
  }

  const std::vector<VkQueueFamilyProperties> families = QueueFamilies(device);
  if (std::optional<std::uint32_t> family = ChooseComputeQueueFamily(families)) {
    candidate.has_compute_queue = true;
    properties.queue_family = *family;
    properties.queue_timestamp_valid_bits = families[*family].timestampValidBits;
    properties.queue_graphics = (families[*family].queueFlags & VK_QUEUE_GRAPHICS_BIT) != 0;
  }
  return candidate;
}

bool IsLavapipe(const VulkanDeviceProperties& properties) {
  return properties.driver_id == VK_DRIVER_ID_MESA_LLVMPIPE ||
         Lower(properties.name).find("llvmpipe") != std::string::npos;
}

// The candidate `wanted` names (a case-insensitive substring of the device
// name), or with no name lavapipe, else the first device.
Expected<const DeviceCandidate*> SelectDevice(const std::vector<DeviceCandidate>& candidates,
                                              const std::string& wanted) {
  if (wanted.empty()) {
    auto lavapipe = std::find_if(candidates.begin(), candidates.end(),
                                 [](const DeviceCandidate& c) { return IsLavapipe(c.properties); });
    return lavapipe != candidates.end() ? &*lavapipe : &candidates.front();
  }
  const std::string key = Lower(wanted);
  std::string available;
  for (const DeviceCandidate& candidate : candidates) {
    if (Lower(candidate.properties.name).find(key) != std::string::npos) return &candidate;
    available += (available.empty() ? "" : ", ") + candidate.properties.name;
  }
  return NotFound(fmt::format("no Vulkan device matches '{}'; available: {}", wanted, available));
}

}  // namespace

std::string DeviceTypeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated gpu";
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual gpu";
    default: return "other";
  }
}

std::string VkResultName(VkResult result) {
  switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_EVENT_SET: return "VK_EVENT_SET";
    case VK_EVENT_RESET: return "VK_EVENT_RESET";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_FRAGMENTED_POOL: return "VK_ERROR_FRAGMENTED_POOL";
    case VK_ERROR_UNKNOWN: return "VK_ERROR_UNKNOWN";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_ERROR_INVALID_EXTERNAL_HANDLE: return "VK_ERROR_INVALID_EXTERNAL_HANDLE";
    case VK_ERROR_FRAGMENTATION: return "VK_ERROR_FRAGMENTATION";
    case VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS: return "VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS";
    case VK_PIPELINE_COMPILE_REQUIRED: return "VK_PIPELINE_COMPILE_REQUIRED";
    case VK_ERROR_VALIDATION_FAILED_EXT: return "VK_ERROR_VALIDATION_FAILED_EXT";
    default: return fmt::format("VkResult({})", static_cast<int>(result));
  }
}

Status CheckVk(VkResult result, const std::string& what) {
  if (result == VK_SUCCESS) return Status::Ok();
  return Unavailable(fmt::format("{} failed: {}", what, VkResultName(result)));
}

std::string VulkanVersionString(std::uint32_t version) {
  return fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(version), VK_API_VERSION_MINOR(version),
                     VK_API_VERSION_PATCH(version));
}

std::string VulkanDeviceProperties::DriverString() const {
  if (driver_name.empty()) return fmt::format("driver version {:#x}", driver_version);
  return driver_info.empty() ? driver_name : driver_name + " " + driver_info;
}

Expected<std::vector<VulkanDeviceSummary>> ListVulkanDevices() {
  DB_ASSIGN_OR_RETURN(VkInstance instance, NewInstance(nullptr));
  Expected<std::vector<VkPhysicalDevice>> devices = EnumerateDevices(instance);
  std::vector<VulkanDeviceSummary> summaries;
  if (devices.ok()) {
    for (VkPhysicalDevice device : *devices) {
      const VulkanDeviceProperties properties = DescribeDevice(device).properties;
      summaries.push_back({properties.name, DeviceTypeName(properties.type), properties.DriverString(),
                           VulkanVersionString(properties.api_version)});
    }
  }
  vkDestroyInstance(instance, nullptr);
  if (!devices.ok()) return devices.status();
  return summaries;
}

void ValidationLog::Record(bool is_error, std::string message) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (is_error) {
    ++error_count_;
    last_error_ = message;
  }
  messages_.push_back(std::move(message));
}

std::vector<std::string> ValidationLog::TakeMessages() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(messages_, {});
}

std::uint64_t ValidationLog::error_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_count_;
}

std::string ValidationLog::last_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_error_;
}

VulkanBuffer::VulkanBuffer(VulkanBuffer&& other) noexcept { *this = std::move(other); }

VulkanBuffer& VulkanBuffer::operator=(VulkanBuffer&& other) noexcept {
  if (this != &other) {
    // The buffer goes before its memory, as the destructor does it.
    buffer_ = std::move(other.buffer_);
    memory_ = std::move(other.memory_);
    device_ = std::exchange(other.device_, VK_NULL_HANDLE);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, nullptr);
    coherent_ = std::exchange(other.coherent_, false);
  }
  return *this;
}

Status VulkanBuffer::FlushHostWrites() const {
  if (coherent_) return Status::Ok();
  const VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, memory_.get(), 0, VK_WHOLE_SIZE};
  return CheckVk(vkFlushMappedMemoryRanges(device_, 1, &range), "vkFlushMappedMemoryRanges");
}

Status VulkanBuffer::InvalidateForHostReads() const {
  if (coherent_) return Status::Ok();
  const VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, memory_.get(), 0, VK_WHOLE_SIZE};
  return CheckVk(vkInvalidateMappedMemoryRanges(device_, 1, &range), "vkInvalidateMappedMemoryRanges");
}

Expected<std::unique_ptr<VulkanContext>> VulkanContext::Create(const VulkanContextOptions& options) {
  std::unique_ptr<VulkanContext> context(new VulkanContext());
  DB_ASSIGN_OR_RETURN(const bool validation_by_environment, ValidationRequestedByEnvironment());
  DB_RETURN_IF_ERROR(context->CreateInstance(options.validation || validation_by_environment));
  DB_RETURN_IF_ERROR(context->PickPhysicalDevice(options.device));
  DB_RETURN_IF_ERROR(context->CreateDevice().WithContext(context->properties_.name));
  return context;
}

VulkanContext::~VulkanContext() {
  if (device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    if (command_pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, command_pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_ != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_, messenger_, nullptr);
  }
  if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

Status VulkanContext::CreateInstance(bool validation) {
  if (!validation) {
    DB_ASSIGN_OR_RETURN(instance_, NewInstance(nullptr));
    return Status::Ok();
  }
  DB_RETURN_IF_ERROR(CheckValidationLayerInstalled());
  const VkDebugUtilsMessengerCreateInfoEXT messenger_info = MessengerInfo(validation_log_.get());
  DB_ASSIGN_OR_RETURN(instance_, NewInstance(&messenger_info));
  validation_enabled_ = true;
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
  if (create == nullptr) {
    return Unavailable("vkCreateDebugUtilsMessengerEXT is missing although VK_EXT_debug_utils is enabled");
  }
  return CheckVk(create(instance_, &messenger_info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
}

Status VulkanContext::PickPhysicalDevice(const std::string& wanted) {
  DB_ASSIGN_OR_RETURN(const std::vector<VkPhysicalDevice> devices, EnumerateDevices(instance_));
  std::vector<DeviceCandidate> candidates;
  candidates.reserve(devices.size());
  for (VkPhysicalDevice device : devices) candidates.push_back(DescribeDevice(device));
  DB_ASSIGN_OR_RETURN(const DeviceCandidate* chosen, SelectDevice(candidates, wanted));

  const std::string& name = chosen->properties.name;
  if (!chosen->has_compute_queue) return Unavailable(fmt::format("Vulkan device '{}' has no compute queue", name));
  if (chosen->properties.api_version < kMinimumDeviceApi) {
    return Unavailable(fmt::format("Vulkan device '{}' supports Vulkan {}; depthbench needs {}", name,
                                   VulkanVersionString(chosen->properties.api_version),
                                   VulkanVersionString(kMinimumDeviceApi)));
  }
  physical_device_ = chosen->handle;
  properties_ = chosen->properties;
  vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);
  return Status::Ok();
}

Status VulkanContext::CreateDevice() {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{};
  queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  queue_info.queueFamilyIndex = properties_.queue_family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;

  VkDeviceCreateInfo device_info{};
  device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  device_info.queueCreateInfoCount = 1;
  device_info.pQueueCreateInfos = &queue_info;
  // float64 arithmetic, where the device has it: the exact-division probe
  // (arithmetic_probe.h) divides in float64. What the raster form draws
  // with, where the device has it; the raster form checks what it lacks
  // when it is prepared (RasterFeatures). Stores from the vertex stage and
  // the processors' numbers, for the speed timer's probe of the stages.
  VkPhysicalDeviceDepthClipControlFeaturesEXT clip_control{};
  clip_control.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DEPTH_CLIP_CONTROL_FEATURES_EXT;
  VkPhysicalDeviceVulkan13Features features13{};
  features13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
  VkPhysicalDeviceVulkan12Features features12{};
  features12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  VkPhysicalDeviceFeatures2 supported{};
  supported.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  const bool api12 = properties_.api_version >= VK_API_VERSION_1_2;
  const bool api13 = properties_.api_version >= VK_API_VERSION_1_3;
  const bool has_clip_control = HasDeviceExtension(physical_device_, VK_EXT_DEPTH_CLIP_CONTROL_EXTENSION_NAME);
  const bool has_sm_builtins = HasDeviceExtension(physical_device_, VK_NV_SHADER_SM_BUILTINS_EXTENSION_NAME);
  VkPhysicalDeviceShaderSMBuiltinsFeaturesNV sm_builtins{};
  sm_builtins.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_SM_BUILTINS_FEATURES_NV;
  // Only structures the device knows go into the chain.
  void** next = &supported.pNext;
  const auto chain = [&next](auto& features) {
    *next = &features;
    next = &features.pNext;
  };
  if (api12) chain(features12);
  if (api13) chain(features13);
  if (has_clip_control) chain(clip_control);
  if (has_sm_builtins) chain(sm_builtins);
  vkGetPhysicalDeviceFeatures2(physical_device_, &supported);
  const VkPhysicalDeviceFeatures& core = supported.features;
  shader_float64_ = core.shaderFloat64 == VK_TRUE;
  // The device judge (bench/device_judge/) counts with 64-bit atomics.
  int64_atomics_ = core.shaderInt64 == VK_TRUE && api12 && features12.shaderBufferInt64Atomics == VK_TRUE;
  raster_features_ = {.graphics_queue = properties_.queue_graphics,
                      .dynamic_rendering = api13 && features13.dynamicRendering == VK_TRUE,
                      .multi_viewport = core.multiViewport == VK_TRUE,
                      .viewport_index = api12 && features12.shaderOutputViewportIndex == VK_TRUE,
                      .depth_clamp = core.depthClamp == VK_TRUE,
                      .fragment_stores = core.fragmentStoresAndAtomics == VK_TRUE,
                      .depth_clip_control = has_clip_control && clip_control.depthClipControl == VK_TRUE};
  stage_probe_features_.vertex_stores = core.vertexPipelineStoresAndAtomics == VK_TRUE;
  if (has_sm_builtins && sm_builtins.shaderSMBuiltins == VK_TRUE) {
    VkPhysicalDeviceShaderSMBuiltinsPropertiesNV sm_properties{};
    sm_properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_SM_BUILTINS_PROPERTIES_NV;
    QueryMoreProperties(physical_device_, sm_properties);
    stage_probe_features_.processors = sm_properties.shaderSMCount;
  }
  // Enabling is the same chain with only what is wanted left on.
  VkPhysicalDeviceFeatures2 enabled{};
  enabled.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  enabled.pNext = supported.pNext;
  enabled.features.shaderFloat64 = core.shaderFloat64;
  enabled.features.shaderInt64 = core.shaderInt64;
  enabled.features.multiViewport = core.multiViewport;
  enabled.features.depthClamp = core.depthClamp;
  enabled.features.fragmentStoresAndAtomics = core.fragmentStoresAndAtomics;
  enabled.features.vertexPipelineStoresAndAtomics = core.vertexPipelineStoresAndAtomics;
  // Of the 1.2 and 1.3 features, only these three are wanted.
  const VkBool32 viewport_index = features12.shaderOutputViewportIndex;
  const VkBool32 int64_atomics = features12.shaderBufferInt64Atomics;
  void* const after12 = features12.pNext;
  features12 = VkPhysicalDeviceVulkan12Features{};
  features12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  features12.pNext = after12;
  features12.shaderOutputViewportIndex = viewport_index;
  features12.shaderBufferInt64Atomics = int64_atomics;
  const VkBool32 dynamic_rendering = features13.dynamicRendering;
  void* const after13 = features13.pNext;
  features13 = VkPhysicalDeviceVulkan13Features{};
  features13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
  features13.pNext = after13;
  features13.dynamicRendering = dynamic_rendering;
  std::vector<const char*> extensions;
  if (has_clip_control) extensions.push_back(VK_EXT_DEPTH_CLIP_CONTROL_EXTENSION_NAME);
  if (has_sm_builtins) extensions.push_back(VK_NV_SHADER_SM_BUILTINS_EXTENSION_NAME);
  device_info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  device_info.ppEnabledExtensionNames = extensions.data();
  device_info.pNext = &enabled;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateDevice(physical_device_, &device_info, nullptr, &device_), "vkCreateDevice"));
  vkGetDeviceQueue(device_, properties_.queue_family, 0, &queue_);

  VkCommandPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  // Backends re-record one command buffer per run.
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = properties_.queue_family;
  return CheckVk(vkCreateCommandPool(device_, &pool_info, nullptr, &command_pool_), "vkCreateCommandPool");
}

Expected<std::uint32_t> VulkanContext::FindMemoryType(std::uint32_t type_bits,
                                                      std::initializer_list<VkMemoryPropertyFlags> candidates) const {
  for (VkMemoryPropertyFlags wanted : candidates) {
    for (std::uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i) {
      const bool allowed = (type_bits & (1u << i)) != 0;
      if (allowed && (memory_properties_.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    }
  }
  return Unavailable(
      fmt::format("Vulkan device '{}' has no suitable memory type (allowed types {:#x})", properties_.name, type_bits));
}

Expected<VulkanBuffer> VulkanContext::CreateHostBuffer(VkDeviceSize size, VkBufferUsageFlags usage,
                                                       HostAccess access) const {
  VulkanBuffer buffer;
  buffer.device_ = device_;
  buffer.size_ = size;

  VkBufferCreateInfo buffer_info{};
  buffer_info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  buffer_info.size = size;
  buffer_info.usage = usage;
  buffer_info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer handle = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateBuffer(device_, &buffer_info, nullptr, &handle), "vkCreateBuffer"));
  buffer.buffer_ = DeviceObject<VkBuffer>(device_, handle, vkDestroyBuffer);

  VkMemoryRequirements requirements{};
  vkGetBufferMemoryRequirements(device_, handle, &requirements);
  constexpr VkMemoryPropertyFlags kVisible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
  constexpr VkMemoryPropertyFlags kCoherent = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  constexpr VkMemoryPropertyFlags kCached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  constexpr VkMemoryPropertyFlags kLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  // Most preferred first. Uploads go to device memory the host can write
  // (a GPU's BAR) where there is room, so that shaders read them without
  // crossing the bus again; a full BAR falls back to host memory.
  std::vector<VkMemoryPropertyFlags> candidates = {kLocal, 0};
  if (access == HostAccess::kReadback) {
    candidates = {kVisible | kCoherent | kCached, kVisible | kCached, kVisible | kCoherent, kVisible};
  } else if (access == HostAccess::kUpload) {
    candidates = {kLocal | kVisible | kCoherent, kVisible | kCoherent, kVisible};
  }
  VkDeviceMemory memory = VK_NULL_HANDLE;
  std::uint32_t memory_type = 0;
  VkResult result = VK_ERROR_OUT_OF_DEVICE_MEMORY;
  for (const VkMemoryPropertyFlags wanted : candidates) {
    Expected<std::uint32_t> type = FindMemoryType(requirements.memoryTypeBits, {wanted});
    if (!type.ok()) continue;
    memory_type = *type;
    VkMemoryAllocateInfo allocate_info{};
    allocate_info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate_info.allocationSize = requirements.size;
    allocate_info.memoryTypeIndex = memory_type;
    result = vkAllocateMemory(device_, &allocate_info, nullptr, &memory);
    if (result == VK_SUCCESS) break;
  }
  DB_RETURN_IF_ERROR(CheckVk(result, fmt::format("vkAllocateMemory of {} bytes", requirements.size)));
  buffer.memory_ = DeviceObject<VkDeviceMemory>(device_, memory, vkFreeMemory);
  DB_RETURN_IF_ERROR(CheckVk(vkBindBufferMemory(device_, handle, memory, 0), "vkBindBufferMemory"));
  if (access == HostAccess::kNone) return buffer;
  DB_RETURN_IF_ERROR(CheckVk(vkMapMemory(device_, memory, 0, VK_WHOLE_SIZE, 0, &buffer.mapped_), "vkMapMemory"));
  buffer.coherent_ = (memory_properties_.memoryTypes[memory_type].propertyFlags & kCoherent) != 0;
  return buffer;
}

Status VulkanContext::GrowHostBuffer(VulkanBuffer& buffer, VkDeviceSize bytes, VkBufferUsageFlags usage,
                                     HostAccess access) const {
  if (buffer.size() >= bytes) return Status::Ok();
  const VkDeviceSize size = std::max(bytes, buffer.size() + buffer.size() / 2);
  buffer = VulkanBuffer();
  DB_ASSIGN_OR_RETURN(buffer, CreateHostBuffer(size, usage, access));
  return Status::Ok();
}

Expected<DeviceObject<VkDeviceMemory>> VulkanContext::AllocateDeviceLocal(
    const VkMemoryRequirements& requirements) const {
  // Device-local first, as an engine places its render targets; a device
  // without it (none known) still runs.
  DB_ASSIGN_OR_RETURN(const std::uint32_t type,
                      FindMemoryType(requirements.memoryTypeBits,
                                     {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, VkMemoryPropertyFlags{0}}));
  VkMemoryAllocateInfo allocate_info{};
  allocate_info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  allocate_info.allocationSize = requirements.size;
  allocate_info.memoryTypeIndex = type;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkAllocateMemory(device_, &allocate_info, nullptr, &memory),
                             fmt::format("vkAllocateMemory of {} bytes", requirements.size)));
  return DeviceObject<VkDeviceMemory>(device_, memory, vkFreeMemory);
}

Expected<DeviceObject<VkSampler>> VulkanContext::CreateTexelSampler() const {
  VkSamplerCreateInfo sampler_info{};
  sampler_info.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  sampler_info.magFilter = VK_FILTER_NEAREST;
  sampler_info.minFilter = VK_FILTER_NEAREST;
  sampler_info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sampler_info.addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sampler_info.addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sampler_info.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VkSampler sampler = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateSampler(device_, &sampler_info, nullptr, &sampler), "vkCreateSampler"));
  return DeviceObject<VkSampler>(device_, sampler, vkDestroySampler);
}

Expected<VulkanImage> VulkanContext::CreateImage(VkFormat format, VkExtent2D extent, VkImageUsageFlags usage,
                                                 VkImageAspectFlags aspect) const {
  VkImageCreateInfo image_info{};
  image_info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  image_info.imageType = VK_IMAGE_TYPE_2D;
  image_info.format = format;
  image_info.extent = {extent.width, extent.height, 1};
  image_info.mipLevels = 1;
  image_info.arrayLayers = 1;
  image_info.samples = VK_SAMPLE_COUNT_1_BIT;
  image_info.tiling = VK_IMAGE_TILING_OPTIMAL;
  image_info.usage = usage;
  image_info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  image_info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage handle = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateImage(device_, &image_info, nullptr, &handle),
                             fmt::format("vkCreateImage of format {} {}x{}", static_cast<int>(format), extent.width,
                                         extent.height)));
  VulkanImage image;
  image.extent = extent;
  image.aspect = aspect;
  image.image = DeviceObject<VkImage>(device_, handle, vkDestroyImage);
  VkMemoryRequirements requirements{};
  vkGetImageMemoryRequirements(device_, handle, &requirements);
  DB_ASSIGN_OR_RETURN(image.memory, AllocateDeviceLocal(requirements));
  DB_RETURN_IF_ERROR(CheckVk(vkBindImageMemory(device_, handle, image.memory.get(), 0), "vkBindImageMemory"));
  VkImageViewCreateInfo view_info{};
  view_info.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  view_info.image = handle;
  view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view_info.format = format;
  view_info.subresourceRange = {aspect, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateImageView(device_, &view_info, nullptr, &view), "vkCreateImageView"));
  image.view = DeviceObject<VkImageView>(device_, view, vkDestroyImageView);
  return image;
}

DeviceInfo DeviceInfoOf(const VulkanDeviceProperties& properties) {
  return {.name = properties.name,
          .driver = properties.DriverString(),
          .api = "Vulkan " + VulkanVersionString(properties.api_version),
          .kind = properties.type == VK_PHYSICAL_DEVICE_TYPE_CPU ? DeviceKind::kCpu : DeviceKind::kGpu,
          .compiler = GlslangVersion()};
}

ValidationScope::ValidationScope(const VulkanContext& context)
    : log_(context.validation_log()), errors_before_(log_->error_count()) {}

Status ValidationScope::Check(std::string_view operation) const {
  const std::uint64_t errors = log_->error_count() - errors_before_;
  if (errors == 0) return Status::Ok();
  return Internal(fmt::format("the Vulkan validation layer reported {} error(s) during {}; the last: {}", errors,
                              operation, log_->last_error()));
}

}  // namespace depthbench
