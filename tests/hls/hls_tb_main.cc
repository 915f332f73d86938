// tests/hls/hls_tb_main.cc — the HLS flow's golden-vector generator and C test benches
// (scripts/hls/tb/) in one executable for ctest (tests/hls/CMakeLists.txt):
//   hls_tb golden <dir> [<flipped dir>]                 every case, into <dir>/<case>/
//   hls_tb init|weigh5|weigh10|update <dir> [<case>]     one bench on one case (default cube)
//   hls_tb expect-mismatch <bench> <dir> [<case>]
// Exit status of a bench: 0 = the top's outputs equal the golden vectors bit for bit, 1 = a
// mismatch, 2 = a vector could not be read (or the case is unknown). expect-mismatch runs the
// bench and exits 0 only when it reported a mismatch (1): a missing vector or a crash fails it.
#define HLS_TB_NO_MAIN
#include "golden_gen.cc"
#include "tb_init.cc"
#include "tb_update.cc"
#include "tb_weigh.cc"

namespace {

bool IsBench(const std::string& what) {
  return what == "init" || what == "weigh5" || what == "weigh10" || what == "update";
}

int RunBench(const std::string& what, const std::string& dir, const std::string& case_name) {
  if (what == "init") return hls_case::TbInit(dir, case_name);
  if (what == "weigh5") return hls_case::TbWeigh(dir, case_name, 5);
  if (what == "weigh10") return hls_case::TbWeigh(dir, case_name, 10);
  if (what == "update") return hls_case::TbUpdate(dir, case_name);
  std::fprintf(stderr, "unknown bench '%s' (init, weigh5, weigh10, update)\n", what.c_str());
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "";
  if (what == "expect-mismatch") {
    if (argc != 4 && argc != 5)
      return std::fprintf(stderr, "usage: %s expect-mismatch <bench> <vector dir> [<case>]\n", argv[0]), 2;
    const int status = RunBench(argv[2], argv[3], argc > 4 ? argv[4] : "cube");
    std::printf("expect-mismatch: the bench exited %d (%s)\n", status,
                status == hls_case::kTbMismatch ? "a mismatch, as expected" : "not a mismatch");
    return status == hls_case::kTbMismatch ? 0 : 1;
  }
  const std::string dir = argc > 2 ? argv[2] : "vectors";
  if (what == "golden") return hls_case::WriteGolden(dir, argc > 3 ? argv[3] : "");
  if (IsBench(what)) return RunBench(what, dir, argc > 3 ? argv[3] : "cube");
  std::fprintf(stderr, "usage: %s golden <vector dir> [<flipped dir>] | init|weigh5|weigh10|update <vector dir> [<case>]\n",
               argv[0]);
  return 2;
}
