// python/bindings/keywords.cc — the keyword options of Estimator and make_synth_scene: every FilterOptions and SynthOptions field by name, and messages in keyword names.
#include "bindings.h"

namespace posefilter::python {

// Every FilterOptions field (filter.h), in declaration order. python/tests/test_options.py
// checks this list against the header, so a new field cannot be forgotten here.
const std::vector<Keyword<FilterOptions>>& FilterKeywords() {
  using O = FilterOptions;
  static const std::vector<Keyword<O>> k = {
      Field("engine", &O::engine),
      Field("cpu_isa", &O::cpu_isa),
      Field("num_particles", &O::num_particles),
      Field("max_iterations", &O::max_iterations),
      Field("confidence", &O::confidence),
      Field("alpha", &O::alpha),
      Field("beta", &O::beta),
      Field("gamma", &O::gamma),
      Field("delta", &O::delta),
      Field("edge_band_m", &O::edge_band_m),
      Nested("inlier_thr1_m", &O::inlier, &InlierParams::thr1_m),
      Nested("inlier_hard", &O::inlier, &InlierParams::hard),
      Nested("inlier_hard_thr_m", &O::inlier, &InlierParams::hard_thr_m),
      Field("anneal_start_m", &O::anneal_start_m),
      Field("anneal_fraction", &O::anneal_fraction),
      Field("anneal_subsample", &O::anneal_subsample),
      Field("anneal_simplify", &O::anneal_simplify),
      Field("zbuffer", &O::zbuffer),
      Field("support_plane", &O::support_plane),
      Field("contact", &O::contact),
      Field("stable_start", &O::stable_start),
      Field("contact_tolerance_m", &O::contact_tolerance_m),
      Field("contact_span_m", &O::contact_span_m),
      Field("occlusion_aware", &O::occlusion_aware),
      Field("max_window_px", &O::max_window_px),
      Field("adaptive_resolution", &O::adaptive_resolution),
      Field("min_window_diameters", &O::min_window_diameters),
      Field("grow_window", &O::grow_window),
      Field("near_m", &O::near_m),
      Field("lod_max_faces", &O::lod_max_faces),
      Field("init_oversample", &O::init_oversample),
      Field("fine_particle_fraction", &O::fine_particle_fraction),
      Field("num_elite", &O::num_elite),
      Field("resample_pool", &O::resample_pool),
      Field("region_cap", &O::region_cap),
      Field("rotation_cap", &O::rotation_cap),
      Field("tracker_bins", &O::tracker_bins),
      Field("sigma_t0_m", &O::sigma_t0_m),
      Field("sigma_r0_rad", &O::sigma_r0_rad),
      Field("min_sigma_fraction", &O::min_sigma_fraction),
      Field("move_probabilities", &O::move_probabilities),
      Field("align_band_m", &O::align_band_m),
      Nested("heuristics_percentile_lo", &O::heuristics, &HeuristicOptions::percentile_lo),
      Nested("heuristics_percentile_hi", &O::heuristics, &HeuristicOptions::percentile_hi),
      Nested("heuristics_depth_extension_m", &O::heuristics, &HeuristicOptions::depth_extension_m),
      Nested("heuristics_max_samples", &O::heuristics, &HeuristicOptions::max_samples),
      Nested("heuristics_max_depth_m", &O::heuristics, &HeuristicOptions::max_depth_m),
      Nested("heuristics_min_valid_pixels", &O::heuristics, &HeuristicOptions::min_valid_pixels),
      Field("restarts", &O::restarts),
      Field("stall_iterations", &O::stall_iterations),
      Field("stall_gain", &O::stall_gain),
      Field("polish_steps", &O::polish_steps),
      Field("polish_turns", &O::polish_turns),
      Field("polish_pivots", &O::polish_pivots),
      Field("polish_keep", &O::polish_keep),
      Field("polish_stable", &O::polish_stable),
      Field("polish_seeds", &O::polish_seeds),
      Field("polish_climbers", &O::polish_climbers),
      Field("seed", &O::seed),
      Field("threads", &O::threads),
  };
  return k;
}

const std::vector<Keyword<SynthOptions>>& SynthKeywords() {
  using O = SynthOptions;
  static const std::vector<Keyword<O>> k = {
      Field("camera", &O::camera),
      Field("depth_scale", &O::depth_scale),
      Field("target", &O::target),
      // target_mesh (a pointer) is handled by make_synth_scene itself.
      Field("min_distance_m", &O::min_distance_m),
      Field("max_distance_m", &O::max_distance_m),
      Field("occlusion", &O::occlusion),
      Field("clutter", &O::clutter),
      Field("noise_sigma_m", &O::noise_sigma_m),
      Field("hole_fraction", &O::hole_fraction),
      Field("missing_edges", &O::missing_edges),
      Field("box_jitter_px", &O::box_jitter_px),
      Field("miss_probability", &O::miss_probability),
      Field("false_positives", &O::false_positives),
  };
  return k;
}

// FilterOptions::IsValid names fields; name the keyword where it differs from the field.
std::string NameKeywords(std::string why) {
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto p = why.find(from);
    if (p != std::string::npos) why.replace(p, from.size(), to);
    return p != std::string::npos;
  };
  if (why.rfind("heuristics: ", 0) == 0) {
    why = why.substr(12);
    for (const char* f : {"percentile_lo", "percentile_hi", "depth_extension_m", "max_samples", "max_depth_m",
                          "min_valid_pixels"})
      for (auto p = why.find(f); p != std::string::npos; p = why.find(f, p + 11 + std::strlen(f)))
        why.replace(p, std::strlen(f), std::string("heuristics_") + f);
    return why;
  }
  if (!replace("hard inlier threshold", "inlier_hard_thr_m")) replace("inlier threshold", "inlier_thr1_m");
  if (why.find("move probabilit") != std::string::npos) why += " (keyword move_probabilities)";
  return why;
}

FilterOptions CheckedFilterOptions(const FilterOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) Fail("invalid filter option: " + NameKeywords(why));
  return o;
}

}  // namespace posefilter::python
