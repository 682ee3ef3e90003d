#include "ecv/primitives.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/timing.h"
#include "ecv/hex_grid.h"
#include "ecv/surface.h"

namespace ecv {
namespace {

// Per-cell statistics of the monogenic signal.
struct CellStats {
  float max_magnitude = -1.0F;
  cv::Point keypoint{-1, -1};
  double magnitude_sum = 0.0;
  double cos_sum = 0.0;  // sum of m cos(2 theta)
  double sin_sum = 0.0;  // sum of m sin(2 theta)
};

std::vector<CellStats> AccumulateCells(const HexGrid& grid, const MonogenicSignal& signal, const cv::Mat& mask) {
  std::vector<CellStats> cells(static_cast<size_t>(grid.NumCells()));
  for (int y = 0; y < signal.magnitude.rows; ++y) {
    const int* label = grid.Labels().ptr<int>(y);
    const float* magnitude = signal.magnitude.ptr<float>(y);
    const float* odd_x = signal.odd_x.ptr<float>(y);
    const float* odd_y = signal.odd_y.ptr<float>(y);
    const uchar* mask_row = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 0; x < signal.magnitude.cols; ++x) {
      if (mask_row != nullptr && mask_row[x] == 0) continue;
      CellStats& cell = cells[static_cast<size_t>(label[x])];
      const float m = magnitude[x];
      if (m > cell.max_magnitude) {
        cell.max_magnitude = m;
        cell.keypoint = {x, y};
      }
      // m cos(2 theta) and m sin(2 theta) from the odd part o = |o| (cos theta, sin theta), without trigonometry.
      const float odd_squared = odd_x[x] * odd_x[x] + odd_y[x] * odd_y[x];
      if (odd_squared <= 0.0F) continue;
      const float weight = m / odd_squared;
      cell.magnitude_sum += m;
      cell.cos_sum += weight * (odd_x[x] * odd_x[x] - odd_y[x] * odd_y[x]);
      cell.sin_sum += weight * 2.0F * odd_x[x] * odd_y[x];
    }
  }
  return cells;
}

// Canny-style non-maximum suppression: is the magnitude at `p` a maximum along the orientation (across
// the edge)? Beside a strong contour the band-pass rings, and the cells next to it would repeat it.
bool IsRidge(const cv::Mat& magnitude, const cv::Point& p, float orientation) {
  const float m = magnitude.at<float>(p);
  for (const float step : {-1.0F, 1.0F}) {
    const float x = static_cast<float>(p.x) + step * std::cos(orientation);
    const float y = static_cast<float>(p.y) + step * std::sin(orientation);
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= magnitude.cols || y0 + 1 >= magnitude.rows) continue;
    const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
    const float neighbour =
        (1 - fy) * ((1 - fx) * magnitude.at<float>(y0, x0) + fx * magnitude.at<float>(y0, x0 + 1)) +
        fy * ((1 - fx) * magnitude.at<float>(y0 + 1, x0) + fx * magnitude.at<float>(y0 + 1, x0 + 1));
    if (neighbour > m) return false;
  }
  return true;
}

// A cell kept by the classification, before 3D.
struct Candidate {
  PrimitiveType type;
  cv::Point keypoint;
  float magnitude;
  float orientation;
};

// Intrinsic dimensionality (paper Sect. II-A): low magnitude -> homogeneous; low circular variance of
// 2 theta -> edge; otherwise texture.
std::vector<Candidate> Classify(const std::vector<CellStats>& cells, const MonogenicSignal& signal,
                                const EcvOptions& options, ExtractionCounts* counts) {
  std::vector<Candidate> candidates;
  for (const CellStats& cell : cells) {
    if (cell.keypoint.x < 0) continue;  // entirely outside the mask
    ++counts->cells;
    if (cell.max_magnitude < options.min_magnitude) {
      ++counts->homogeneous;
      continue;
    }
    const double resultant = std::hypot(cell.cos_sum, cell.sin_sum) / std::max(cell.magnitude_sum, 1e-12);
    const bool edge = 1.0 - resultant < options.max_edge_variance;
    ++(edge ? counts->edge_cells : counts->texture_cells);
    const float orientation = signal.orientation.at<float>(cell.keypoint);
    if (edge && options.edge_nms && !IsRidge(signal.magnitude, cell.keypoint, orientation)) {
      ++counts->suppressed;
      continue;
    }
    candidates.push_back(
        {edge ? PrimitiveType::kSegment : PrimitiveType::kTexlet, cell.keypoint, cell.max_magnitude, orientation});
  }
  return candidates;
}

std::vector<Primitive> Reconstruct(const RgbdFrame& frame, const std::vector<Candidate>& candidates,
                                   const EcvOptions& options, ExtractionCounts* counts) {
  const SurfaceOptions surface_options{options.surface_radius_m, options.depth_gap_m, options.color_radius_px};
  std::vector<Primitive> primitives;
  primitives.reserve(candidates.size());
  for (const Candidate& candidate : candidates) {
    const std::optional<LocalSurface> surface = ReconstructSurface(frame, candidate.keypoint, surface_options);
    if (!surface) {
      ++counts->no_depth;
      continue;
    }
    Primitive primitive;
    primitive.type = candidate.type;
    primitive.position = surface->position;
    primitive.color = surface->color;
    primitive.pixel =
        Eigen::Vector2f(static_cast<float>(candidate.keypoint.x), static_cast<float>(candidate.keypoint.y));
    primitive.magnitude = candidate.magnitude;
    primitive.image_orientation = candidate.orientation;
    if (candidate.type == PrimitiveType::kTexlet) {
      if (surface->normal.isZero()) {
        ++counts->no_surface;
        continue;
      }
      primitive.orientation = surface->normal;
      ++counts->texlets;
    } else {
      primitive.orientation = EdgeDirection(frame.camera, primitive.pixel, candidate.orientation, *surface);
      ++counts->segments;
    }
    primitives.push_back(primitive);
  }
  return primitives;
}

}  // namespace

const char* ToString(PrimitiveType type) {
  return type == PrimitiveType::kSegment ? "segment" : "texlet";
}

void EcvOptions::Check() const {
  monogenic.Check();
  auto require = [](bool ok, const char* field, const char* expected, double value) {
    if (!ok) ThrowInputError("ECV options", field, expected, std::to_string(value));
  };
  require(grid_spacing_px >= 2.0 && std::isfinite(grid_spacing_px), "grid_spacing_px", "at least 2 pixels",
          grid_spacing_px);
  require(min_magnitude >= 0.0 && std::isfinite(min_magnitude), "min_magnitude", "a magnitude >= 0", min_magnitude);
  require(max_edge_variance >= 0.0 && max_edge_variance <= 1.0, "max_edge_variance", "a variance in [0, 1]",
          max_edge_variance);
  require(surface_radius_m > 0.0 && std::isfinite(surface_radius_m), "surface_radius_m", "a radius > 0 m",
          surface_radius_m);
  require(depth_gap_m > 0.0 && std::isfinite(depth_gap_m), "depth_gap_m", "a gap > 0 m", depth_gap_m);
  require(color_radius_px >= 0 && color_radius_px <= 20, "color_radius_px", "0 to 20 pixels", color_radius_px);
}

ExtractionResult ExtractPrimitives(const RgbdFrame& frame, const EcvOptions& options, const cv::Mat& mask) {
  options.Check();
  frame.Check();
  if (!mask.empty() && (mask.size() != frame.color.size() || mask.type() != CV_8UC1)) {
    ThrowInputError(frame.name, "mask", "an 8-bit single-channel mask of the image's size");
  }
  ExtractionResult result;
  Clock::time_point start = Clock::now();
  cv::Mat grey;
  cv::cvtColor(frame.color, grey, cv::COLOR_RGB2GRAY);
  const MonogenicSignal signal = ComputeMonogenic(grey, options.monogenic);
  result.timings.monogenic_ms = MillisecondsSince(start);

  start = Clock::now();
  thread_local std::unique_ptr<HexGrid> grid;  // the same for every frame of a stream
  if (!grid || grid->ImageSize() != grey.size() || grid->Spacing() != options.grid_spacing_px) {
    grid = std::make_unique<HexGrid>(grey.size(), options.grid_spacing_px);
  }
  const std::vector<CellStats> cells = AccumulateCells(*grid, signal, mask);
  result.timings.grid_ms = MillisecondsSince(start);

  start = Clock::now();
  const std::vector<Candidate> candidates = Classify(cells, signal, options, &result.counts);
  result.timings.classify_ms = MillisecondsSince(start);

  start = Clock::now();
  result.primitives = Reconstruct(frame, candidates, options, &result.counts);
  result.timings.reconstruct_ms = MillisecondsSince(start);
  return result;
}

std::vector<Eigen::Vector3f> PrimitivePositions(const std::vector<Primitive>& primitives) {
  std::vector<Eigen::Vector3f> positions;
  positions.reserve(primitives.size());
  for (const Primitive& primitive : primitives) positions.push_back(primitive.position);
  return positions;
}

}  // namespace ecv
