// The hw and rtl engines in a build without the FPGA C model (CMake option POSEFILTER_HW=OFF):
// their registry rows say why they cannot run, and making their runs or a cycle-model report
// throws that reason.
#include <memory>
#include <string>

#include "filter/engine.h"
#include "filter/rtl_engine.h"
#include "posefilter/error.h"
#include "posefilter/hw_engine.h"

namespace posefilter {

namespace {
const char* const kNoHwModel =
    "hw engine: this build has no FPGA C model (configure with -DPOSEFILTER_HW=ON); use --engine cpu";
}  // namespace

namespace filter {

bool HwEngineBuilt(std::string* why) {
  if (why) *why = kNoHwModel;
  return false;
}

bool RtlEngineBuilt(std::string* why) { return HwEngineBuilt(why); }

std::unique_ptr<EngineRuns> MakeHwEngine(const PreparedScene&, const Mesh&, const Prior&, int, const FilterOptions&) {
  throw Error(kNoHwModel);
}

std::unique_ptr<hw::host::Transport> RtlDeviceTransport() { throw Error(kNoHwModel); }

std::unique_ptr<EngineRuns> MakeRtlEngine(const PreparedScene&, const Mesh&, const Prior&, int, const FilterOptions&) {
  throw Error(kNoHwModel);
}

std::unique_ptr<EngineRuns> MakeRtlEngine(const PreparedScene&, const Mesh&, const Prior&, int, const FilterOptions&,
                                          const hw::host::VerilatorTransportOptions&) {
  throw Error(kNoHwModel);
}

}  // namespace filter

bool HwProfileOptions::IsValid(std::string* why) const {
  if (why) *why = kNoHwModel;
  return false;
}

HwProfile ProfileHw(const SceneInput&, const Mesh&, const Prior&, int, const FilterOptions&, const HwProfileOptions&) {
  throw Error(std::string("hw-report: ") + kNoHwModel);
}

}  // namespace posefilter
