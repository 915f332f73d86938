# scripts/hls/weigh10.tcl — HwWeighTop10 (weighing + sorting with 10 raster cores, the second
# design of thesis §7.7): csim, csynth, cosim.
source [file join [file dirname [info script]] common.tcl]
posefilter_hls_flow posefilter_hls_weigh10 HwWeighTop10 tb_weigh.cc "-DHLS_TB_CORES=10"
exit
