// Tests of DepthImage / RgbImage PNG I/O (include/posefilter/depth_image.h).
//
// Besides round trips through our own writer, the loaders are checked against PNGs built byte
// by byte here (stored-deflate zlib, hand-computed CRC/Adler), so byte order, bit depth and
// colour-type handling are verified independently of libpng's writer.
#include "posefilter/depth_image.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;

// ---- A minimal independent PNG encoder -------------------------------------------------------

std::uint32_t Crc32(const std::string& bytes) {
  std::uint32_t c = 0xffffffffu;
  for (unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

void PutBe32(std::string& s, std::uint32_t v) {
  for (int k = 3; k >= 0; --k) s.push_back(char((v >> (8 * k)) & 0xff));
}

void AppendChunk(std::string& png, const std::string& type, const std::string& data) {
  PutBe32(png, std::uint32_t(data.size()));
  const std::string body = type + data;
  png += body;
  PutBe32(png, Crc32(body));
}

// zlib stream of stored (uncompressed) deflate blocks.
std::string ZlibStored(const std::string& raw) {
  std::string z = "\x78\x01";
  size_t pos = 0;
  do {
    const size_t n = std::min<size_t>(65535, raw.size() - pos);
    const bool last = pos + n == raw.size();
    z.push_back(last ? 1 : 0);
    z.push_back(char(n & 0xff));
    z.push_back(char(n >> 8));
    z.push_back(char(~n & 0xff));
    z.push_back(char((~n >> 8) & 0xff));
    z += raw.substr(pos, n);
    pos += n;
  } while (pos < raw.size());
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  PutBe32(z, (b << 16) | a);
  return z;
}

// PNG with the given header fields; `rows` are the unfiltered scanlines (without filter byte).
std::string MakePng(int w, int h, int bit_depth, int color_type,
                    const std::vector<std::string>& rows) {
  std::string png = "\x89PNG\r\n\x1a\n";
  std::string ihdr;
  PutBe32(ihdr, std::uint32_t(w));
  PutBe32(ihdr, std::uint32_t(h));
  ihdr += {char(bit_depth), char(color_type), 0, 0, 0};
  AppendChunk(png, "IHDR", ihdr);
  if (color_type == 3) AppendChunk(png, "PLTE", std::string("\xff\x00\x00\x00\xff\x00", 6));
  std::string raw;
  for (const auto& r : rows) raw += '\0' + r;  // filter type 0 (None)
  AppendChunk(png, "IDAT", ZlibStored(raw));
  AppendChunk(png, "IEND", "");
  return png;
}

std::string Be16(unsigned v) { return {char(v >> 8), char(v & 0xff)}; }

// ---- Fixture ---------------------------------------------------------------------------------

using testing_util::ExpectError;
using testing_util::ReadFile;

// A fresh directory per test.
class PngFileTest : public testing_util::ScratchDirTest {
 protected:
  PngFileTest() : ScratchDirTest("png") {}
};

const float kNaNf = std::numeric_limits<float>::quiet_NaN();

// ---- Depth -----------------------------------------------------------------------------------

TEST(DepthImageTest, CountValidCountsPositiveDepths) {
  DepthImage d(4, 3);
  EXPECT_EQ(d.CountValid(), 0u);
  d.at(0, 0) = 0.5f;
  d.at(3, 2) = 1e-4f;
  d.at(1, 1) = -1.f;  // negative is not a valid depth
  EXPECT_EQ(d.CountValid(), 2u);
  EXPECT_EQ(d.data[2 * 4 + 3], 1e-4f);  // at(u, v) is row-major: index v·width + u
}

TEST_F(PngFileTest, Depth16BitRoundTripIsExactToDepthScale) {
  const double scale = 0.001;
  DepthImage d(7, 5);
  for (int v = 0; v < d.height; ++v) {
    for (int u = 0; u < d.width; ++u) d.at(u, v) = 0.3f + 0.0137f * float(u * d.height + v);
  }
  d.at(0, 0) = 0.f;          // missing stays missing
  d.at(1, 0) = -0.5f;        // negative → missing
  d.at(2, 0) = kNaNf;        // NaN → missing
  d.at(3, 0) = 100.f;        // beyond 65535·scale → clamped
  d.at(4, 0) = 0.0004f;      // rounds to 0 PNG units → missing
  d.at(5, 0) = 65.535f;      // exactly the largest value
  const std::string path = Path("depth.png");
  SaveDepthPng(d, path, scale);
  const DepthImage back = LoadDepthPng(path, scale);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  for (int v = 0; v < d.height; ++v) {
    for (int u = 0; u < d.width; ++u) {
      const double m = d.at(u, v);
      const double units = (std::isfinite(m) && m > 0) ? std::min(65535.0, std::round(m / scale)) : 0;
      EXPECT_EQ(back.at(u, v), float(units * scale)) << "pixel " << u << "," << v;
      if (units > 0 && units < 65535) {
        EXPECT_NEAR(back.at(u, v), m, 0.5 * scale + 1e-6);
      }
    }
  }
  EXPECT_EQ(back.at(0, 0), 0.f);
  EXPECT_EQ(back.at(2, 0), 0.f);
  EXPECT_FLOAT_EQ(back.at(3, 0), 65.535f);
  EXPECT_EQ(back.CountValid(), size_t(7 * 5 - 4));
}

TEST_F(PngFileTest, Depth16BitIsBigEndianInTheFile) {
  // Hand-made 3×2 16-bit gray PNG: samples 0x0102, 0xff00, 0, 1, 65535, 0x1234.
  const std::string png = MakePng(3, 2, 16, 0, {Be16(0x0102) + Be16(0xff00) + Be16(0),
                                                Be16(1) + Be16(65535) + Be16(0x1234)});
  const std::string path = Write("be.png", png);
  const double s = 1e-4;
  const DepthImage d = LoadDepthPng(path, s);
  ASSERT_EQ(d.width, 3);
  ASSERT_EQ(d.height, 2);
  EXPECT_EQ(d.at(0, 0), float(0x0102 * s));
  EXPECT_EQ(d.at(1, 0), float(0xff00 * s));
  EXPECT_EQ(d.at(2, 0), 0.f);
  EXPECT_EQ(d.at(0, 1), float(1 * s));
  EXPECT_EQ(d.at(1, 1), float(65535 * s));
  EXPECT_EQ(d.at(2, 1), float(0x1234 * s));

  // Our writer produces the same samples: re-save and reload.
  SaveDepthPng(d, Path("again.png"), s);
  const DepthImage again = LoadDepthPng(Path("again.png"), s);
  EXPECT_EQ(again.data, d.data);
}

// An 8-bit grey PNG is a preview of a depth image, not depth: refused, naming the file.
TEST_F(PngFileTest, Depth8BitGrayIsRefused) {
  const std::string path = Write("d8.png", MakePng(2, 2, 8, 0, {std::string("\x00\x07", 2), "\xff\x80"}));
  ExpectError([&] { LoadDepthPng(path, 0.01); }, {path, "16-bit"});
}

TEST_F(PngFileTest, DepthRejectsBadDepthScale) {
  SaveDepthPng(DepthImage(2, 2, 1.f), Path("ok.png"), 0.001);
  for (double s : {0.0, -0.001, double(kNaNf), std::numeric_limits<double>::infinity()}) {
    ExpectError([&] { LoadDepthPng(Path("ok.png"), s); }, {Path("ok.png"), "depth_scale"});
    ExpectError([&] { SaveDepthPng(DepthImage(2, 2, 1.f), Path("w.png"), s); },
                {Path("w.png"), "depth_scale"});
  }
}

TEST_F(PngFileTest, DepthMissingFile) {
  ExpectError([&] { LoadDepthPng(Path("missing.png"), 0.001); }, {Path("missing.png"), "cannot open"});
}

TEST_F(PngFileTest, DepthTextFileRenamedPng) {
  const std::string path = Write("text.png", "hello, I am not an image\n");
  ExpectError([&] { LoadDepthPng(path, 0.001); }, {path, "not a PNG"});
}

TEST_F(PngFileTest, DepthEmptyFile) {
  const std::string path = Write("empty.png", "");
  ExpectError([&] { LoadDepthPng(path, 0.001); }, {path, "not a PNG"});
}

TEST_F(PngFileTest, DepthTruncatedPng) {
  DepthImage d(64, 48);
  for (size_t i = 0; i < d.data.size(); ++i) d.data[i] = 0.5f + 0.001f * float(i % 977);
  SaveDepthPng(d, Path("full.png"), 0.0001);
  const std::string bytes = ReadFile(Path("full.png"));
  ASSERT_GT(bytes.size(), 100u);
  // Cut inside the image data, and cut inside the header.
  const std::string half = Write("half.png", bytes.substr(0, bytes.size() / 2));
  ExpectError([&] { LoadDepthPng(half, 0.0001); }, {half});
  const std::string head = Write("head.png", bytes.substr(0, 20));
  ExpectError([&] { LoadDepthPng(head, 0.0001); }, {head});
}

// A small file whose header declares a huge image is refused from the header: over
// kMaxPngPixels for every reader, and, for a depth image read for a camera, any size other than
// the camera's (nothing is decoded, so the check costs no memory).
TEST_F(PngFileTest, HugeOrMismatchedHeadersAreRefusedBeforeDecoding) {
  // Padded with a private ancillary chunk to a size whose bytes could inflate to the declared
  // pixels, so the limit, not the file-size bound, is what refuses them.
  auto padded = [](int w, int h, int bit_depth, int color_type, std::size_t row_bytes, std::size_t pad) {
    std::string png = MakePng(w, h, bit_depth, color_type, {std::string(row_bytes, '\0')});
    std::string chunk;
    AppendChunk(chunk, "prVt", std::string(pad, 'x'));
    return png.insert(33, chunk);  // after the signature (8) and IHDR (25)
  };
  const std::string huge = Write("huge.png", padded(30000, 30000, 16, 0, 60000, 1800000));
  ExpectError([&] { LoadDepthPng(huge, 0.001); }, {huge, "30000x30000", "8192x8192"});
  ExpectError([&] { LoadLabelPng(huge); }, {huge, "30000x30000", "8192x8192"});
  const std::string huge_rgb = Write("huge_rgb.png", padded(9000, 9000, 8, 2, 27000, 240000));
  ExpectError([&] { LoadRgbPng(huge_rgb); }, {huge_rgb, "9000x9000", "8192x8192"});
  const std::string small = Write("small.png", MakePng(4, 4, 16, 0, std::vector<std::string>(4, std::string(8, '\x11'))));
  ExpectError([&] { LoadDepthPng(small, 0.001, 640, 480); }, {small, "4x4 but the camera is 640x480", "PNG header"});
  EXPECT_EQ(LoadDepthPng(small, 0.001, 4, 4).width, 4);  // the camera's size: read as before
  EXPECT_EQ(LoadDepthPng(small, 0.001, 0, 0).width, 4);  // no size given: no comparison
}

TEST_F(PngFileTest, DepthCorruptDataCrc) {
  std::string png = MakePng(4, 4, 16, 0, std::vector<std::string>(4, std::string(8, '\x11')));
  png[png.size() - 30] ^= 0x5a;  // flip a byte inside IDAT → CRC mismatch
  const std::string path = Write("crc.png", png);
  ExpectError([&] { LoadDepthPng(path, 0.001); }, {path});
}

TEST_F(PngFileTest, DepthRejectsColourPngs) {
  const std::string rgb = Write("rgb.png", MakePng(2, 1, 8, 2, {"\x01\x02\x03\x04\x05\x06"}));
  ExpectError([&] { LoadDepthPng(rgb, 0.001); }, {rgb, "single-channel", "RGB"});
  const std::string rgba = Write("rgba.png", MakePng(1, 1, 8, 6, {"\x01\x02\x03\x04"}));
  ExpectError([&] { LoadDepthPng(rgba, 0.001); }, {rgba, "RGBA"});
  const std::string ga = Write("ga.png", MakePng(1, 1, 16, 4, {"\x01\x02\x03\x04"}));
  ExpectError([&] { LoadDepthPng(ga, 0.001); }, {ga, "gray+alpha"});
  const std::string pal = Write("pal.png", MakePng(2, 1, 8, 3, {std::string("\x00\x01", 2)}));
  ExpectError([&] { LoadDepthPng(pal, 0.001); }, {pal, "palette"});
}

TEST_F(PngFileTest, DepthRejectsLowBitDepth) {
  const std::string path = Write("d1.png", MakePng(8, 1, 1, 0, {"\xa5"}));
  ExpectError([&] { LoadDepthPng(path, 0.001); }, {path, "1-bit"});
}

TEST_F(PngFileTest, DepthSaveRejectsBadImages) {
  ExpectError([&] { SaveDepthPng(DepthImage(), Path("e.png"), 0.001); }, {Path("e.png"), "empty"});
  DepthImage wrong(4, 4);
  wrong.data.resize(15);
  ExpectError([&] { SaveDepthPng(wrong, Path("w.png"), 0.001); }, {Path("w.png")});
  const std::string no_dir = Path("no/such/dir/d.png");
  ExpectError([&] { SaveDepthPng(DepthImage(2, 2, 1.f), no_dir, 0.001); }, {no_dir, "does not exist"});
}

// ---- RGB -------------------------------------------------------------------------------------

TEST_F(PngFileTest, RgbRoundTripIsExact) {
  RgbImage img(9, 4);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = std::uint8_t((i * 37 + 11) % 256);
  img.px(8, 3)[0] = 255;
  SaveRgbPng(img, Path("c.png"));
  const RgbImage back = LoadRgbPng(Path("c.png"));
  EXPECT_EQ(back.width, 9);
  EXPECT_EQ(back.height, 4);
  EXPECT_EQ(back.data, img.data);
}

TEST_F(PngFileTest, RgbLoaderConvertsOtherColourTypes) {
  // Gray → r = g = b.
  RgbImage g = LoadRgbPng(Write("g.png", MakePng(2, 1, 8, 0, {"\x10\xf0"})));
  ASSERT_EQ(g.data.size(), 6u);
  EXPECT_EQ(g.data, (std::vector<std::uint8_t>{0x10, 0x10, 0x10, 0xf0, 0xf0, 0xf0}));
  // RGBA → alpha dropped.
  RgbImage a = LoadRgbPng(Write("a.png", MakePng(1, 1, 8, 6, {"\x01\x02\x03\x80"})));
  EXPECT_EQ(a.data, (std::vector<std::uint8_t>{1, 2, 3}));
  // 16-bit RGB → high bytes.
  RgbImage h = LoadRgbPng(
      Write("h.png", MakePng(1, 1, 16, 2, {Be16(0x1234) + Be16(0xab00) + Be16(0x00ff)})));
  EXPECT_EQ(h.data, (std::vector<std::uint8_t>{0x12, 0xab, 0x00}));
  // Palette → looked-up colours (palette: red, green).
  RgbImage p = LoadRgbPng(Write("p.png", MakePng(2, 1, 8, 3, {std::string("\x01\x00", 2)})));
  EXPECT_EQ(p.data, (std::vector<std::uint8_t>{0, 255, 0, 255, 0, 0}));
}

TEST_F(PngFileTest, RgbBadInputs) {
  ExpectError([&] { LoadRgbPng(Path("missing.png")); }, {Path("missing.png")});
  const std::string text = Write("t.png", "GIF89a not a png");
  ExpectError([&] { LoadRgbPng(text); }, {text, "not a PNG"});
  RgbImage img(16, 16);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = std::uint8_t(i * 7);
  SaveRgbPng(img, Path("full.png"));
  const std::string bytes = ReadFile(Path("full.png"));
  const std::string cut = Write("cut.png", bytes.substr(0, bytes.size() * 2 / 3));
  ExpectError([&] { LoadRgbPng(cut); }, {cut});

  RgbImage wrong(3, 3);
  wrong.data.pop_back();
  ExpectError([&] { SaveRgbPng(wrong, Path("w.png")); }, {Path("w.png")});
  ExpectError([&] { SaveRgbPng(RgbImage(), Path("e.png")); }, {Path("e.png")});
}

// ---- 8-bit gray ------------------------------------------------------------------------------

TEST_F(PngFileTest, Gray8RoundTripIsExact) {
  const int w = 17, h = 5;  // odd width: no row padding to hide behind
  std::vector<std::uint8_t> px(size_t(w) * h);
  for (size_t i = 0; i < px.size(); ++i) px[i] = std::uint8_t((i * 37 + 11) % 256);
  px[0] = 0;
  px[1] = 255;
  const std::string path = Path("g8.png");
  SaveGray8Png(px, w, h, path);
  // The header says 8-bit gray: IHDR data starts at byte 16 (width, height, bit depth, colour type).
  const std::string bytes = ReadFile(path);
  ASSERT_GT(bytes.size(), 26u);
  EXPECT_EQ(bytes.substr(12, 4), "IHDR");
  EXPECT_EQ(std::uint8_t(bytes[24]), 8);  // bit depth
  EXPECT_EQ(std::uint8_t(bytes[25]), 0);  // colour type gray
  // Read back as labels (id = sample) and as RGB (r = g = b = sample); as depth it is refused:
  // 256 levels are a preview image, not a depth map.
  const LabelImage d = LoadLabelPng(path);
  ASSERT_EQ(d.width, w);
  ASSERT_EQ(d.height, h);
  ExpectError([&] { LoadDepthPng(path, 1.0); }, {path, "must be 16-bit", "8-bit"});
  const RgbImage rgb = LoadRgbPng(path);
  ASSERT_EQ(rgb.data.size(), px.size() * 3);
  for (size_t i = 0; i < px.size(); ++i) {
    EXPECT_EQ(d.ids[i], px[i]) << "pixel " << i;
    EXPECT_EQ(rgb.data[3 * i], px[i]) << "pixel " << i;
    EXPECT_EQ(rgb.data[3 * i + 2], px[i]) << "pixel " << i;
  }
}

TEST_F(PngFileTest, Gray8SaveRejectsBadImages) {
  ExpectError([&] { SaveGray8Png({}, 0, 0, Path("e.png")); }, {Path("e.png"), "empty"});
  ExpectError([&] { SaveGray8Png(std::vector<std::uint8_t>(11), 3, 4, Path("w.png")); },
              {Path("w.png"), "3x4", "11"});
  ExpectError([&] { SaveGray8Png(std::vector<std::uint8_t>(4), -2, -2, Path("n.png")); }, {Path("n.png")});
  const std::string no_dir = Path("no/such/dir/g.png");
  ExpectError([&] { SaveGray8Png(std::vector<std::uint8_t>(4), 2, 2, no_dir); }, {no_dir, "does not exist"});
  EXPECT_FALSE(fs::exists(Path("e.png")));
  EXPECT_FALSE(fs::exists(Path("w.png")));
  EXPECT_FALSE(fs::exists(Path("n.png")));
}

// ---- Real YCB-Video frames (optional) --------------------------------------------------------

fs::path YcbvScene() {
  return testing_util::YcbvDataDir() / "scenes" / "ycbv_0000_000001";
}

TEST(DepthYcbvTest, RealDepthHasPlausibleMedian) {
  const fs::path file = YcbvScene() / "depth.png";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not found";
  const DepthImage d = LoadDepthPng(file.string(), 0.0001);
  EXPECT_EQ(d.width, 640);
  EXPECT_EQ(d.height, 480);
  std::vector<float> valid;
  for (float z : d.data) {
    ASSERT_TRUE(std::isfinite(z));
    if (z > 0) valid.push_back(z);
  }
  EXPECT_EQ(valid.size(), d.CountValid());
  ASSERT_GT(valid.size(), d.data.size() / 2);
  std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
  const float median = valid[valid.size() / 2];
  EXPECT_GT(median, 0.4f);
  EXPECT_LT(median, 1.5f);
}

TEST(DepthYcbvTest, RealRgbLoadsAndIsRejectedAsDepth) {
  const fs::path file = YcbvScene() / "rgb.png";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not found";
  const RgbImage rgb = LoadRgbPng(file.string());
  EXPECT_EQ(rgb.width, 640);
  EXPECT_EQ(rgb.height, 480);
  ASSERT_EQ(rgb.data.size(), 640u * 480u * 3u);
  EXPECT_GT(*std::max_element(rgb.data.begin(), rgb.data.end()), 100);
  ExpectError([&] { LoadDepthPng(file.string(), 0.0001); }, {file.string(), "RGB"});
}

}  // namespace
}  // namespace posefilter
