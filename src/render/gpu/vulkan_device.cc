// The Vulkan compute device of the gpu engine: instance, device choice, memory, submission.
#include "render/gpu/vulkan_device.h"

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "posefilter/error.h"

namespace posefilter::render::gpu {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
const char* const kHowToGetOne =
    " (a GPU driver, or Mesa's CPU driver lavapipe: Debian package mesa-vulkan-drivers, which "
    "scripts/setup.sh installs; or use --engine cpu)";

std::atomic<int> g_fault{int(Fault::kNone)};

std::mutex& SharedMutex() {
  static std::mutex m;
  return m;
}
// Kept for the life of the process (never destroyed at exit: drivers tear down their own
// state in static destructors too). Replaced after a device loss.
std::shared_ptr<VulkanDevice>*& SharedSlot() {
  static std::shared_ptr<VulkanDevice>* slot = new std::shared_ptr<VulkanDevice>();
  return slot;
}

std::string Check(VkResult r, const char* what) {
  return std::string("gpu engine: ") + what + " failed: " + ResultName(r);
}

const char* TypeName(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

int TypeRank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

bool ValidationRequested() {
  const char* v = std::getenv("POSEFILTER_VULKAN_VALIDATION");
  return v != nullptr && std::string(v) != "" && std::string(v) != "0";
}

bool LayerPresent(const char* name) {
  std::uint32_t n = 0;
  if (vkEnumerateInstanceLayerProperties(&n, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(n);
  if (vkEnumerateInstanceLayerProperties(&n, layers.data()) != VK_SUCCESS) return false;
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

}  // namespace

const char* ResultName(VkResult r) {
  switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    default: return "a Vulkan error";
  }
}

void VulkanDevice::InjectFault(Fault f) { g_fault.store(int(f)); }

std::shared_ptr<VulkanDevice> VulkanDevice::Shared() {
  std::lock_guard<std::mutex> lock(SharedMutex());
  std::shared_ptr<VulkanDevice>& slot = *SharedSlot();
  if (slot && !slot->lost()) return slot;
  std::shared_ptr<VulkanDevice> d(new VulkanDevice());
  d->Init();
  slot = d;
  return slot;
}

VKAPI_ATTR VkBool32 VKAPI_CALL VulkanDevice::OnMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                        VkDebugUtilsMessageTypeFlagsEXT,
                                                        const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<VulkanDevice*>(user);
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    std::lock_guard<std::mutex> lock(self->message_mutex_);
    if (self->validation_errors_++ == 0) self->first_error_ = data && data->pMessage ? data->pMessage : "";
  }
  return VK_FALSE;
}

void VulkanDevice::Init() {
  const bool validate = ValidationRequested();
  if (validate && !LayerPresent(kValidationLayer))
    throw Error(std::string("gpu engine: POSEFILTER_VULKAN_VALIDATION is set but the layer ") + kValidationLayer +
                " is not installed (Debian package vulkan-validationlayers)");
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "posefilter";
  app.apiVersion = VK_API_VERSION_1_1;
  std::vector<const char*> layers, extensions;
  if (validate) {
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = std::uint32_t(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = std::uint32_t(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  VkResult r = vkCreateInstance(&ici, nullptr, &instance_);
  if (r != VK_SUCCESS) throw Error(Check(r, "creating a Vulkan instance") + ": no Vulkan driver" + kHowToGetOne);
  if (validate) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mci.pfnUserCallback = &VulkanDevice::OnMessage;
    mci.pUserData = this;
    if (!create || create(instance_, &mci, nullptr, &validation_) != VK_SUCCESS)
      throw Error("gpu engine: could not install the validation messenger");
  }

  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  if (count > 0) vkEnumeratePhysicalDevices(instance_, &count, devices.data());
  if (devices.empty()) throw Error(std::string("gpu engine: no Vulkan device found") + kHowToGetOne);

  // Candidates: a compute queue, 64-bit integers and floats in shaders.
  struct Candidate {
    VkPhysicalDevice dev;
    std::uint32_t family;
    VkPhysicalDeviceProperties props;
  };
  std::vector<Candidate> ok;
  std::string rejected;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    VkPhysicalDeviceFeatures f;
    vkGetPhysicalDeviceFeatures(d, &f);
    std::uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> qs(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, qs.data());
    std::uint32_t family = UINT32_MAX;
    for (std::uint32_t i = 0; i < nq; ++i)
      if (qs[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
        family = i;
        break;
      }
    // Subgroup arithmetic in compute shaders (the sums' reduction, shaders/reduce.glsl).
    VkPhysicalDeviceSubgroupProperties sg{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    p2.pNext = &sg;
    if (p.apiVersion >= VK_API_VERSION_1_1) vkGetPhysicalDeviceProperties2(d, &p2);
    const bool subgroups = (sg.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                           (sg.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT);
    if (family == UINT32_MAX || !f.shaderInt64 || !f.shaderFloat64 || p.apiVersion < VK_API_VERSION_1_1 || !subgroups) {
      rejected += std::string(rejected.empty() ? "" : ", ") + p.deviceName;
      continue;
    }
    ok.push_back({d, family, p});
  }
  if (ok.empty())
    throw Error("gpu engine: no Vulkan 1.1 device with a compute queue, 64-bit shader integers and floats and "
                "subgroup arithmetic (seen: " +
                rejected + ")" + kHowToGetOne);
  const Candidate* pick = nullptr;
  if (const char* want = std::getenv("POSEFILTER_GPU_DEVICE"); want != nullptr && *want != '\0') {
    const std::string w = want;
    char* end = nullptr;
    const long idx = std::strtol(want, &end, 10);
    for (std::size_t i = 0; i < ok.size() && !pick; ++i) {
      const bool by_index = end && *end == '\0' && idx == long(i);
      if (by_index || std::string(ok[i].props.deviceName).find(w) != std::string::npos) pick = &ok[i];
    }
    if (!pick) throw Error("gpu engine: POSEFILTER_GPU_DEVICE='" + w + "' names no usable Vulkan device");
  } else {
    for (const Candidate& c : ok)
      if (!pick || TypeRank(c.props.deviceType) < TypeRank(pick->props.deviceType)) pick = &c;
  }
  physical_ = pick->dev;
  queue_family_ = pick->family;
  name_ = pick->props.deviceName;
  type_ = TypeName(pick->props.deviceType);
  max_storage_range_ = pick->props.limits.maxStorageBufferRange;
  max_group_count_ = std::min(pick->props.limits.maxComputeWorkGroupCount[0],
                              pick->props.limits.maxComputeWorkGroupCount[1]);
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkPhysicalDeviceFeatures features{};
  features.shaderInt64 = VK_TRUE;
  features.shaderFloat64 = VK_TRUE;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.pEnabledFeatures = &features;
  r = vkCreateDevice(physical_, &dci, nullptr, &device_);
  if (r != VK_SUCCESS) throw Error(Check(r, ("creating the device " + name_).c_str()));
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = queue_family_;
  r = vkCreateCommandPool(device_, &pci, nullptr, &upload_pool_);
  if (r != VK_SUCCESS) throw Error(Check(r, "creating a command pool"));
}

std::shared_ptr<void> VulkanDevice::Cached(const std::function<std::shared_ptr<void>()>& make) {
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (!cache_) cache_ = make();
  return cache_;
}

VulkanDevice::~VulkanDevice() {
  cache_.reset();  // its pipelines belong to device_
  if (device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    if (upload_pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, upload_pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (validation_ != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, validation_, nullptr);
  }
  if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

std::uint32_t VulkanDevice::MemoryType(std::uint32_t bits, VkMemoryPropertyFlags want,
                                       VkMemoryPropertyFlags avoid) const {
  for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    const VkMemoryPropertyFlags f = memory_.memoryTypes[i].propertyFlags;
    if ((bits & (1u << i)) && (f & want) == want && (f & avoid) == 0) return i;
  }
  return UINT32_MAX;
}

Buffer VulkanDevice::CreateBuffer(VkDeviceSize bytes, bool host) {
  Buffer b;
  b.size = bytes;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = bytes;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
              VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkResult r = vkCreateBuffer(device_, &bci, nullptr, &b.buffer);
  if (r != VK_SUCCESS) throw Error(Check(r, "creating a buffer"));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  std::uint32_t type = UINT32_MAX;
  if (host) {
    const VkMemoryPropertyFlags hv = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    type = MemoryType(req.memoryTypeBits, hv | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, 0);
    if (type == UINT32_MAX) type = MemoryType(req.memoryTypeBits, hv, 0);
  } else {
    type = MemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    if (type == UINT32_MAX) type = MemoryType(req.memoryTypeBits, 0, 0);
  }
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  r = type == UINT32_MAX ? VK_ERROR_OUT_OF_DEVICE_MEMORY : vkAllocateMemory(device_, &mai, nullptr, &b.memory);
  if (r != VK_SUCCESS) {
    vkDestroyBuffer(device_, b.buffer, nullptr);
    throw Error(Check(r, ("allocating " + std::to_string(bytes) + " bytes on " + name_).c_str()));
  }
  vkBindBufferMemory(device_, b.buffer, b.memory, 0);
  if (memory_.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
    r = vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped);
    if (r != VK_SUCCESS) b.mapped = nullptr;
  }
  return b;
}

void VulkanDevice::DestroyBuffer(Buffer* b) {
  if (b->buffer != VK_NULL_HANDLE) vkDestroyBuffer(device_, b->buffer, nullptr);
  if (b->memory != VK_NULL_HANDLE) vkFreeMemory(device_, b->memory, nullptr);
  *b = Buffer{};
}

void VulkanDevice::Upload(const Buffer& dst, const void* data, VkDeviceSize bytes) {
  if (bytes == 0) return;
  if (dst.mapped != nullptr) {
    std::memcpy(dst.mapped, data, bytes);
    VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    range.memory = dst.memory;
    range.size = VK_WHOLE_SIZE;
    vkFlushMappedMemoryRanges(device_, 1, &range);
    return;
  }
  Buffer staging = CreateBuffer(bytes, /*host=*/true);
  std::memcpy(staging.mapped, data, bytes);
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  // The upload pool and what is recorded from it belong to one upload at a time.
  std::lock_guard<std::mutex> upload_lock(upload_mutex_);
  {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = upload_pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    vkAllocateCommandBuffers(device_, &ai, &cmd);
  }
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &bi);
  VkBufferCopy copy{0, 0, bytes};
  vkCmdCopyBuffer(cmd, staging.buffer, dst.buffer, 1, &copy);
  vkEndCommandBuffer(cmd);
  try {
    SubmitAndWait(cmd, 60.0);
  } catch (...) {
    vkFreeCommandBuffers(device_, upload_pool_, 1, &cmd);
    DestroyBuffer(&staging);
    throw;
  }
  vkFreeCommandBuffers(device_, upload_pool_, 1, &cmd);
  DestroyBuffer(&staging);
}

void VulkanDevice::SubmitAndWait(VkCommandBuffer cmd, double timeout_s) {
  const Fault fault = Fault(g_fault.exchange(int(Fault::kNone)));
  if (fault == Fault::kDeviceLost) {
    lost_ = true;
    throw Error("gpu engine: the Vulkan device " + name_ + " was lost while weighing (VK_ERROR_DEVICE_LOST, injected); "
                "the estimate stops here (rerun, or use --engine cpu)");
  }
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  VkResult r = vkCreateFence(device_, &fci, nullptr, &fence);
  if (r != VK_SUCCESS) throw Error(Check(r, "creating a fence"));
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    r = vkQueueSubmit(queue_, 1, &si, fence);
  }
  if (r == VK_SUCCESS && fault == Fault::kNone)
    r = vkWaitForFences(device_, 1, &fence, VK_TRUE, std::uint64_t(timeout_s * 1e9));
  else if (r == VK_SUCCESS)
    r = VK_TIMEOUT;  // injected
  if (r == VK_TIMEOUT) {
    // The work may still be running: wait for it before the caller frees its buffers. A device
    // that never finishes is then reported lost by the driver, or by the second wait's timeout.
    const VkResult again = vkWaitForFences(device_, 1, &fence, VK_TRUE, std::uint64_t(timeout_s * 1e9));
    vkDestroyFence(device_, fence, nullptr);
    lost_ = true;
    throw Error("gpu engine: the device " + name_ + " did not finish a weighing batch within " +
                std::to_string(int(timeout_s)) + " s (" + (fault == Fault::kTimeout ? "injected" : ResultName(again)) +
                "); the estimate stops here (use --engine cpu)");
  }
  vkDestroyFence(device_, fence, nullptr);
  if (r == VK_ERROR_DEVICE_LOST) {
    lost_ = true;
    throw Error("gpu engine: the Vulkan device " + name_ + " was lost while weighing (VK_ERROR_DEVICE_LOST); "
                "the estimate stops here (rerun, or use --engine cpu)");
  }
  if (r != VK_SUCCESS) throw Error(Check(r, "submitting a weighing batch"));
}

int VulkanDevice::ValidationErrors() const {
  std::lock_guard<std::mutex> lock(message_mutex_);
  return validation_errors_;
}

std::string VulkanDevice::FirstValidationError() const {
  std::lock_guard<std::mutex> lock(message_mutex_);
  return first_error_;
}

}  // namespace posefilter::render::gpu
