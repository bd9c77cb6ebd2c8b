// read_image and write_image: round trips of every layout, files made independently with libpng
// (palette, low bit depths, transparency, interlacing), and malformed PNG and JPEG files the tests
// make themselves, each of which must give a ConfigError naming the file, never a crash or a
// partial image.
#include <gtest/gtest.h>
#include <png.h>
#include <zlib.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/io/image.h"

namespace fs = std::filesystem;

namespace ambfplus {
namespace {

using Bytes = std::vector<std::uint8_t>;

class ImageIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    folder_ = fs::temp_directory_path() /
              ("ambfplus_image_io_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }

  std::string path(const std::string& name) const { return (folder_ / name).string(); }

  std::string write_bytes(const std::string& name, const Bytes& bytes) const {
    std::ofstream(path(name), std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return path(name);
  }

  static Bytes read_bytes(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return Bytes(std::istreambuf_iterator<char>(in), {});
  }

  fs::path folder_;
};

// Expects read_image(file) to throw a ConfigError whose message names the file and contains
// `expected` (when given); returns the message.
std::string expect_config_error(const std::string& file, const std::string& expected = "") {
  try {
    const Image image = read_image(file);
    ADD_FAILURE() << file << ": read a " << image.width << "x" << image.height
                  << " image, expected an error";
  } catch (const ConfigError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file), std::string::npos) << message;
    EXPECT_EQ(e.file(), file);
    if (!expected.empty()) EXPECT_NE(message.find(expected), std::string::npos) << message;
    return message;
  }
  return "";
}

// A deterministic test pattern: every sample differs from its neighbours and rows differ.
Bytes pattern(int width, int height, int channels, int sample_bytes, unsigned seed) {
  Bytes out(std::size_t(width) * height * channels * sample_bytes);
  std::mt19937 rng(seed);
  for (auto& b : out) b = static_cast<std::uint8_t>(rng());
  return out;
}

// PNG bytes built chunk by chunk (independent of libpng's writer), for malformed variants.
void put32(Bytes& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

void chunk(Bytes& out, const char* type, const Bytes& data) {
  put32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  put32(out, static_cast<std::uint32_t>(crc32(0, out.data() + start, uInt(out.size() - start))));
}

Bytes ihdr(std::uint32_t width, std::uint32_t height, int depth, int colour) {
  Bytes d;
  put32(d, width);
  put32(d, height);
  d.insert(d.end(), {std::uint8_t(depth), std::uint8_t(colour), 0, 0, 0});
  return d;
}

// An 8-bit RGB PNG of width*3-byte rows, filter 0, one IDAT.
// The header may state another size (header_width, header_height when not -1).
Bytes handmade_png(std::uint32_t width, std::uint32_t height, const Bytes& pixels,
                   std::int64_t header_width = -1, std::int64_t header_height = -1) {
  Bytes raw;
  for (std::uint32_t r = 0; r < height; ++r) {
    raw.push_back(0);
    raw.insert(raw.end(), pixels.begin() + r * width * 3, pixels.begin() + (r + 1) * width * 3);
  }
  uLongf size = compressBound(uLong(raw.size()));
  Bytes z(size);
  compress(z.data(), &size, raw.data(), uLong(raw.size()));
  z.resize(size);
  Bytes png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  chunk(png, "IHDR",
        ihdr(header_width < 0 ? width : std::uint32_t(header_width),
             header_height < 0 ? height : std::uint32_t(header_height), 8, 2));
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});
  return png;
}

// Offset of a chunk's type field in PNG bytes.
std::size_t find_chunk(const Bytes& png, const char* type) {
  for (std::size_t at = 8; at + 8 <= png.size();) {
    const std::uint32_t length =
        (png[at] << 24) | (png[at + 1] << 16) | (png[at + 2] << 8) | png[at + 3];
    if (std::memcmp(&png[at + 4], type, 4) == 0) return at + 4;
    at += 12 + length;
  }
  return std::string::npos;
}

// A PNG written by libpng itself with any layout write_image does not produce.
struct LibpngLayout {
  int width, height, bit_depth, colour;
  bool interlaced = false;
  std::vector<png_color> palette = {};
  Bytes trns_alpha = {};       // palette transparency
  int trns_grey = -1;          // grey transparent level
  png_color_16 trns_rgb = {};  // RGB transparent colour (used when trns_rgb_set)
  bool trns_rgb_set = false;
};

void write_with_libpng(const std::string& file, const LibpngLayout& l, const Bytes& packed_rows) {
  std::FILE* f = std::fopen(file.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  const std::size_t stride = packed_rows.size() / l.height;
  std::vector<png_bytep> rows(l.height);
  for (int r = 0; r < l.height; ++r) rows[r] = const_cast<png_bytep>(&packed_rows[r * stride]);
  png_color_16 grey = {};
  grey.gray = static_cast<png_uint_16>(l.trns_grey);
  png_color_16 rgb = l.trns_rgb;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    FAIL() << "libpng could not write the test file";
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, l.width, l.height, l.bit_depth, l.colour,
               l.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (!l.palette.empty()) png_set_PLTE(png, info, l.palette.data(), int(l.palette.size()));
  if (!l.trns_alpha.empty()) {
    png_set_tRNS(png, info, l.trns_alpha.data(), int(l.trns_alpha.size()), nullptr);
  }
  if (l.trns_grey >= 0) png_set_tRNS(png, info, nullptr, 0, &grey);
  if (l.trns_rgb_set) png_set_tRNS(png, info, nullptr, 0, &rgb);
  png_write_info(png, info);
  if (l.bit_depth == 16) png_set_swap(png);  // the test rows are little-endian
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

TEST_F(ImageIo, PngRoundTripsEveryLayoutWithRow0AtTheTop) {
  for (PixelType type : {PixelType::kUInt8, PixelType::kUInt16}) {
    const int bytes = type == PixelType::kUInt8 ? 1 : 2;
    for (int channels = 1; channels <= 4; ++channels) {
      const int width = 13, height = 7;
      const Bytes pixels = pattern(width, height, channels, bytes, 10 * channels + bytes);
      // Rows written from a padded buffer: the stride is honoured.
      const std::size_t row = std::size_t(width) * channels * bytes, stride = row + 6;
      Bytes padded(stride * height, 0xAB);
      for (int r = 0; r < height; ++r) {
        std::memcpy(&padded[r * stride], &pixels[r * row], row);
      }
      const std::string file =
          path("c" + std::to_string(channels) + "_" + std::to_string(bytes) + ".png");
      write_image(file, padded.data(), height, width, channels, type, stride);
      const Image back = read_image(file);
      EXPECT_EQ(back.width, width);
      EXPECT_EQ(back.height, height);
      EXPECT_EQ(back.channels, channels);
      EXPECT_EQ(back.type, type);
      EXPECT_EQ(back.pixels, pixels) << file;
      // The same pixels again through write_image(Image).
      write_image(path("again.png"), back);
      EXPECT_EQ(read_image(path("again.png")).pixels, pixels);
    }
  }
}

TEST_F(ImageIo, JpegRoundTripsGreyAndRgbWithinItsLoss) {
  const int width = 64, height = 48;
  for (int channels : {1, 3}) {
    // Smooth content (JPEG's loss is small there): a bright top fading to a dark bottom, with
    // red growing to the right.
    Bytes pixels(std::size_t(width) * height * channels);
    for (int r = 0; r < height; ++r) {
      for (int c = 0; c < width; ++c) {
        std::uint8_t* px = &pixels[(std::size_t(r) * width + c) * channels];
        px[0] = static_cast<std::uint8_t>(250 - 4 * r);
        if (channels == 3) {
          px[0] = static_cast<std::uint8_t>(40 + 3 * c);
          px[1] = static_cast<std::uint8_t>(250 - 4 * r);
          px[2] = 90;
        }
      }
    }
    const std::string file = path("smooth" + std::to_string(channels) + ".jpg");
    write_image(file, pixels.data(), height, width, channels, PixelType::kUInt8);
    const Image back = read_image(file);
    ASSERT_EQ(back.channels, channels);
    ASSERT_EQ(back.width, width);
    ASSERT_EQ(back.height, height);
    EXPECT_EQ(back.type, PixelType::kUInt8);
    double error = 0;
    int worst = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const int d = std::abs(int(back.pixels[i]) - int(pixels[i]));
      error += d;
      worst = std::max(worst, d);
    }
    EXPECT_LT(error / pixels.size(), 1.5) << channels;
    EXPECT_LT(worst, 12) << channels;
  }
  // The extension may be .jpeg, in any case; the content decides how it is read.
  const Bytes grey(32 * 16, 77);
  write_image(path("grey.JPEG"), grey.data(), 16, 32, 1, PixelType::kUInt8);
  fs::rename(path("grey.JPEG"), path("actually_a_jpeg.png"));
  EXPECT_EQ(read_image(path("actually_a_jpeg.png")).channels, 1);
}

TEST_F(ImageIo, PngPaletteLowDepthTransparencyAndInterlacingExpand) {
  const int width = 11, height = 9;
  std::mt19937 rng(5);
  // Palette, 4 bits, with transparency: RGBA with the palette's colours and alphas.
  const std::vector<png_color> palette = {{0, 0, 0}, {250, 10, 20}, {5, 200, 30}, {7, 8, 9}};
  const Bytes alphas = {0, 255, 128};  // the fourth entry has none: opaque
  std::vector<int> index(width * height);
  for (auto& i : index) i = int(rng() % 4);
  Bytes packed(height * ((width * 4 + 7) / 8), 0);
  const std::size_t stride = packed.size() / height;
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      packed[r * stride + c / 2] |= std::uint8_t(index[r * width + c] << (c % 2 ? 0 : 4));
    }
  }
  for (bool interlaced : {false, true}) {
    LibpngLayout layout{width, height, 4, PNG_COLOR_TYPE_PALETTE, interlaced, palette, alphas};
    const std::string file = path(std::string("palette") + (interlaced ? "_i" : "") + ".png");
    write_with_libpng(file, layout, packed);
    const Image image = read_image(file);
    ASSERT_EQ(image.channels, 4);
    ASSERT_EQ(image.type, PixelType::kUInt8);
    for (int r = 0; r < height; ++r) {
      for (int c = 0; c < width; ++c) {
        const int i = index[r * width + c];
        const std::uint8_t* px = image.row(r) + 4 * c;
        EXPECT_EQ(px[0], palette[i].red);
        EXPECT_EQ(px[1], palette[i].green);
        EXPECT_EQ(px[2], palette[i].blue);
        EXPECT_EQ(px[3], i < 3 ? alphas[i] : 255);
      }
    }
    // Without transparency the palette gives RGB.
    layout.trns_alpha.clear();
    write_with_libpng(path("opaque.png"), layout, packed);
    EXPECT_EQ(read_image(path("opaque.png")).channels, 3);
  }

  // 1-bit grey: 0 and 255.
  Bytes bits(height * 2, 0);
  for (int r = 0; r < height; ++r) bits[r * 2] = r % 2 ? 0xA0 : 0x00;  // columns 0 and 2 set
  write_with_libpng(path("bits.png"), {width, height, 1, PNG_COLOR_TYPE_GRAY}, bits);
  const Image grey = read_image(path("bits.png"));
  ASSERT_EQ(grey.channels, 1);
  EXPECT_EQ(grey.row(1)[0], 255);
  EXPECT_EQ(grey.row(1)[1], 0);
  EXPECT_EQ(grey.row(1)[2], 255);
  EXPECT_EQ(grey.row(0)[0], 0);

  // An RGB transparent colour becomes alpha; a grey transparent level does not.
  Bytes rgb(width * height * 3, 60);
  rgb[0] = rgb[1] = rgb[2] = 9;
  LibpngLayout keyed{width, height, 8, PNG_COLOR_TYPE_RGB};
  keyed.trns_rgb.red = keyed.trns_rgb.green = keyed.trns_rgb.blue = 9;
  keyed.trns_rgb_set = true;
  write_with_libpng(path("keyed.png"), keyed, rgb);
  const Image rgba = read_image(path("keyed.png"));
  ASSERT_EQ(rgba.channels, 4);
  EXPECT_EQ(rgba.pixels[3], 0);
  EXPECT_EQ(rgba.pixels[7], 255);
  EXPECT_EQ(rgba.pixels[4], 60);
  LibpngLayout grey_keyed{width, height, 16, PNG_COLOR_TYPE_GRAY};
  grey_keyed.trns_grey = 1000;
  Bytes grey16(width * height * 2);
  for (std::size_t i = 0; i < grey16.size() / 2; ++i) {
    grey16[2 * i] = std::uint8_t(i * 7);
    grey16[2 * i + 1] = std::uint8_t(i);
  }
  write_with_libpng(path("grey16.png"), grey_keyed, grey16);
  const Image g16 = read_image(path("grey16.png"));
  ASSERT_EQ(g16.channels, 1);
  ASSERT_EQ(g16.type, PixelType::kUInt16);
  EXPECT_EQ(g16.pixels, grey16);  // machine order (little-endian here), as written
}

TEST_F(ImageIo, MissingFilesFoldersAndOtherFormats) {
  EXPECT_THROW(read_image(path("nowhere.png")), AssetNotFound);
  expect_config_error(folder_.string(), "folder");
  expect_config_error(write_bytes("empty.png", {}), "empty");
  expect_config_error(write_bytes("text.png", Bytes{'h', 'e', 'l', 'l', 'o'}), "not a PNG or JPEG");
  expect_config_error(write_bytes("gif.png", Bytes{'G', 'I', 'F', '8', '9', 'a', 1, 0, 1, 0}),
                      "not a PNG or JPEG");
}

TEST_F(ImageIo, EveryTruncationOfAPngOrJpegIsAnError) {
  const Bytes rgb = pattern(19, 12, 3, 1, 3);
  write_image(path("whole.png"), rgb.data(), 12, 19, 3, PixelType::kUInt8);
  write_image(path("whole.jpg"), rgb.data(), 12, 19, 3, PixelType::kUInt8);
  for (const char* name : {"whole.png", "whole.jpg"}) {
    const Bytes whole = read_bytes(path(name));
    ASSERT_GT(whole.size(), 100u);
    int ends_early = 0;
    for (std::size_t n = 1; n < whole.size(); ++n) {
      const std::string cut =
          write_bytes(std::string("cut_") + name, Bytes(whole.begin(), whole.begin() + n));
      const std::string message = expect_config_error(cut);
      ends_early += message.find("ends early") != std::string::npos ||
                    message.find("Premature end") != std::string::npos;
    }
    // Most cuts are reported as what they are.
    EXPECT_GT(ends_early, int(whole.size()) / 2) << name;
  }
}

TEST_F(ImageIo, PngChecksumsHeadersAndSizesAreChecked) {
  const Bytes rgb = pattern(5, 4, 3, 1, 9);
  const Bytes good = handmade_png(5, 4, rgb);
  const Image image = read_image(write_bytes("good.png", good));
  EXPECT_EQ(image.pixels, rgb);

  // A wrong checksum on the header, and on the pixel data.
  Bytes bad = good;
  bad[find_chunk(bad, "IHDR") + 4 + 13] ^= 0x5a;
  expect_config_error(write_bytes("ihdr_crc.png", bad), "CRC error");
  bad = good;
  const std::size_t idat = find_chunk(bad, "IDAT");
  const std::size_t idat_length =
      (bad[idat - 4] << 24) | (bad[idat - 3] << 16) | (bad[idat - 2] << 8) | bad[idat - 1];
  bad[idat + 4 + idat_length] ^= 0x01;
  expect_config_error(write_bytes("idat_crc.png", bad), "CRC error");

  // Header fields that make no sense (with valid checksums).
  Bytes header = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  chunk(header, "IHDR", ihdr(5, 4, 3, 2));  // 3-bit RGB does not exist
  chunk(header, "IEND", {});
  expect_config_error(write_bytes("depth.png", header), "cannot decode the PNG image");
  // The first chunk must be IHDR.
  Bytes no_header = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  chunk(no_header, "IEND", {});
  expect_config_error(write_bytes("no_ihdr.png", no_header), "out of place");

  // Absurd sizes: beyond PNG's limit, beyond ours a side, beyond ours in bytes, and zero; each
  // fails before any pixel memory is taken.
  expect_config_error(write_bytes("huge.png", handmade_png(5, 4, rgb, 0x7fffffff, 4)));
  expect_config_error(write_bytes("wide.png", handmade_png(5, 4, rgb, 100000, 4)),
                      "more than the 65535 a side");
  expect_config_error(write_bytes("big.png", handmade_png(5, 4, rgb, 30000, 30000)), "MiB");
  expect_config_error(write_bytes("zero.png", handmade_png(5, 4, rgb, 5, 0)));
  // A header promising more rows than the data holds.
  expect_config_error(write_bytes("short.png", handmade_png(5, 4, rgb, 5, 40)),
                      "Not enough image data");
}

TEST_F(ImageIo, JpegMarkersSizesAndCorruptDataAreChecked) {
  const Bytes rgb = pattern(24, 16, 3, 1, 4);
  write_image(path("good.jpg"), rgb.data(), 16, 24, 3, PixelType::kUInt8);
  const Bytes good = read_bytes(path("good.jpg"));
  // The frame header (SOF0): FF C0, length, precision, height, width.
  std::size_t sof = 0;
  for (std::size_t i = 2; i + 1 < good.size(); ++i) {
    if (good[i] == 0xff && good[i + 1] == 0xc0) {
      sof = i;
      break;
    }
  }
  ASSERT_GT(sof, 0u);
  auto with_size = [&](int width, int height) {
    Bytes b = good;
    b[sof + 5] = std::uint8_t(height >> 8);
    b[sof + 6] = std::uint8_t(height);
    b[sof + 7] = std::uint8_t(width >> 8);
    b[sof + 8] = std::uint8_t(width);
    return b;
  };
  expect_config_error(write_bytes("big.jpg", with_size(65000, 65000)), "MiB");
  expect_config_error(write_bytes("zero.jpg", with_size(24, 0)));
  // More rows than the data holds.
  expect_config_error(write_bytes("tall.jpg", with_size(24, 400)));
  // A precision libjpeg does not decode.
  Bytes precision = good;
  precision[sof + 4] = 12;
  expect_config_error(write_bytes("precision.jpg", precision), "cannot decode the JPEG image");
  // The image data ended by an end-of-image marker early.
  Bytes early = good;
  early.resize(good.size() / 2);
  early.insert(early.end(), {0xff, 0xd9});
  expect_config_error(write_bytes("early.jpg", early), "cannot decode the JPEG image");
  // Only tables, no image.
  expect_config_error(write_bytes("tables.jpg", Bytes{0xff, 0xd8, 0xff, 0xd9}));
}

// Every single-byte change of a small PNG and JPEG either reads (JPEG has no checksums) or gives
// a ConfigError naming the file: never a crash, never another exception.
TEST_F(ImageIo, NoSingleByteCorruptionCrashes) {
  const Bytes rgba = pattern(9, 7, 4, 1, 8), rgb = pattern(9, 7, 3, 1, 8);
  write_image(path("a.png"), rgba.data(), 7, 9, 4, PixelType::kUInt8);
  write_image(path("a.jpg"), rgb.data(), 7, 9, 3, PixelType::kUInt8);
  for (const char* name : {"a.png", "a.jpg"}) {
    const Bytes whole = read_bytes(path(name));
    int errors = 0, reads = 0;
    for (std::size_t i = 0; i < whole.size(); ++i) {
      for (std::uint8_t flip : {0x01, 0x80, 0xff}) {
        Bytes b = whole;
        b[i] ^= flip;
        const std::string file = write_bytes(std::string("x_") + name, b);
        try {
          const Image image = read_image(file);
          EXPECT_EQ(image.pixels.size(), image.row_bytes() * image.height);
          ++reads;
        } catch (const ConfigError& e) {
          EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
          ++errors;
        }
      }
    }
    // PNG's checksums catch every change but those in bytes libpng does not check.
    if (std::string(name) == "a.png") EXPECT_GT(errors, int(3 * whole.size()) * 9 / 10);
    EXPECT_GT(errors, 0) << name;
    RecordProperty(std::string(name) + "_reads", reads);
  }
}

TEST_F(ImageIo, WritingChecksTheFormatAndLeavesNoPartialFile) {
  const Bytes rgba = pattern(4, 3, 4, 1, 2);
  auto expect_write_error = [&](const std::string& file, const std::string& expected,
                                const std::function<void()>& write) {
    try {
      write();
      ADD_FAILURE() << file << ": written, expected an error";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(file)) << file;
  };
  const std::string bmp = path("a.bmp"), jpg = path("a.jpg"), png = path("a.png");
  expect_write_error(bmp, "expected .png, .jpg or .jpeg",
                     [&] { write_image(bmp, rgba.data(), 3, 4, 4, PixelType::kUInt8); });
  expect_write_error(jpg, "no alpha",
                     [&] { write_image(jpg, rgba.data(), 3, 4, 4, PixelType::kUInt8); });
  expect_write_error(jpg, "8-bit",
                     [&] { write_image(jpg, rgba.data(), 3, 2, 1, PixelType::kUInt16); });
  expect_write_error(png, "channels",
                     [&] { write_image(png, rgba.data(), 3, 4, 5, PixelType::kUInt8); });
  expect_write_error(png, "empty",
                     [&] { write_image(png, rgba.data(), 0, 4, 4, PixelType::kUInt8); });
  const std::string nowhere = path("no/such/folder/a.png");
  expect_write_error(nowhere, "No such file",
                     [&] { write_image(nowhere, rgba.data(), 3, 4, 4, PixelType::kUInt8); });
  // A full disk: /dev/full accepts the open and fails every write.
  if (fs::exists("/dev/full")) {
    for (const char* ext : {".png", ".jpg"}) {
      const Bytes big = pattern(300, 300, 3, 1, 1);
      const std::string full = folder_.string() + "/full" + ext;
      fs::create_symlink("/dev/full", full);
      try {
        write_image(full, big.data(), 300, 300, 3, PixelType::kUInt8);
        ADD_FAILURE() << "writing to /dev/full succeeded";
      } catch (const ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("space"), std::string::npos) << e.what();
      }
    }
  }
}

}  // namespace
}  // namespace ambfplus
