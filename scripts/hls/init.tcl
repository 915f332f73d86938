# scripts/hls/init.tcl — HwInitTop (initialisation, thesis §7.4): csim, csynth, cosim.
source [file join [file dirname [info script]] common.tcl]
posefilter_hls_flow posefilter_hls_init HwInitTop tb_init.cc ""
exit
