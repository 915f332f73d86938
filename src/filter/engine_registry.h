// src/filter/engine_registry.h — the engines, one row each: the one list of engine names. It
// gives FilterOptions::engine its values (the option table's choices, EngineBit, the hardware
// limits' check), EstimatePose its engine (driver.cc), the float filter its weigher
// (engine_weigh.h), `posefilter bench` its list, `posefilter --version` its engine lines.
// docs/ARCHITECTURE.md, "Engines", shows how a new engine is added: one file and one row.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "filter/engine.h"
#include "filter/engine_weigh.h"
#include "posefilter/filter.h"
#include "posefilter/prepared_model.h"

namespace posefilter::filter {

// What an engine's runs are made from (EstimatePose's inputs, the scene prepared once).
// `model`: the mesh's prepared model, or null (the float engines prepare one on the fly).
struct EngineInputs {
  std::shared_ptr<const PreparedScene> prep;
  const PreparedModel* model = nullptr;
  const Mesh& mesh;
  const Prior& prior;
  int cls = 0;
  const FilterOptions& options;
};

struct EngineRow {
  const char* name;  // the FilterOptions::engine (--engine, engine=) value
  // The EngineBits (posefilter/option_table.h) of the option rows it reads. A row whose bit an
  // earlier row has already reads that engine's options and is listed under its name (rtl: the
  // hw engine's options).
  unsigned bit;
  const char* summary;  // one line: what it is (its `posefilter --version` line, unless `describe`)
  // Whether its runs weigh the float filter's particles (particle_filter.cc) through its weigher:
  // then every such engine draws the same particles and counts the same fragments.
  bool float_filter;
  // Whether default lists (`posefilter bench`'s) take it when it is available: not rtl (it
  // simulates every clock), gpu only on a GPU (a CPU Vulkan driver is correct but slow).
  bool (*listed_by_default)();
  // The engine's runs for one estimate; the inputs outlive them. Throws Error on inputs the
  // engine cannot take.
  std::unique_ptr<EngineRuns> (*make_runs)(const EngineInputs& in);
  // The weigher of a float context (BuildContext) with this engine's options.
  std::unique_ptr<ParticleWeigher> (*make_weigher)(const Context& ctx);
  // Whether this build and machine can run it; else *why (may be null) says why not (built
  // without Vulkan or Verilator, no Vulkan device, ...).
  bool (*available)(std::string* why);
  // Its `posefilter --version` line with this build's details (null: the summary).
  std::string (*describe)();
};

// Every engine, in the order lists show them (the reference first: bench's baseline).
std::span<const EngineRow> EngineRegistry();
// The row of an engine name; null for any other name.
const EngineRow* FindEngine(std::string_view name);
// The row of the default engine (FilterOptions{}.engine).
const EngineRow& DefaultEngine();
// Every engine name joined by `separator`, the default engine first ("cpu|reference|...").
std::string EngineChoices(const char* separator);

}  // namespace posefilter::filter
