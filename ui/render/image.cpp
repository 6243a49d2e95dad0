#include "render/image.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "core/file_io.h"

namespace wrap::render {

Image Image::Filled(int width, int height, Rgb8 color) {
  Image image;
  image.width = std::max(0, width);
  image.height = std::max(0, height);
  image.rgb.resize(3 * static_cast<size_t>(image.width) * image.height);
  for (size_t i = 0; i < image.rgb.size(); i += 3) {
    image.rgb[i] = color[0];
    image.rgb[i + 1] = color[1];
    image.rgb[i + 2] = color[2];
  }
  return image;
}

Result<void> WritePng(const Image& image, const std::filesystem::path& path) {
  if (image.empty() || image.rgb.size() != 3 * static_cast<size_t>(image.width) * image.height) {
    return Fail(ErrorCode::kInternal, "PNG '" + path.string() + "': malformed image");
  }
  std::string bytes;
  auto sink = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), size);
  };
  if (!stbi_write_png_to_func(sink, &bytes, image.width, image.height, 3, image.rgb.data(),
                              3 * image.width)) {
    return Fail(ErrorCode::kIo, "PNG '" + path.string() + "': encoding failed");
  }
  return WriteFileAtomic(path, bytes);
}

Result<Image> ReadPng(const std::filesystem::path& path) {
  auto bytes = ReadFile(path);
  if (!bytes) return std::unexpected(bytes.error());
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes->data()),
                                              static_cast<int>(bytes->size()), &w, &h, &n, 3);
  if (!data) {
    const char* why = stbi_failure_reason();
    return Fail(ErrorCode::kIo, "PNG '" + path.string() + "': cannot decode (" +
                                    (why ? why : "unknown reason") + ")");
  }
  Image image;
  image.width = w;
  image.height = h;
  image.rgb.assign(data, data + 3 * static_cast<size_t>(w) * h);
  stbi_image_free(data);
  return image;
}

ImageDifference CompareImages(const Image& actual, const Image& expected, int tolerance) {
  ImageDifference d;
  d.same_size = actual.width == expected.width && actual.height == expected.height &&
                actual.rgb.size() == expected.rgb.size();
  if (!d.same_size || actual.rgb.empty()) return d;
  size_t within = 0;
  double sum = 0.0;
  for (size_t i = 0; i < actual.rgb.size(); ++i) {
    const int diff = std::abs(int(actual.rgb[i]) - int(expected.rgb[i]));
    within += diff <= tolerance;
    d.max_difference = std::max(d.max_difference, diff);
    sum += diff;
  }
  d.fraction_within = double(within) / double(actual.rgb.size());
  d.mean_difference = sum / double(actual.rgb.size());
  return d;
}

Image DifferenceImage(const Image& actual, const Image& expected, int tolerance) {
  if (actual.width != expected.width || actual.height != expected.height) return {};
  Image out = Image::Filled(actual.width, actual.height, {0, 0, 0});
  for (int y = 0; y < actual.height; ++y) {
    for (int x = 0; x < actual.width; ++x) {
      const std::uint8_t* a = actual.at(x, y);
      const std::uint8_t* e = expected.at(x, y);
      int worst = 0;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(a[c]) - int(e[c])));
      std::uint8_t* o = out.at(x, y);
      if (worst <= tolerance) {
        const int grey = (int(e[0]) + int(e[1]) + int(e[2])) / 3;
        o[0] = o[1] = o[2] = static_cast<std::uint8_t>(160 + grey * 80 / 255);
      } else {
        o[0] = static_cast<std::uint8_t>(std::min(255, 128 + 2 * worst));
        o[1] = o[2] = 0;
      }
    }
  }
  return out;
}

Image Downscale(const Image& image, int factor) {
  if (factor <= 1) return image;
  const int w = std::max(1, image.width / factor);
  const int h = std::max(1, image.height / factor);
  Image out = Image::Filled(w, h, {0, 0, 0});
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      int sum[3] = {0, 0, 0};
      int n = 0;
      for (int dy = 0; dy < factor && y * factor + dy < image.height; ++dy) {
        for (int dx = 0; dx < factor && x * factor + dx < image.width; ++dx) {
          const std::uint8_t* p = image.at(x * factor + dx, y * factor + dy);
          for (int c = 0; c < 3; ++c) sum[c] += p[c];
          ++n;
        }
      }
      for (int c = 0; c < 3; ++c) out.at(x, y)[c] = static_cast<std::uint8_t>((sum[c] + n / 2) / n);
    }
  }
  return out;
}

void Blit(const Image& src, Image& dst, int x, int y) {
  for (int sy = 0; sy < src.height; ++sy) {
    const int dy = y + sy;
    if (dy < 0 || dy >= dst.height) continue;
    const int x0 = std::max(0, -x);
    const int x1 = std::min(src.width, dst.width - x);
    if (x1 <= x0) continue;
    std::copy_n(src.at(x0, sy), 3 * (x1 - x0), dst.at(x + x0, dy));
  }
}

}  // namespace wrap::render
