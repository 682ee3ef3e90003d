#include "ecv/hex_grid.h"

#include <cmath>
#include <limits>

#include "core/error.h"

namespace ecv {

HexGrid::HexGrid(cv::Size size, double spacing_px) : spacing_(spacing_px) {
  if (!(spacing_px >= 2.0) || !std::isfinite(spacing_px)) {
    ThrowInputError("hexagonal grid", "spacing_px", "a spacing of at least 2 pixels", std::to_string(spacing_px));
  }
  CV_Assert(size.width > 0 && size.height > 0);
  const double row_step = spacing_px * std::sqrt(3.0) / 2.0;
  const int rows = static_cast<int>(std::ceil(size.height / row_step)) + 1;
  const int columns = static_cast<int>(std::ceil(size.width / spacing_px)) + 2;
  auto centre_x = [&](int row, int column) { return column * spacing_px - (row % 2 == 1 ? spacing_px / 2.0 : 0.0); };

  // Lattice index -> cell index, keeping only centres whose hexagon meets the image.
  std::vector<int> cell_of(static_cast<size_t>(rows * columns), -1);
  labels_.create(size, CV_32SC1);
  for (int y = 0; y < size.height; ++y) {
    const int row0 = static_cast<int>(std::floor(y / row_step));
    int* label = labels_.ptr<int>(y);
    for (int x = 0; x < size.width; ++x) {
      // The nearest centre lies in row0 or row0 + 1, at the nearest column of that row.
      double best = std::numeric_limits<double>::max();
      int best_index = 0;
      for (int row = row0; row <= std::min(row0 + 1, rows - 1); ++row) {
        const double shift = row % 2 == 1 ? -spacing_px / 2.0 : 0.0;
        const int column = std::clamp(static_cast<int>(std::lround((x - shift) / spacing_px)), 0, columns - 1);
        const double dx = x - centre_x(row, column), dy = y - row * row_step;
        const double squared = dx * dx + dy * dy;
        if (squared < best) {
          best = squared;
          best_index = row * columns + column;
        }
      }
      int& cell = cell_of[static_cast<size_t>(best_index)];
      if (cell < 0) {
        cell = static_cast<int>(centres_.size());
        const int row = best_index / columns, column = best_index % columns;
        centres_.emplace_back(static_cast<float>(centre_x(row, column)), static_cast<float>(row * row_step));
      }
      label[x] = cell;
    }
  }
}

}  // namespace ecv
