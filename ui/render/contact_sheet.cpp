#include "render/contact_sheet.h"

#include <algorithm>
#include <cmath>

namespace wrap::render {

namespace {

constexpr Rgb8 kPaper = {255, 255, 255};
constexpr Rgb8 kFrameLine = {200, 200, 200};

// A one-pixel grey line around a cell.
void Outline(Image& sheet, int x, int y, int w, int h) {
  auto put = [&](int px, int py) {
    if (px < 0 || py < 0 || px >= sheet.width || py >= sheet.height) return;
    std::copy(kFrameLine.begin(), kFrameLine.end(), sheet.at(px, py));
  };
  for (int i = -1; i <= w; ++i) {
    put(x + i, y - 1);
    put(x + i, y + h);
  }
  for (int j = -1; j <= h; ++j) {
    put(x - 1, y + j);
    put(x + w, y + j);
  }
}

}  // namespace

SheetLayout PlanContactSheet(int count, int frame_width, int frame_height, int caption_height,
                             int title_height, const SheetOptions& options) {
  SheetLayout l;
  l.count = std::max(0, count);
  l.columns = options.columns > 0 ? options.columns : std::clamp(l.count, 1, 4);
  l.rows = std::max(1, (l.count + l.columns - 1) / l.columns);
  l.gap = std::max(0, options.gap_px);
  const int wanted = l.columns * frame_width;
  l.shrink = std::max(1, (wanted + options.max_width_px - 1) / std::max(1, options.max_width_px));
  l.cell_width = std::max(1, frame_width / l.shrink);
  l.cell_height = std::max(1, frame_height / l.shrink);
  l.caption_height = std::max(0, caption_height);
  l.title_height = std::max(0, title_height);
  l.width = l.columns * l.cell_width + (l.columns + 1) * l.gap;
  l.height = l.title_height + l.rows * (l.cell_height + l.caption_height) + (l.rows + 1) * l.gap;
  return l;
}

Image ComposeContactSheet(const SheetLayout& l, const std::vector<Image>& cells,
                          const std::vector<Image>& captions, const Image& title) {
  Image sheet = Image::Filled(l.width, l.height, kPaper);
  if (!title.empty()) {
    Blit(title, sheet, (l.width - title.width) / 2,
         l.gap / 2 + (l.title_height - title.height) / 2);
  }
  for (int i = 0; i < l.count && i < static_cast<int>(cells.size()); ++i) {
    const int col = i % l.columns;
    const int row = i / l.columns;
    const int x = l.gap + col * (l.cell_width + l.gap);
    const int y = l.title_height + l.gap + row * (l.cell_height + l.caption_height + l.gap);
    Blit(cells[i], sheet, x, y);
    Outline(sheet, x, y, l.cell_width, l.cell_height);
    if (i < static_cast<int>(captions.size())) Blit(captions[i], sheet, x, y + l.cell_height);
  }
  return sheet;
}

}  // namespace wrap::render
