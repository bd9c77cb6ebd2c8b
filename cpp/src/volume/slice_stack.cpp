#include <algorithm>
#include <filesystem>
#include <map>
#include <unordered_map>

#include "ambfplus/errors.h"
#include "ambfplus/io/image.h"
#include "ambfplus/volume/volume_io.h"
#include "util/strings.h"
#include "volume/grid_access.h"

namespace fs = std::filesystem;

namespace ambfplus {
namespace {

// Slice files by index: "<prefix><digits>.<format>", any padding, extension in any case.
std::map<int, fs::path> find_slices(const SliceStackSpec& spec) {
  std::error_code ec;
  if (!fs::is_directory(spec.folder, ec)) throw AssetNotFound(spec.folder, "slice folder");
  std::map<int, fs::path> slices;
  const std::string ext = "." + to_lower(spec.format);
  for (const auto& entry : fs::directory_iterator(spec.folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (to_lower(entry.path().extension().string()) != ext) continue;
    if (name.compare(0, spec.prefix.size(), spec.prefix) != 0) continue;
    const std::string digits =
        name.substr(spec.prefix.size(), name.size() - spec.prefix.size() - ext.size());
    if (digits.empty() || digits.size() > 9 ||
        !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      continue;
    }
    const int index = std::stoi(digits);
    if (spec.count >= 0 && index > spec.count) continue;
    auto [it, inserted] = slices.emplace(index, entry.path());
    if (!inserted) {
      throw ConfigError(entry.path().string(), "slice " + std::to_string(index) +
                                                   " also exists as " + it->second.string());
    }
  }
  return slices;
}

// A slice as 8-bit grey, RGB or RGBA: 16-bit samples rounded to 8 bits, grey and alpha as RGBA.
Image read_slice(const fs::path& path) {
  Image image = read_image(path.string());
  if (image.type == PixelType::kUInt16) {
    const std::size_t n = image.pixels.size() / 2;
    std::vector<std::uint8_t> narrow(n);
    const auto* wide = reinterpret_cast<const std::uint16_t*>(image.pixels.data());
    // round(v / 257): 65535 maps to 255, and every 8-bit value v * 257 back to v.
    for (std::size_t i = 0; i < n; ++i)
      narrow[i] = static_cast<std::uint8_t>((wide[i] + 128) / 257);
    image.pixels = std::move(narrow);
    image.type = PixelType::kUInt8;
  }
  if (image.channels == 2) {
    const std::size_t n = std::size_t(image.width) * image.height;
    std::vector<std::uint8_t> rgba(4 * n);
    for (std::size_t i = 0; i < n; ++i) {
      rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = image.pixels[2 * i];
      rgba[4 * i + 3] = image.pixels[2 * i + 1];
    }
    image.pixels = std::move(rgba);
    image.channels = 4;
  }
  return image;
}

std::uint32_t pack(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  return (std::uint32_t(r) << 16) | (std::uint32_t(g) << 8) | b;
}

}  // namespace

std::shared_ptr<VolumeData> load_slice_stack(const SliceStackSpec& spec) {
  if (spec.count == 0 || spec.count < -1) {
    throw ArgumentError("slice stack " + spec.folder + ": count " + std::to_string(spec.count) +
                        " leaves no slice (expected the largest slice index, >= 1, or -1 for "
                        "every slice)");
  }
  if (spec.alpha_threshold < 0 || spec.alpha_threshold > 255) {
    throw ArgumentError("slice stack " + spec.folder + ": alpha_threshold " +
                        std::to_string(spec.alpha_threshold) + " is outside 0..255");
  }
  check_volume_sizes(spec.dimensions, "slice stack " + spec.folder + ": dimensions");
  const std::map<int, fs::path> slices = find_slices(spec);
  if (slices.size() > 8192) {
    throw ConfigError(
        spec.folder, std::to_string(slices.size()) + " slices, more than a volume may have (8192)");
  }
  if (slices.empty() || slices.begin()->first != 0) {
    throw AssetNotFound((fs::path(spec.folder) / (spec.prefix + "0." + spec.format)).string(),
                        "first slice of the stack");
  }
  // The stack is slices 0..n-1; a gap before a present slice is an error, not the stack's end.
  int n = 0;
  while (slices.count(n)) ++n;
  if (slices.size() != static_cast<std::size_t>(n)) {
    const auto after = slices.upper_bound(n);
    throw ConfigError(
        (fs::path(spec.folder) / (spec.prefix + std::to_string(n) + "." + spec.format)).string(),
        "slice " + std::to_string(n) + " is missing but slice " + std::to_string(after->first) +
            " (" + after->second.filename().string() + ") exists");
  }

  // Read every slice once; colours map to labels through a cache.
  std::vector<Image> images;
  images.reserve(n);
  for (int k = 0; k < n; ++k) {
    Image image = read_slice(slices.at(k));
    if (k > 0 && (image.height != images[0].height || image.width != images[0].width)) {
      throw ConfigError(slices.at(k).string(), "slice is " + std::to_string(image.width) + "x" +
                                                   std::to_string(image.height) +
                                                   " but slice 0 is " +
                                                   std::to_string(images[0].width) + "x" +
                                                   std::to_string(images[0].height));
    }
    if (image.width > 8192 || image.height > 8192) {
      throw ConfigError(slices.at(k).string(), "slice is " + std::to_string(image.width) + "x" +
                                                   std::to_string(image.height) +
                                                   ", larger than a volume may be (8192)");
    }
    if (k > 0 && image.channels != images[0].channels) {
      throw ConfigError(slices.at(k).string(), "slice has " + std::to_string(image.channels) +
                                                   " channels but slice 0 has " +
                                                   std::to_string(images[0].channels));
    }
    images.push_back(std::move(image));
  }
  const int width = images[0].width, height = images[0].height, channels = images[0].channels;

  LabelTable table = spec.labels;
  std::unordered_map<std::uint32_t, std::uint16_t> colour_to_label;
  if (channels >= 3 && table.empty()) {
    // One label per colour found, most frequent first (ties by colour value).
    std::unordered_map<std::uint32_t, std::int64_t> counts;
    for (const Image& image : images) {
      for (int r = 0; r < height; ++r) {
        const std::uint8_t* px = image.row(r);
        for (int c = 0; c < width; ++c, px += channels) {
          const bool solid =
              channels == 4 ? px[3] >= spec.alpha_threshold : (px[0] | px[1] | px[2]) != 0;
          if (solid) ++counts[pack(px[0], px[1], px[2])];
        }
      }
    }
    std::vector<std::pair<std::uint32_t, std::int64_t>> order(counts.begin(), counts.end());
    std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
      return a.second != b.second ? a.second > b.second : a.first < b.first;
    });
    if (order.size() > 65535) {
      throw ConfigError(spec.folder, "the slices hold " + std::to_string(order.size()) +
                                         " colours, more than 65535 labels: give a label table");
    }
    for (std::size_t i = 0; i < order.size(); ++i) {
      Label l;
      l.id = static_cast<std::uint16_t>(i + 1);
      l.name = "label_" + std::to_string(l.id);
      l.color = {std::uint8_t(order[i].first >> 16), std::uint8_t(order[i].first >> 8),
                 std::uint8_t(order[i].first)};
      table.add(l);
      colour_to_label[order[i].first] = l.id;
    }
  }
  if (channels == 1 && table.empty()) {
    // Grey slices carry label ids; name the ids found.
    std::vector<bool> seen(256, false);
    for (const Image& image : images) {
      for (int r = 0; r < height; ++r) {
        const std::uint8_t* px = image.row(r);
        for (int c = 0; c < width; ++c) seen[px[c]] = true;
      }
    }
    for (int v = 1; v < 256; ++v) {
      if (!seen[v]) continue;
      Label l;
      l.id = static_cast<std::uint16_t>(v);
      l.name = "label_" + std::to_string(v);
      l.color = {std::uint8_t(v), std::uint8_t(v), std::uint8_t(v)};
      table.add(l);
    }
  }
  const LabelType type = table.max_id() > 255 ? LabelType::kUInt16 : LabelType::kUInt8;
  auto volume = std::make_shared<VolumeData>(std::array<int, 3>{width, height, n}, spec.dimensions,
                                             type, table);
  visit_labels(type, volume->label_data(), [&](auto* labels) {
    using T = std::remove_pointer_t<decltype(labels)>;
    for (int k = 0; k < n; ++k) {
      const Image& image = images[k];
      for (int r = 0; r < height; ++r) {
        const std::uint8_t* px = image.row(r);
        T* out = labels + volume->linear_index(0, height - 1 - r, k);
        for (int c = 0; c < width; ++c, px += channels) {
          if (channels == 1) {
            out[c] = static_cast<T>(px[0]);
            continue;
          }
          const bool solid =
              channels == 4 ? px[3] >= spec.alpha_threshold : (px[0] | px[1] | px[2]) != 0;
          if (!solid) {
            out[c] = 0;
            continue;
          }
          const std::uint32_t rgb = pack(px[0], px[1], px[2]);
          auto it = colour_to_label.find(rgb);
          if (it == colour_to_label.end()) {
            it = colour_to_label.emplace(rgb, table.nearest({px[0], px[1], px[2]})).first;
          }
          out[c] = static_cast<T>(it->second);
        }
      }
    }
  });
  volume->commit();
  volume->set_source(spec.folder);
  return volume;
}

void save_slice_stack(const VolumeData& volume, const std::string& folder,
                      const std::string& prefix, const std::string& format) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (!fs::is_directory(folder, ec)) throw ConfigError(folder, "cannot create the slice folder");
  const auto& shape = volume.shape();
  const int width = shape[0], height = shape[1];
  std::vector<std::array<std::uint8_t, 3>> colours(65536, {255, 255, 255});
  for (const Label& l : volume.label_table().labels()) colours[l.id] = l.color;
  Image image;
  image.width = width;
  image.height = height;
  image.channels = 4;
  image.pixels.resize(image.row_bytes() * height);
  visit_labels(volume.label_type(), volume.label_data(), [&](const auto* labels) {
    for (int k = 0; k < shape[2]; ++k) {
      for (int r = 0; r < height; ++r) {
        std::uint8_t* px = image.row(r);
        const auto* in = labels + volume.linear_index(0, height - 1 - r, k);
        for (int c = 0; c < width; ++c, px += 4) {
          const auto l = in[c];
          const auto& rgb = colours[l];
          px[0] = l ? rgb[0] : 0;
          px[1] = l ? rgb[1] : 0;
          px[2] = l ? rgb[2] : 0;
          px[3] = l ? 255 : 0;
        }
      }
      const std::string path =
          (fs::path(folder) / (prefix + std::to_string(k) + "." + format)).string();
      write_image(path, image);
    }
  });
}

}  // namespace ambfplus
