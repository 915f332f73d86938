// The gpu engine's score kernel on Vulkan: buffers, pipelines and the three passes of a batch
// (gpu_kernel.h; the shaders are in shaders/, compiled to SPIR-V at build time).
#include "render/gpu_kernel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "posefilter/error.h"
#include "render/gpu/vulkan_device.h"
#include "render/gpu/shaders/jobs_spv.h"
#include "render/gpu/shaders/raster_big_spv.h"
#include "render/gpu/shaders/raster_spv.h"
#include "render/gpu/shaders/score_spv.h"
#include "render/gpu/shaders/vertex_spv.h"

namespace posefilter::render {

namespace {

using gpu::Buffer;
using gpu::VulkanDevice;

// Layouts shared with shaders/common.glsl.
constexpr std::uint32_t kParticleWords = 20;
constexpr std::uint32_t kResultWords = 16;
enum Sum { kInlier, kRaster, kOccluded, kDiffSum, kDiffCount, kEdge, kEdgeContinued, kFront };
constexpr std::uint32_t kFlagZBuffer = 1, kFlagHard = 2;
constexpr std::uint32_t kGroup = 64;  // local_size_x of every pass
constexpr std::uint32_t kScorePixels = 16;  // window pixels per invocation of score.comp
enum Binding { kVertices, kFaces, kDepth, kParticles, kVertexRecords, kZBuffer, kResults, kJobs, kJobGroups, kNumBindings };
// The passes, in the order a batch runs them.
enum Pass { kVertexPass, kRasterPass, kJobsPass, kRasterBigPass, kScorePass, kNumPasses };

struct Push {
  float fx, fy, cx, cy, near_m, thr1_m, inv_thr1, hard_thr_m, align_band_m, edge_band_m;
  std::int32_t num_vertices, num_faces, num_particles, depth_width, depth_height;
  std::uint32_t flags;
};

std::string Fail(VkResult r, const char* what) {
  return std::string("gpu engine: ") + what + " failed: " + gpu::ResultName(r);
}

// The compiled passes, one set per device (VulkanDevice::Cached).
struct Programs {
  VkDevice device = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkShaderModule modules[kNumPasses] = {};
  VkPipeline pipelines[kNumPasses] = {};
  ~Programs() {
    for (VkPipeline p : pipelines)
      if (p) vkDestroyPipeline(device, p, nullptr);
    for (VkShaderModule m : modules)
      if (m) vkDestroyShaderModule(device, m, nullptr);
    if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
    if (set_layout) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
  }
};

std::shared_ptr<Programs> MakePrograms(VkDevice device) {
  auto pr = std::make_shared<Programs>();
  pr->device = device;
  VkDescriptorSetLayoutBinding b[kNumBindings];
  for (int i = 0; i < kNumBindings; ++i)
    b[i] = VkDescriptorSetLayoutBinding{std::uint32_t(i), VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
                                        VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = kNumBindings;
  dl.pBindings = b;
  VkResult r = vkCreateDescriptorSetLayout(device, &dl, nullptr, &pr->set_layout);
  if (r != VK_SUCCESS) throw Error(Fail(r, "creating the descriptor set layout"));
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Push)};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &pr->set_layout;
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &range;
  r = vkCreatePipelineLayout(device, &pl, nullptr, &pr->layout);
  if (r != VK_SUCCESS) throw Error(Fail(r, "creating the pipeline layout"));
  const std::uint32_t* code[kNumPasses] = {kVertexSpv, kRasterSpv, kJobsSpv, kRasterBigSpv, kScoreSpv};
  const std::size_t bytes[kNumPasses] = {sizeof(kVertexSpv), sizeof(kRasterSpv), sizeof(kJobsSpv),
                                         sizeof(kRasterBigSpv), sizeof(kScoreSpv)};
  for (int i = 0; i < kNumPasses; ++i) {
    VkShaderModuleCreateInfo mi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    mi.codeSize = bytes[i];
    mi.pCode = code[i];
    r = vkCreateShaderModule(device, &mi, nullptr, &pr->modules[i]);
    if (r != VK_SUCCESS) throw Error(Fail(r, "loading a shader"));
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = pr->modules[i];
    ci.stage.pName = "main";
    ci.layout = pr->layout;
    r = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &pr->pipelines[i]);
    if (r != VK_SUCCESS) throw Error(Fail(r, "compiling a compute pipeline"));
  }
  return pr;
}

// The largest buffer binding the kernel uses on `dev`: the device's maxStorageBufferRange, or
// less where POSEFILTER_GPU_MAX_BUFFER_BYTES says so (bytes; a cap on the device memory a
// batch takes, and how tests reach the limits with small inputs).
VkDeviceSize BufferLimit(const VulkanDevice& dev) {
  VkDeviceSize limit = dev.max_storage_range();
  if (const char* cap = std::getenv("POSEFILTER_GPU_MAX_BUFFER_BYTES"); cap != nullptr && *cap != '\0') {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(cap, &end, 10);
    if (end == cap || *end != '\0' || v < 1024)
      throw Error(std::string("gpu engine: POSEFILTER_GPU_MAX_BUFFER_BYTES='") + cap +
                  "' is not a byte count of at least 1024");
    limit = std::min<VkDeviceSize>(limit, v);
  }
  return limit;
}

// Whether a and b point at the same model and scene depth arrays.
bool SameArrays(const ScoreKernelParams& a, const ScoreKernelParams& b) {
  return a.vertices == b.vertices && a.num_vertices == b.num_vertices && a.faces == b.faces &&
         a.num_faces == b.num_faces && a.depth == b.depth && a.depth_width == b.depth_width &&
         a.depth_height == b.depth_height;
}

// Whether a and b share the arrays and every setting of a batch (all but the pose and window).
bool SameSettings(const ScoreKernelParams& a, const ScoreKernelParams& b) {
  return SameArrays(a, b) && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.near_m == b.near_m && a.inlier.thr1_m == b.inlier.thr1_m && a.inlier.hard == b.inlier.hard &&
         a.inlier.hard_thr_m == b.inlier.hard_thr_m && a.zbuffer == b.zbuffer &&
         a.align_band_m == b.align_band_m && a.edge_band_m == b.edge_band_m;
}

}  // namespace

struct GpuKernel::Impl {
  std::shared_ptr<VulkanDevice> dev;
  std::shared_ptr<Programs> programs;
  ScoreKernelParams like;
  Buffer vertices, faces, depth;   // uploaded once
  Buffer particles, results;       // host-visible, per batch
  Buffer vrec, zbuf, jobs;         // device scratch, grown as needed
  Buffer job_groups;               // raster_big's indirect dispatch (3 words)
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkCommandPool cmd_pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  bool set_dirty = true;

  ~Impl() {
    if (!dev) return;  // the device could not be made
    VkDevice d = dev->device();
    if (cmd_pool) vkDestroyCommandPool(d, cmd_pool, nullptr);
    if (pool) vkDestroyDescriptorPool(d, pool, nullptr);
    for (Buffer* b : {&vertices, &faces, &depth, &particles, &results, &vrec, &zbuf, &jobs, &job_groups})
      dev->DestroyBuffer(b);
  }

  // Makes *b hold at least `bytes` (growing by half again), marking the descriptors stale.
  void Ensure(Buffer* b, VkDeviceSize bytes, bool host) {
    if (b->buffer != VK_NULL_HANDLE && b->size >= bytes) return;
    dev->DestroyBuffer(b);
    *b = dev->CreateBuffer(std::max<VkDeviceSize>(bytes + bytes / 2, 256), host);
    set_dirty = true;
  }

  void UpdateSet() {
    if (!set_dirty) return;
    VkDescriptorBufferInfo info[kNumBindings];
    const Buffer* bufs[kNumBindings] = {&vertices, &faces, &depth, &particles, &vrec, &zbuf, &results, &jobs, &job_groups};
    VkWriteDescriptorSet w[kNumBindings];
    for (int i = 0; i < kNumBindings; ++i) {
      info[i] = VkDescriptorBufferInfo{bufs[i]->buffer, 0, VK_WHOLE_SIZE};
      w[i] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w[i].dstSet = set;
      w[i].dstBinding = std::uint32_t(i);
      w[i].descriptorCount = 1;
      w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      w[i].pBufferInfo = &info[i];
    }
    vkUpdateDescriptorSets(dev->device(), kNumBindings, w, 0, nullptr);
    set_dirty = false;
  }

  void Barrier(VkAccessFlags src, VkAccessFlags dst, VkPipelineStageFlags from, VkPipelineStageFlags to) {
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = src;
    mb.dstAccessMask = dst;
    vkCmdPipelineBarrier(cmd, from, to, 0, 1, &mb, 0, nullptr, 0, nullptr);
  }

  void Dispatch(int pass, const Push& push, std::uint32_t groups_x, std::uint32_t groups_y) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, programs->pipelines[pass]);
    vkCmdPushConstants(cmd, programs->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Push), &push);
    vkCmdDispatch(cmd, std::max(groups_x, 1u), groups_y, 1);
  }

  // One batch of particles (indices into params) that fits the device's buffers.
  void RunBatch(const std::vector<ScoreKernelParams>& params, const std::vector<int>& idx,
                std::vector<ScoreKernelResult>* out, double timeout_s);
};

GpuKernel::GpuKernel(const ScoreKernelParams& like) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.dev = VulkanDevice::Shared();
  VkDevice device = m.dev->device();
  m.programs = std::static_pointer_cast<Programs>(m.dev->Cached([&] { return MakePrograms(device); }));
  m.like = like;
  if ((like.num_vertices > 0 && !like.vertices) || (like.num_faces > 0 && !like.faces) || like.num_vertices < 0 ||
      like.num_faces < 0)
    throw Error("gpu engine: the mesh arrays are missing");
  if (!like.depth || like.depth_width <= 0 || like.depth_height <= 0)
    throw Error("gpu engine: the scene depth is missing");
  // Checked once here: every later batch points at these same arrays (SameArrays).
  for (std::int64_t f = 0; f < 3 * std::int64_t(like.num_faces); ++f)
    if (like.faces[f] >= std::uint32_t(like.num_vertices))
      throw Error("gpu engine: face " + std::to_string(f / 3) + " has a vertex index out of range");
  const VkDeviceSize limit = BufferLimit(*m.dev);
  const VkDeviceSize vbytes = VkDeviceSize(like.num_vertices) * 3 * sizeof(float);
  const VkDeviceSize fbytes = VkDeviceSize(like.num_faces) * 3 * sizeof(std::uint32_t);
  const VkDeviceSize dbytes = VkDeviceSize(like.depth_width) * like.depth_height * sizeof(float);
  // One particle's vertex records (16 bytes a vertex) and large-face list (8 bytes a face) must
  // fit one binding each.
  if (vbytes > limit || fbytes > limit || VkDeviceSize(like.num_vertices) * 16 > limit ||
      4 + VkDeviceSize(like.num_faces) * 8 > limit || std::uint64_t(like.num_faces) / kGroup >= m.dev->max_group_count()) {
    std::ostringstream os;
    os << "gpu engine: the mesh (" << like.num_vertices << " vertices, " << like.num_faces
       << " faces) is too large for the device " << m.dev->name() << " (a storage buffer holds at most " << limit
       << " bytes: at most " << limit / 16 << " vertices and " << (limit - 4) / 8
       << " faces); simplify it (--lod) or use --engine cpu";
    throw Error(os.str());
  }
  if (dbytes > limit) throw Error("gpu engine: the depth image is too large for the device " + m.dev->name());
  m.vertices = m.dev->CreateBuffer(std::max<VkDeviceSize>(vbytes, 16), false);
  m.faces = m.dev->CreateBuffer(std::max<VkDeviceSize>(fbytes, 16), false);
  m.depth = m.dev->CreateBuffer(dbytes, false);
  m.dev->Upload(m.vertices, like.vertices, vbytes);
  m.dev->Upload(m.faces, like.faces, fbytes);
  m.dev->Upload(m.depth, like.depth, dbytes);

  VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kNumBindings};
  VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pci.maxSets = 1;
  pci.poolSizeCount = 1;
  pci.pPoolSizes = &ps;
  VkResult r = vkCreateDescriptorPool(device, &pci, nullptr, &m.pool);
  if (r != VK_SUCCESS) throw Error(Fail(r, "creating a descriptor pool"));
  VkDescriptorSetAllocateInfo dai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dai.descriptorPool = m.pool;
  dai.descriptorSetCount = 1;
  dai.pSetLayouts = &m.programs->set_layout;
  r = vkAllocateDescriptorSets(device, &dai, &m.set);
  if (r != VK_SUCCESS) throw Error(Fail(r, "allocating a descriptor set"));
  VkCommandPoolCreateInfo cpi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  cpi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cpi.queueFamilyIndex = m.dev->queue_family();
  r = vkCreateCommandPool(device, &cpi, nullptr, &m.cmd_pool);
  if (r != VK_SUCCESS) throw Error(Fail(r, "creating a command pool"));
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = m.cmd_pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  r = vkAllocateCommandBuffers(device, &cai, &m.cmd);
  if (r != VK_SUCCESS) throw Error(Fail(r, "allocating a command buffer"));
}

GpuKernel::~GpuKernel() = default;


void GpuKernel::Score(const std::vector<ScoreKernelParams>& params, std::vector<ScoreKernelResult>* out,
                      double timeout_s) {
  Impl& m = *impl_;
  out->assign(params.size(), ScoreKernelResult{});
  std::vector<int> todo;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const ScoreKernelParams& k = params[i];
    if (i > 0 && !SameSettings(k, params[0]))
      throw Error("gpu engine: a batch mixes models, images or settings (particle " + std::to_string(i) + ")");
    if (!SameArrays(k, m.like))
      throw Error("gpu engine: the parameters point at another model or image than the kernel uploaded");
    if (k.scene_normals) throw Error("gpu engine: ICP sums (scene_normals) are not computed on the device");
    (*out)[i].faces_total = k.num_faces;
    const PixelRect& w = k.window;
    if (w.width <= 0 || w.height <= 0) continue;  // nothing rendered (as the reference)
    if (w.u0 < 0 || w.v0 < 0 || w.u0 + w.width > k.depth_width || w.v0 + w.height > k.depth_height)
      throw Error("gpu engine: the window of particle " + std::to_string(i) + " does not lie inside the depth image");
    todo.push_back(int(i));
  }
  if (todo.empty()) return;
  // Batches that fit one storage binding each (vertex records, z-buffer) and the group count.
  const VkDeviceSize limit = BufferLimit(*m.dev);
  const std::uint64_t max_particles = m.dev->max_group_count();
  const VkDeviceSize per_vertex_set = VkDeviceSize(m.like.num_vertices) * 16;
  const VkDeviceSize per_job_list = VkDeviceSize(m.like.num_faces) * 8;  // every face large
  std::vector<int> batch;
  VkDeviceSize zb_bytes = 0;
  for (int i : todo) {
    const VkDeviceSize area = VkDeviceSize(params[std::size_t(i)].window.Area()) * 4;
    if (area > limit || area / 4 / kGroup >= m.dev->max_group_count())
      throw Error("gpu engine: a window of " + std::to_string(area / 4) + " pixels is too large for the device");
    if (!batch.empty() && (VkDeviceSize(batch.size() + 1) * per_vertex_set > limit || zb_bytes + area > limit ||
                           4 + VkDeviceSize(batch.size() + 1) * per_job_list > limit || batch.size() + 1 > max_particles)) {
      m.RunBatch(params, batch, out, timeout_s);
      batch.clear();
      zb_bytes = 0;
    }
    batch.push_back(i);
    zb_bytes += area;
  }
  m.RunBatch(params, batch, out, timeout_s);
}

void GpuKernel::Impl::RunBatch(const std::vector<ScoreKernelParams>& params, const std::vector<int>& idx,
                               std::vector<ScoreKernelResult>* out, double timeout_s) {
  const ScoreKernelParams& k0 = params[std::size_t(idx[0])];
  const std::uint32_t n = std::uint32_t(idx.size());
  // Per-particle records and z-buffer offsets.
  Ensure(&particles, VkDeviceSize(n) * kParticleWords * 4, true);
  Ensure(&results, VkDeviceSize(n) * kResultWords * 4, true);
  auto* rec = static_cast<std::uint32_t*>(particles.mapped);
  std::uint64_t zb_pixels = 0, max_area = 0;
  for (std::uint32_t j = 0; j < n; ++j) {
    const ScoreKernelParams& k = params[std::size_t(idx[j])];
    std::uint32_t* r = rec + std::size_t(j) * kParticleWords;
    std::memcpy(r, k.R, 9 * sizeof(float));
    std::memcpy(r + 9, k.t, 3 * sizeof(float));
    const std::int32_t win[4] = {k.window.u0, k.window.v0, k.window.width, k.window.height};
    std::memcpy(r + 12, win, sizeof(win));
    r[16] = std::uint32_t(zb_pixels);
    r[17] = r[18] = r[19] = 0;
    zb_pixels += std::uint64_t(k.window.Area());
    max_area = std::max<std::uint64_t>(max_area, std::uint64_t(k.window.Area()));
  }
  Ensure(&vrec, std::max<VkDeviceSize>(VkDeviceSize(n) * VkDeviceSize(like.num_vertices) * 16, 16), false);
  Ensure(&zbuf, std::max<VkDeviceSize>(zb_pixels * 4, 16), false);
  Ensure(&jobs, 4 + VkDeviceSize(n) * VkDeviceSize(like.num_faces) * 8, false);
  Ensure(&job_groups, 16, false);
  UpdateSet();

  Push push{};
  push.fx = k0.fx;
  push.fy = k0.fy;
  push.cx = k0.cx;
  push.cy = k0.cy;
  push.near_m = k0.near_m;
  push.thr1_m = k0.inlier.thr1_m;
  push.inv_thr1 = 1.0f / k0.inlier.thr1_m;
  push.hard_thr_m = k0.inlier.hard_thr_m;
  push.align_band_m = k0.align_band_m;
  push.edge_band_m = k0.edge_band_m;
  push.num_vertices = k0.num_vertices;
  push.num_faces = k0.num_faces;
  push.num_particles = std::int32_t(n);
  push.depth_width = k0.depth_width;
  push.depth_height = k0.depth_height;
  push.flags = (k0.zbuffer ? kFlagZBuffer : 0u) | (k0.inlier.hard ? kFlagHard : 0u);

  vkResetCommandBuffer(cmd, 0);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &bi);
  vkCmdFillBuffer(cmd, results.buffer, 0, VkDeviceSize(n) * kResultWords * 4, 0);
  vkCmdFillBuffer(cmd, jobs.buffer, 0, 4, 0);  // no large faces listed yet
  if (k0.zbuffer) vkCmdFillBuffer(cmd, zbuf.buffer, 0, std::max<VkDeviceSize>(zb_pixels * 4, 4), 0);
  Barrier(VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, programs->layout, 0, 1, &set, 0, nullptr);
  const auto groups = [](std::uint64_t items) { return std::uint32_t((items + kGroup - 1) / kGroup); };
  const VkAccessFlags rw = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  const VkPipelineStageFlags cs = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  Dispatch(kVertexPass, push, groups(std::uint64_t(like.num_vertices)), n);
  Barrier(rw, rw, cs, cs);
  Dispatch(kRasterPass, push, groups(std::uint64_t(like.num_faces)), n);
  Barrier(rw, rw, cs, cs);
  Dispatch(kJobsPass, push, 1, 1);
  Barrier(rw, rw | VK_ACCESS_INDIRECT_COMMAND_READ_BIT, cs, cs | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, programs->pipelines[kRasterBigPass]);
  vkCmdPushConstants(cmd, programs->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Push), &push);
  vkCmdDispatchIndirect(cmd, job_groups.buffer, 0);
  if (k0.zbuffer) {
    Barrier(rw, rw, cs, cs);
    Dispatch(kScorePass, push, groups((max_area + kScorePixels - 1) / kScorePixels), n);
  }
  Barrier(VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_HOST_READ_BIT, cs, VK_PIPELINE_STAGE_HOST_BIT);
  vkEndCommandBuffer(cmd);
  dev->SubmitAndWait(cmd, timeout_s);

  const auto* res = static_cast<const std::uint32_t*>(results.mapped);
  for (std::uint32_t j = 0; j < n; ++j) {
    const std::uint32_t* r = res + std::size_t(j) * kResultWords;
    auto sum = [&](int s) {
      return std::int64_t(std::uint64_t(r[2 * s]) | (std::uint64_t(r[2 * s + 1]) << 32));
    };
    ScoreKernelResult& o = (*out)[std::size_t(idx[j])];
    o.inlier_sum = std::ldexp(double(sum(kInlier)), -23);
    o.n_raster = sum(kRaster);
    o.n_occluded = sum(kOccluded);
    o.depth_diff_sum = std::ldexp(double(sum(kDiffSum)), -32);
    o.depth_diff_count = sum(kDiffCount);
    o.n_edge = sum(kEdge);
    o.n_edge_continued = sum(kEdgeContinued);
    o.faces_front = sum(kFront);
  }
}

bool GpuBuilt() { return true; }

int GpuValidationErrors() { return GpuAvailable(nullptr) ? gpu::VulkanDevice::Shared()->ValidationErrors() : 0; }
std::string GpuFirstValidationError() {
  return GpuAvailable(nullptr) ? gpu::VulkanDevice::Shared()->FirstValidationError() : "";
}

bool GpuAvailable(std::string* why) {
  try {
    gpu::VulkanDevice::Shared();
    return true;
  } catch (const Error& e) {
    if (why) *why = e.what();
    return false;
  }
}

std::string GpuDeviceName() {
  const std::shared_ptr<gpu::VulkanDevice> d = gpu::VulkanDevice::Shared();
  return d->name() + " (" + d->type() + ")";
}

namespace gpu_testing {
void InjectFault(bool lost) { gpu::VulkanDevice::InjectFault(lost ? gpu::Fault::kDeviceLost : gpu::Fault::kTimeout); }
}  // namespace gpu_testing

}  // namespace posefilter::render
