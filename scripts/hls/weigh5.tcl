# scripts/hls/weigh5.tcl — HwWeighTop5 (weighing + sorting with 5 raster cores, thesis §7.5,
# the first design of §7.7): csim, csynth, cosim.
source [file join [file dirname [info script]] common.tcl]
posefilter_hls_flow posefilter_hls_weigh5 HwWeighTop5 tb_weigh.cc "-DHLS_TB_CORES=5"
exit
