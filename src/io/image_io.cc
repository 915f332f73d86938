// io/image_io.cc — PNG I/O of depth, label and colour images with libpng's classic API (the
// types: posefilter/depth_image.h, src/core/depth_image.cc).
//
// libpng reports errors by longjmp. To keep that well-defined in C++, every setjmp lives in a
// small function whose frame holds only trivially destructible locals, and the longjmp only
// unwinds libpng's C frames and our error callback; all C++ objects (buffers, row pointers)
// are allocated by the callers before/after those functions. libpng's error text is copied
// into a fixed buffer and turned into posefilter::Error by the caller.
#include "posefilter/depth_image.h"

#include <png.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/file_io.h"

namespace posefilter {

namespace {

// ---------------------------------------------------------------------------------------------
// Error plumbing shared by reader and writer.

struct PngMessage {
  char text[256] = "";
};

void PngErrorFn(png_structp png, png_const_charp msg) {
  auto* m = static_cast<PngMessage*>(png_get_error_ptr(png));
  if (m != nullptr) {
    std::snprintf(m->text, sizeof(m->text), "%s", msg != nullptr ? msg : "unknown libpng error");
  }
  png_longjmp(png, 1);
}

void PngWarningFn(png_structp, png_const_charp) {}  // warnings (e.g. sRGB profile) are ignored

// Second step of setting up a read or write: `png` is what png_create_{read,write}_struct (with
// PngErrorFn/PngWarningFn and `msg`) returned; creates its info struct into `*info`. Returns
// false with `msg` set when either is missing.
bool PngCreateInfo(png_structp png, png_infop* info, PngMessage* msg) {
  if (png != nullptr) *info = png_create_info_struct(png);
  if (png == nullptr || *info == nullptr) {
    std::snprintf(msg->text, sizeof(msg->text), "libpng initialisation failed");
    return false;
  }
  return true;
}

// Row pointers into `pixels`, `height` rows of `rowbytes` bytes each.
std::vector<png_bytep> RowPointers(std::vector<std::uint8_t>& pixels, size_t height, size_t rowbytes) {
  std::vector<png_bytep> rows(height);
  for (size_t r = 0; r < height; ++r) rows[r] = pixels.data() + r * rowbytes;
  return rows;
}

// ---------------------------------------------------------------------------------------------
// Reading.

// What the caller wants from a PNG, applied as libpng transformations.
enum class ReadMode { kRaw, kRgb8 };

struct PngReadState {
  FILE* fp = nullptr;
  png_structp png = nullptr;
  png_infop info = nullptr;
  PngMessage msg;
  // Filled by PngReadHeader:
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, color_type = 0;
  size_t rowbytes = 0;  // bytes per row after the transformations
  int channels = 0;     // channels per pixel after the transformations
};

void PngReadClose(PngReadState* s) {
  if (s->png != nullptr) png_destroy_read_struct(&s->png, s->info != nullptr ? &s->info : nullptr, nullptr);
  s->png = nullptr;
  s->info = nullptr;
  if (s->fp != nullptr) std::fclose(s->fp);
  s->fp = nullptr;
}

// RAII owner of a PngReadState (lives in the C++ caller's frame, never crossed by longjmp).
class PngReader {
 public:
  PngReader() = default;
  PngReader(const PngReader&) = delete;
  PngReader& operator=(const PngReader&) = delete;
  ~PngReader() { PngReadClose(&s); }
  PngReadState s;
};

// Walks the chunk list (length, type, data, CRC) from just after the signature to IEND or the
// end of the file, then seeks back. libpng allocates an ancillary chunk (text, ICC profile) whole
// before reading it, so a length field beyond the end of the file (a 1.9 GB zTXt chunk in an
// 80-byte file) made it allocate gigabytes: such a file is rejected here first. Returns false
// with s->msg set on such a chunk.
bool PngChunksFitFile(PngReadState* s) {
  const long start = std::ftell(s->fp);
  long end = -1;
  if (start >= 0 && std::fseek(s->fp, 0, SEEK_END) == 0) end = std::ftell(s->fp);
  long pos = start;
  while (end >= 0 && end - pos >= 8) {
    unsigned char h[8];
    if (std::fseek(s->fp, pos, SEEK_SET) != 0 || std::fread(h, 1, 8, s->fp) != 8) break;
    const unsigned long len = (static_cast<unsigned long>(h[0]) << 24) | (static_cast<unsigned long>(h[1]) << 16) |
                              (static_cast<unsigned long>(h[2]) << 8) | h[3];
    // A chunk type is four ASCII letters (PNG spec §5.3): the walk ends at anything else, which
    // libpng refuses if it gets there (walking on, a file of zeros would be a chain of empty
    // "chunks" 12 bytes apart, read to its end).
    bool letters = true;
    for (int k = 0; k < 4; ++k) {
      const unsigned char c = h[4 + k];
      letters = letters && ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'));
    }
    if (!letters) break;
    if (len > static_cast<unsigned long>(end - pos - 8)) {
      char type[5] = {0, 0, 0, 0, 0};
      for (int k = 0; k < 4; ++k) type[k] = std::isalpha(h[4 + k]) ? static_cast<char>(h[4 + k]) : '?';
      std::snprintf(s->msg.text, sizeof(s->msg.text),
                    "chunk \"%s\" at byte %ld says %lu bytes, but the file ends %ld bytes later (truncated or corrupt)",
                    type, pos, len, end - pos - 8);
      return false;
    }
    if (std::memcmp(h + 4, "IEND", 4) == 0) break;
    pos += 12 + static_cast<long>(len);
  }
  if (start < 0 || std::fseek(s->fp, start, SEEK_SET) != 0) {
    std::snprintf(s->msg.text, sizeof(s->msg.text), "cannot seek in the file");
    return false;
  }
  return true;
}

// Opens the file, checks the signature and reads the header. For kRgb8 it also sets up the
// conversion to 8-bit RGB. Returns false with s->msg set on failure.
// Only trivially destructible locals: see the file comment.
bool PngReadHeader(PngReadState* s, const char* path, ReadMode mode) {
  s->fp = std::fopen(path, "rb");
  if (s->fp == nullptr) {
    std::snprintf(s->msg.text, sizeof(s->msg.text), "cannot open (%s)", std::strerror(errno));
    return false;
  }
  unsigned char sig[8];
  if (std::fread(sig, 1, 8, s->fp) != 8 || png_sig_cmp(sig, 0, 8) != 0) {
    std::snprintf(s->msg.text, sizeof(s->msg.text), "not a PNG file");
    return false;
  }
  if (!PngChunksFitFile(s)) return false;
  s->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &s->msg, PngErrorFn, PngWarningFn);
  if (!PngCreateInfo(s->png, &s->info, &s->msg)) return false;
  if (setjmp(png_jmpbuf(s->png))) return false;
  png_init_io(s->png, s->fp);
  png_set_sig_bytes(s->png, 8);
  png_read_info(s->png, s->info);
  s->width = png_get_image_width(s->png, s->info);
  s->height = png_get_image_height(s->png, s->info);
  s->bit_depth = png_get_bit_depth(s->png, s->info);
  s->color_type = png_get_color_type(s->png, s->info);
  if (mode == ReadMode::kRgb8) {
    if (s->color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(s->png);
    if (s->color_type == PNG_COLOR_TYPE_GRAY && s->bit_depth < 8) {
      png_set_expand_gray_1_2_4_to_8(s->png);
    }
    if (s->bit_depth == 16) png_set_strip_16(s->png);
    if ((s->color_type & PNG_COLOR_MASK_ALPHA) != 0) png_set_strip_alpha(s->png);
    if (s->color_type == PNG_COLOR_TYPE_GRAY || s->color_type == PNG_COLOR_TYPE_GRAY_ALPHA) {
      png_set_gray_to_rgb(s->png);
    }
    // tRNS (transparency for palette/gray/RGB) is left unexpanded: RGB stays 3 channels.
  }
  png_set_interlace_handling(s->png);
  png_read_update_info(s->png, s->info);
  s->rowbytes = png_get_rowbytes(s->png, s->info);
  s->channels = png_get_channels(s->png, s->info);
  return true;
}

// Reads all rows into the caller's buffers (row pointers prepared by the caller).
bool PngReadRows(PngReadState* s, png_bytep* rows) {
  if (setjmp(png_jmpbuf(s->png))) return false;
  png_read_image(s->png, rows);
  png_read_end(s->png, nullptr);
  return true;
}

// Throws when the header announces more than kMaxPngPixels (checked after CheckPngFitsFile:
// before any pixel buffer exists, so a file declaring a huge image costs nothing).
void CheckPngPixelCap(const PngReadState& s, const std::string& path, const char* what) {
  const unsigned long long pixels = static_cast<unsigned long long>(s.width) * s.height;
  if (pixels > static_cast<unsigned long long>(kMaxPngPixels)) {
    throw Error(path + ": " + what + " PNG header says " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                " pixels, more than the " + std::to_string(kMaxPngPixels) + " (8192x8192) any image may have");
  }
}

// Throws when (expect_width > 0) the header announces another size than the caller's camera,
// before anything is decoded.
void CheckPngCameraSize(const PngReadState& s, const std::string& path, const char* what, int expect_width,
                        int expect_height) {
  if (expect_width > 0 && (s.width != static_cast<png_uint_32>(expect_width) ||
                           s.height != static_cast<png_uint_32>(expect_height))) {
    throw Error(path + ": " + what + " PNG is " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                " but the camera is " + std::to_string(expect_width) + "x" + std::to_string(expect_height) +
                " (read from the PNG header; nothing decoded)");
  }
}

// Throws unless the file is large enough for the image its header announces: deflate expands
// at most 1032:1, so a PNG of N bytes holds at most 1032·N bytes of (unfiltered) pixel data.
// Checked before the pixel buffer is allocated, so a corrupt or hostile header (a 100-byte file
// saying 8196 × 196608 pixels) cannot make the reader allocate gigabytes.
void CheckPngFitsFile(PngReadState* s, const std::string& path, const char* what) {
  const long here = std::ftell(s->fp);
  long size = -1;
  if (here >= 0 && std::fseek(s->fp, 0, SEEK_END) == 0) size = std::ftell(s->fp);
  if (size < 0 || std::fseek(s->fp, here, SEEK_SET) != 0) throw Error(path + ": cannot read " + what + " PNG");
  const int channels = (s->color_type & PNG_COLOR_MASK_PALETTE) != 0 ? 1
                       : ((s->color_type & PNG_COLOR_MASK_COLOR) != 0 ? 3 : 1) +
                             ((s->color_type & PNG_COLOR_MASK_ALPHA) != 0 ? 1 : 0);
  const unsigned long long row_bits = static_cast<unsigned long long>(s->width) * channels * s->bit_depth;
  const unsigned long long raw_bytes = (row_bits + 7) / 8 * s->height;
  if (raw_bytes > 1032ull * static_cast<unsigned long long>(size)) {
    throw Error(path + ": corrupt or truncated " + what + " PNG: its header says " + std::to_string(s->width) + "x" +
                std::to_string(s->height) + " pixels, more than a " + std::to_string(size) + "-byte file can hold");
  }
}

// Opens `path`, reads the header and all rows. Returns the raw transformed rows, packed.
std::vector<std::uint8_t> ReadPngPixels(const std::string& path, const char* what, ReadMode mode,
                                        PngReader* reader) {
  PngReadState* s = &reader->s;
  if (!PngReadHeader(s, path.c_str(), mode)) {
    throw Error(path + ": cannot read " + what + " PNG: " + s->msg.text);
  }
  if (s->width == 0 || s->height == 0) throw Error(path + ": " + what + " PNG has zero size");
  CheckPngFitsFile(s, path, what);
  CheckPngPixelCap(*s, path, what);  // so at most 8 bytes × kMaxPngPixels = 512 MiB below
  std::vector<std::uint8_t> pixels = NameOutOfMemory(path, std::string(what) + " PNG", [&] {
    return std::vector<std::uint8_t>(static_cast<size_t>(s->rowbytes) * s->height);
  });
  std::vector<png_bytep> rows = RowPointers(pixels, s->height, s->rowbytes);
  if (!PngReadRows(s, rows.data())) {
    throw Error(path + ": corrupt or truncated " + what + " PNG: " + s->msg.text);
  }
  return pixels;
}

// ---------------------------------------------------------------------------------------------
// Writing.

struct PngWriteState {
  png_structp png = nullptr;
  png_infop info = nullptr;
  PngMessage msg;
};

class PngWriter {
 public:
  PngWriter() = default;
  PngWriter(const PngWriter&) = delete;
  PngWriter& operator=(const PngWriter&) = delete;
  ~PngWriter() {
    if (s.png != nullptr) png_destroy_write_struct(&s.png, s.info != nullptr ? &s.info : nullptr);
  }
  PngWriteState s;
};

// Writes a whole non-interlaced image to the open file `fp`. color_type PNG_COLOR_TYPE_GRAY or
// _RGB. Rows must already be in PNG byte order (16-bit samples big-endian).
bool PngWriteAll(PngWriteState* s, FILE* fp, png_uint_32 w, png_uint_32 h, int bit_depth,
                 int color_type, png_bytep* rows) {
  s->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &s->msg, PngErrorFn, PngWarningFn);
  if (!PngCreateInfo(s->png, &s->info, &s->msg)) return false;
  if (setjmp(png_jmpbuf(s->png))) return false;
  png_init_io(s->png, fp);
  png_set_IHDR(s->png, s->info, w, h, bit_depth, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(s->png, s->info);
  png_write_image(s->png, rows);
  png_write_end(s->png, nullptr);
  return true;
}

// Throws unless a w×h image holds exactly w·h·`per_pixel` of its `unit`s (`size` of them).
void CheckWritableSize(const std::string& path, const char* what, int w, int h, size_t size,
                       size_t per_pixel, const char* unit) {
  if (w <= 0 || h <= 0 || size != size_t(w) * size_t(h) * per_pixel) {
    throw Error(path + ": cannot write " + what + " PNG: image is empty or its size (" + std::to_string(w) + "x" +
                std::to_string(h) + ") does not match its data (" + std::to_string(size) + " " + unit + ")");
  }
}

void WritePng(const std::string& path, const char* what, int w, int h, int bit_depth,
              int color_type, std::vector<std::uint8_t>& pixels, size_t rowbytes) {
  std::vector<png_bytep> rows = RowPointers(pixels, static_cast<size_t>(h), rowbytes);
  // Written to a temporary file and renamed (file_io.h): never a truncated PNG at `path`.
  WriteFileAtomicallyC(path, [&](FILE* fp, std::string* error) {
    PngWriter writer;
    const bool ok = PngWriteAll(&writer.s, fp, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h),
                                bit_depth, color_type, rows.data());
    if (!ok) *error = std::string("cannot write ") + what + " PNG: " + writer.s.msg.text;
    return ok;
  });
}

// The samples of a single-channel 8- or 16-bit PNG (depth or label image), row-major;
// `what` names the kind of image in errors.
std::vector<std::uint16_t> ReadGrayPng(const std::string& path, const char* what, int* width, int* height,
                                       bool require_16_bit = false, int expect_width = 0, int expect_height = 0) {
  PngReader reader;
  // Peek at the header first to reject colour images with a clear message before decoding.
  if (!PngReadHeader(&reader.s, path.c_str(), ReadMode::kRaw)) {
    throw Error(path + ": cannot read " + what + " PNG: " + reader.s.msg.text);
  }
  const PngReadState& h = reader.s;
  CheckPngCameraSize(h, path, what, expect_width, expect_height);
  if (h.color_type != PNG_COLOR_TYPE_GRAY) {
    const char* kind = h.color_type == PNG_COLOR_TYPE_RGB          ? "RGB"
                       : h.color_type == PNG_COLOR_TYPE_RGB_ALPHA  ? "RGBA"
                       : h.color_type == PNG_COLOR_TYPE_PALETTE    ? "palette"
                       : h.color_type == PNG_COLOR_TYPE_GRAY_ALPHA ? "gray+alpha"
                                                                   : "unknown";
    throw Error(path + ": " + what + " PNG must be single-channel gray, but it is " + kind);
  }
  if (h.bit_depth != 8 && h.bit_depth != 16) {
    throw Error(path + ": " + what + " PNG must be 8- or 16-bit, but it is " + std::to_string(h.bit_depth) + "-bit");
  }
  if (require_16_bit && h.bit_depth != 16) {
    throw Error(path + ": " + what + " PNG must be 16-bit, but it is " + std::to_string(h.bit_depth) +
                "-bit (an 8-bit image holds 256 levels: a preview, not a depth map)");
  }
  if (h.width > static_cast<png_uint_32>(std::numeric_limits<int>::max()) ||
      h.height > static_cast<png_uint_32>(std::numeric_limits<int>::max())) {
    throw Error(path + ": " + what + " PNG is too large");
  }
  const int w = static_cast<int>(h.width), hh = static_cast<int>(h.height);
  const int bytes_per_px = h.bit_depth / 8;
  const size_t rowbytes = h.rowbytes;
  if (static_cast<unsigned long long>(rowbytes) * h.height > (1ull << 32)) {
    throw Error(path + ": " + what + " PNG is too large");
  }
  if (rowbytes != size_t(w) * bytes_per_px) throw Error(path + ": unexpected " + what + " PNG row size");
  CheckPngFitsFile(&reader.s, path, what);
  CheckPngPixelCap(reader.s, path, what);
  std::vector<std::uint8_t> pixels(rowbytes * hh);
  std::vector<png_bytep> rows = RowPointers(pixels, size_t(hh), rowbytes);
  if (!PngReadRows(&reader.s, rows.data())) {
    throw Error(path + ": corrupt or truncated " + what + " PNG: " + reader.s.msg.text);
  }
  const size_t n = size_t(w) * hh;
  std::vector<std::uint16_t> out(n);
  if (bytes_per_px == 2) {
    // 16-bit PNG samples are big-endian in the file (libpng hands them over unswapped).
    for (size_t i = 0; i < n; ++i) out[i] = std::uint16_t((unsigned(pixels[2 * i]) << 8) | pixels[2 * i + 1]);
  } else {
    for (size_t i = 0; i < n; ++i) out[i] = pixels[i];
  }
  *width = w;
  *height = hh;
  return out;
}

// Writes 16-bit samples (row-major, w × h) as a single-channel 16-bit PNG.
void WriteGray16Png(const std::vector<std::uint16_t>& samples, int w, int h, const std::string& path, const char* what) {
  CheckWritableSize(path, what, w, h, samples.size(), 1, "values");
  std::vector<std::uint8_t> pixels(2 * samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    pixels[2 * i] = static_cast<std::uint8_t>(samples[i] >> 8);  // big-endian sample
    pixels[2 * i + 1] = static_cast<std::uint8_t>(samples[i] & 0xffu);
  }
  WritePng(path, what, w, h, 16, PNG_COLOR_TYPE_GRAY, pixels, size_t(w) * 2);
}

}  // namespace

DepthImage LoadDepthPng(const std::string& path, double depth_scale) { return LoadDepthPng(path, depth_scale, 0, 0); }

DepthImage LoadDepthPng(const std::string& path, double depth_scale, int width, int height) {
  if (!std::isfinite(depth_scale) || depth_scale <= 0) {
    throw Error(path + ": depth_scale must be finite and > 0 (got " + std::to_string(depth_scale) +
                ")");
  }
  if (depth_scale * 65535.0 > FLT_MAX) {
    throw Error(path + ": depth_scale " + std::to_string(depth_scale) +
                " overflows float depths");
  }
  int w = 0, h = 0;
  const std::vector<std::uint16_t> samples = ReadGrayPng(path, "depth", &w, &h, /*require_16_bit=*/true, width, height);
  DepthImage depth(w, h);
  for (size_t i = 0; i < samples.size(); ++i) depth.data[i] = static_cast<float>(samples[i] * depth_scale);
  return depth;
}

LabelImage LoadLabelPng(const std::string& path) {
  LabelImage labels;
  labels.ids = ReadGrayPng(path, "label", &labels.width, &labels.height);
  return labels;
}

void SaveLabelPng(const LabelImage& labels, const std::string& path) {
  WriteGray16Png(labels.ids, labels.width, labels.height, path, "label");
}

void SaveDepthPng(const DepthImage& depth, const std::string& path, double depth_scale) {
  if (!std::isfinite(depth_scale) || depth_scale <= 0) {
    throw Error(path + ": depth_scale must be finite and > 0 (got " + std::to_string(depth_scale) +
                ")");
  }
  const size_t n = depth.data.size();
  std::vector<std::uint16_t> samples(n);
  for (size_t i = 0; i < n; ++i) {
    const double d = depth.data[i];
    unsigned v = 0;  // missing (0, negative, NaN or inf) → 0
    if (std::isfinite(d) && d > 0) {
      const double q = std::round(d / depth_scale);
      v = q >= 65535.0 ? 65535u : static_cast<unsigned>(q);
    }
    samples[i] = static_cast<std::uint16_t>(v);
  }
  WriteGray16Png(samples, depth.width, depth.height, path, "depth");
}

RgbImage LoadRgbPng(const std::string& path) {
  PngReader reader;
  std::vector<std::uint8_t> pixels = ReadPngPixels(path, "RGB", ReadMode::kRgb8, &reader);
  const PngReadState& s = reader.s;
  if (s.channels != 3 || s.rowbytes != size_t(s.width) * 3) {
    throw Error(path + ": RGB PNG did not convert to 8-bit RGB");
  }
  // Sides fit an int: ReadPngPixels refused more than kMaxPngPixels.
  RgbImage image;
  image.width = static_cast<int>(s.width);
  image.height = static_cast<int>(s.height);
  image.data = std::move(pixels);
  return image;
}

void SaveRgbPng(const RgbImage& image, const std::string& path) {
  CheckWritableSize(path, "RGB", image.width, image.height, image.data.size(), 3, "bytes");
  std::vector<std::uint8_t> pixels = image.data;  // libpng takes non-const row pointers
  WritePng(path, "RGB", image.width, image.height, 8, PNG_COLOR_TYPE_RGB, pixels,
           size_t(image.width) * 3);
}

void SaveGray8Png(const std::vector<std::uint8_t>& pixels, int width, int height, const std::string& path) {
  CheckWritableSize(path, "gray", width, height, pixels.size(), 1, "bytes");
  std::vector<std::uint8_t> rows = pixels;  // libpng takes non-const row pointers
  WritePng(path, "gray", width, height, 8, PNG_COLOR_TYPE_GRAY, rows, size_t(width));
}

}  // namespace posefilter
