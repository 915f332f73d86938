// scripts/hls/tops.cc — the design source of the HLS flow (scripts/hls/*.tcl add_files): the
// tops of src/hw/top.h. Under __SYNTHESIS__ (csynth) HwInitTop, HwWeighTop5, HwWeighTop10 and
// HwUpdateTop have external linkage here, the one translation unit that defines them; in C
// simulation they are inline and the test bench's own copies run.
#include "hw/top.h"
