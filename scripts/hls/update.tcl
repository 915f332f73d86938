# scripts/hls/update.tcl — HwUpdateTop (resampling + diffusion, thesis §7.5.4, §7.6): csim,
# csynth, cosim.
source [file join [file dirname [info script]] common.tcl]
posefilter_hls_flow posefilter_hls_update HwUpdateTop tb_update.cc ""
exit
