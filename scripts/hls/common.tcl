# scripts/hls/common.tcl — shared by init.tcl, weigh5.tcl, weigh10.tcl, update.tcl (Vitis HLS):
#   vitis_hls -f scripts/hls/<top>.tcl          (from any directory)
# Environment:
#   POSEFILTER_HLS_STEPS    the steps to run, default "csim csynth cosim export" (export: the
#                           top as a Vivado IP, export_design -format ip_catalog)
#   POSEFILTER_HLS_VECTORS  the golden-vector directory the test benches read, default
#                           <repo>/build/release/tests/hls/vectors (written by ctest's
#                           hls_golden_write or `hls_tb golden <dir>`; see README.md)
#   POSEFILTER_HLS_CASE     the test benches' case, cube (default) or torus (README.md)
#   POSEFILTER_HLS_OUT      where the projects go, default the current directory
# The include path holds the repository's src/ and include/ but NOT src/hw/hls_types/: the
# kernels' "ap_int.h", "ap_fixed.h" and "hls_stream.h" resolve to the vendor's headers, which
# vitis_hls puts on the path itself.

set posefilter_root [file normalize [file join [file dirname [info script]] .. ..]]
set posefilter_part xczu9eg-ffvb1156-2-e
set posefilter_clock_ns 5

proc posefilter_env {name default} {
  if {[info exists ::env($name)] && $::env($name) ne ""} { return $::env($name) }
  return $default
}

# One top: project <project>, top function <top>, test bench scripts/hls/tb/<tb>, extra test
# bench defines <tb_defs> (e.g. -DHLS_TB_CORES=10).
proc posefilter_hls_flow {project top tb tb_defs} {
  set root $::posefilter_root
  set steps [posefilter_env POSEFILTER_HLS_STEPS "csim csynth cosim export"]
  set vectors [posefilter_env POSEFILTER_HLS_VECTORS [file join $root build release tests hls vectors]]
  set case [posefilter_env POSEFILTER_HLS_CASE cube]
  set out [posefilter_env POSEFILTER_HLS_OUT [pwd]]
  set cflags "-std=c++17 -I$root/src -I$root/include"
  cd $out
  open_project -reset $project
  set_top $top
  add_files [file join $root src hw tops.cc] -cflags $cflags
  add_files -tb [file join $root scripts hls tb $tb] -cflags "$cflags -I$root/scripts/hls/tb $tb_defs"
  open_solution -reset solution1 -flow_target vivado
  set_part $::posefilter_part
  create_clock -period $::posefilter_clock_ns -name default
  if {[lsearch $steps csim] >= 0} { csim_design -argv "$vectors $case" }
  if {[lsearch $steps csynth] >= 0} { csynth_design }
  if {[lsearch $steps cosim] >= 0} { cosim_design -argv "$vectors $case" }
  if {[lsearch $steps export] >= 0} { export_design -format ip_catalog }
  close_project
}
