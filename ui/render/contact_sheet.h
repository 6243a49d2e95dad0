// Contact sheets: snapshots in a grid, each with a caption strip below it and an optional title
// above, like the snapshot figures of a paper. Pure pixel work: the captions are drawn by the
// caller (OffscreenRenderer::RenderText), so this needs no GL.
#pragma once

#include <vector>

#include "render/image.h"

namespace wrap::render {

/// Options of PlanContactSheet.
struct SheetOptions {
  int columns = 0;          ///< Columns; 0: up to 4 (fewer for fewer snapshots).
  int max_width_px = 2560;  ///< Snapshots are shrunk by an integer factor to stay within this.
  int gap_px = 12;          ///< Space between and around cells [px].
};

/// Where everything goes on a sheet.
struct SheetLayout {
  int count = 0;           ///< Snapshots.
  int columns = 1;         ///< Grid columns.
  int rows = 1;            ///< Grid rows.
  int shrink = 1;          ///< Integer downscale factor of the snapshots.
  int cell_width = 0;      ///< Snapshot width on the sheet [px].
  int cell_height = 0;     ///< Snapshot height on the sheet [px].
  int caption_height = 0;  ///< Caption strip under each snapshot [px].
  int title_height = 0;    ///< Title strip at the top [px] (0: none).
  int gap = 0;             ///< [px].
  int width = 0;           ///< Sheet width [px].
  int height = 0;          ///< Sheet height [px].
};

/// Lays out `count` snapshots of `frame_width` x `frame_height` with captions of
/// `caption_height` and a title of `title_height` (0: none) [px].
SheetLayout PlanContactSheet(int count, int frame_width, int frame_height, int caption_height,
                             int title_height, const SheetOptions& options = {});

/// Composes the sheet on white: `cells` (the snapshots, already shrunk by layout.shrink),
/// `captions` (layout.cell_width x layout.caption_height each; missing ones are left blank) and
/// `title` (centred in the title strip; may be empty).
Image ComposeContactSheet(const SheetLayout& layout, const std::vector<Image>& cells,
                          const std::vector<Image>& captions, const Image& title);

}  // namespace wrap::render
