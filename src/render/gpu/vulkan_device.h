// src/render/gpu/vulkan_device.h — the Vulkan compute device the gpu engine weighs on
// (internal; built when POSEFILTER_VULKAN is on).
//
// One device per process, made on first use (VulkanDevice::Shared) and kept: creating a
// Vulkan instance and device costs tens of milliseconds, more than a whole tracked frame.
// Device selection: POSEFILTER_GPU_DEVICE (an index into vkEnumeratePhysicalDevices, or a
// substring of the device name) if set, else the first discrete GPU, else an integrated one,
// else any device with a compute queue (Mesa's lavapipe on a machine without a GPU). A usable
// device has Vulkan 1.1, 64-bit integers and floats in shaders, and subgroup arithmetic in
// compute shaders (every desktop GPU driver and lavapipe).
// Validation: POSEFILTER_VULKAN_VALIDATION=1 enables VK_LAYER_KHRONOS_validation and counts
// the error messages it reports (ValidationErrors); the tests run once with it set.
// The device holds no render state: every GpuKernel (gpu_kernel.h) owns its buffers,
// descriptor sets and command buffers; the device serialises only queue submissions.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

namespace posefilter::render::gpu {

// A buffer and its own memory allocation. `mapped` is non-null for host-visible memory.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  void* mapped = nullptr;
};

// Fault injection for tests: the next submission reports this instead of running.
enum class Fault { kNone, kDeviceLost, kTimeout };

class VulkanDevice {
 public:
  // The process's device, made on first use. Throws posefilter::Error naming what is missing
  // (no Vulkan loader or driver, no device with a compute queue and 64-bit integer and float
  // shader arithmetic) — the message says how to get one or to use --engine cpu. After a
  // device loss the next call makes a new device.
  static std::shared_ptr<VulkanDevice> Shared();
  ~VulkanDevice();
  VulkanDevice(const VulkanDevice&) = delete;
  VulkanDevice& operator=(const VulkanDevice&) = delete;

  VkDevice device() const { return device_; }
  const std::string& name() const { return name_; }
  // vkPhysicalDeviceProperties::deviceType as text: "discrete", "integrated", "cpu", ...
  const std::string& type() const { return type_; }
  std::uint32_t queue_family() const { return queue_family_; }
  // The largest storage buffer binding (maxStorageBufferRange, bytes).
  VkDeviceSize max_storage_range() const { return max_storage_range_; }
  std::uint32_t max_group_count() const { return max_group_count_; }

  // A buffer of `bytes` for storage and transfers: device-local, or host-visible and
  // coherent (`host`: written or read by the host every batch). Throws Error when the device
  // has no memory for it.
  Buffer CreateBuffer(VkDeviceSize bytes, bool host);
  void DestroyBuffer(Buffer* b);
  // Copies `bytes` of host memory into a device-local buffer (through a staging buffer unless
  // its memory is host-visible).
  void Upload(const Buffer& dst, const void* data, VkDeviceSize bytes);

  // Submits one command buffer and waits for it, at most `timeout_s` seconds. Throws Error on
  // a device loss (marking the device lost: Shared() then makes a new one) or a timeout.
  void SubmitAndWait(VkCommandBuffer cmd, double timeout_s);
  bool lost() const { return lost_; }

  // Error messages of the validation layer so far (0 when validation is off).
  int ValidationErrors() const;
  bool validation() const { return validation_ != VK_NULL_HANDLE; }
  // The first validation error's text ("" when none).
  std::string FirstValidationError() const;

  // Tests: the next SubmitAndWait reports `f` instead of running the work.
  static void InjectFault(Fault f);

  // The object `make` returns, made once per device and kept until the device goes (the gpu
  // kernel's compiled pipelines); destroyed before the device.
  std::shared_ptr<void> Cached(const std::function<std::shared_ptr<void>()>& make);

 private:
  VulkanDevice() = default;
  void Init();
  std::uint32_t MemoryType(std::uint32_t bits, VkMemoryPropertyFlags want, VkMemoryPropertyFlags avoid) const;
  static VKAPI_ATTR VkBool32 VKAPI_CALL OnMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT type,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT validation_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool upload_pool_ = VK_NULL_HANDLE;  // under upload_mutex_
  std::uint32_t queue_family_ = 0;
  VkPhysicalDeviceMemoryProperties memory_{};
  VkDeviceSize max_storage_range_ = 0;
  std::uint32_t max_group_count_ = 0;
  std::string name_, type_;
  std::atomic<bool> lost_{false};
  mutable std::mutex queue_mutex_;     // vkQueueSubmit
  std::mutex upload_mutex_;            // the upload pool and its command buffers
  mutable std::mutex message_mutex_;
  int validation_errors_ = 0;
  std::mutex cache_mutex_;
  std::shared_ptr<void> cache_;
  std::string first_error_;
};

// "VK_ERROR_DEVICE_LOST" etc. for a VkResult.
const char* ResultName(VkResult r);

}  // namespace posefilter::render::gpu
