// tests/hls/hls_tb_main.cc — the HLS flow's golden-vector generator and C test benches
// (scripts/hls/tb/) in one executable for ctest (tests/hls/CMakeLists.txt):
//   hls_tb golden <dir> [<flipped dir>] | init <dir> | weigh5 <dir> | weigh10 <dir> | update <dir>
// Exit status 0 = the top's outputs equal the golden vectors bit for bit.
#define HLS_TB_NO_MAIN
#include "golden_gen.cc"
#include "tb_init.cc"
#include "tb_update.cc"
#include "tb_weigh.cc"

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "";
  const std::string dir = argc > 2 ? argv[2] : "vectors";
  if (what == "golden") return hls_case::WriteGolden(dir, argc > 3 ? argv[3] : "");
  if (what == "init") return hls_case::TbInit(dir);
  if (what == "weigh5") return hls_case::TbWeigh(dir, 5);
  if (what == "weigh10") return hls_case::TbWeigh(dir, 10);
  if (what == "update") return hls_case::TbUpdate(dir);
  std::fprintf(stderr, "usage: %s golden|init|weigh5|weigh10|update <vector dir> [<flipped dir>]\n", argv[0]);
  return 2;
}
