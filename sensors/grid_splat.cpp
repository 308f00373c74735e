#include "sensors/grid_splat.h"

#include <algorithm>
#include <cmath>

namespace sedbridge::sensors {
namespace {

// Dense accumulation over the grid and the touched cells listed: a thread's buffers.
std::vector<double>& ThreadGrid() {
  thread_local std::vector<double> grid;
  return grid;
}
std::vector<int>& ThreadTouched() {
  thread_local std::vector<int> touched;
  return touched;
}

}  // namespace

GridSplat::GridSplat(const Eigen::Vector2d& origin, double h, int n)
    : origin_(origin), h_(h), n_(n), grid_(ThreadGrid()), touched_(ThreadTouched()) {
  grid_.assign(size_t(n) * size_t(n), 0.0);
  touched_.clear();
}

void GridSplat::Add(int col, int row, double w) {
  if (col < 0 || row < 0 || col >= n_ || row >= n_ || !(w > 0)) return;
  double& g = grid_[size_t(row) * size_t(n_) + size_t(col)];
  if (g == 0) touched_.push_back(row * n_ + col);
  g += w;
}

void GridSplat::Deposit(double x_mm, double y_mm, double w) {
  total_ += w;
  const double gx = (x_mm - origin_.x()) / h_, gy = (y_mm - origin_.y()) / h_;
  const double fx = std::floor(gx), fy = std::floor(gy), tx = gx - fx, ty = gy - fy;
  const int i = int(fx), j = int(fy);
  Add(i, j, w * (1 - tx) * (1 - ty));
  Add(i + 1, j, w * tx * (1 - ty));
  Add(i, j + 1, w * (1 - tx) * ty);
  Add(i + 1, j + 1, w * tx * ty);
}

void GridSplat::Emit(double force_N, std::vector<SurfaceLoad>* loads) {
  if (!(total_ > 0)) return;
  std::sort(touched_.begin(), touched_.end());
  const double scale = force_N / total_;
  for (const int cell : touched_) loads->push_back({cell, scale * grid_[size_t(cell)], 0, 0});
}

}  // namespace sedbridge::sensors
