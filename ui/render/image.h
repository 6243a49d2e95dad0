// RGB images: PNG files (through stb), comparison with a tolerance, difference images and
// simple compositing, for renders, contact sheets and golden-image tests.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/result.h"

namespace wrap::render {

/// An 8-bit RGB colour.
using Rgb8 = std::array<std::uint8_t, 3>;

/// An 8-bit RGB image, rows top to bottom, no padding.
struct Image {
  int width = 0;                  ///< [px].
  int height = 0;                 ///< [px].
  std::vector<std::uint8_t> rgb;  ///< width * height * 3 bytes.

  /// A width x height image filled with `color`.
  static Image Filled(int width, int height, Rgb8 color);
  /// Pointer to pixel (x, y) (no bounds check).
  std::uint8_t* at(int x, int y) { return rgb.data() + 3 * (static_cast<size_t>(y) * width + x); }
  const std::uint8_t* at(int x, int y) const {
    return rgb.data() + 3 * (static_cast<size_t>(y) * width + x);
  }
  bool empty() const { return width <= 0 || height <= 0; }
};

/// Encodes `image` as PNG and writes it atomically. Fails with kIo naming the file.
Result<void> WritePng(const Image& image, const std::filesystem::path& path);

/// Reads a PNG (any channel count, converted to RGB). Fails with kIo naming the file.
Result<Image> ReadPng(const std::filesystem::path& path);

/// How two images differ, channel by channel.
struct ImageDifference {
  bool same_size = false;        ///< False: nothing else is meaningful.
  double fraction_within = 0.0;  ///< Channel values differing by at most the tolerance, [0, 1].
  int max_difference = 0;        ///< Largest absolute channel difference [0, 255].
  double mean_difference = 0.0;  ///< Mean absolute channel difference.
};

/// Compares `actual` with `expected`: a channel value matches when within `tolerance` levels.
ImageDifference CompareImages(const Image& actual, const Image& expected, int tolerance);

/// A visual difference: grey (the expected image, faded) where channels agree within
/// `tolerance`, red where they do not, brighter for larger differences. Same size as the
/// inputs (empty when their sizes differ).
Image DifferenceImage(const Image& actual, const Image& expected, int tolerance);

/// The image shrunk by an integer `factor` (box filter); a copy when factor <= 1.
Image Downscale(const Image& image, int factor);

/// Copies `src` into `dst` with its top-left corner at (x, y), clipped to `dst`.
void Blit(const Image& src, Image& dst, int x, int y);

}  // namespace wrap::render
