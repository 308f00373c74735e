#pragma once
// A pressure field deposited on the forward model's grid: point weights spread bilinearly
// over the four cells around each point, then the touched cells emitted as loads scaled to
// a force. The closed-form fields that are integrated by rings or strips (a flat punch, a
// cone) deposit through it.

#include <Eigen/Core>
#include <vector>

#include "sensors/tactile_forward_model.h"

namespace sedbridge::sensors {

class GridSplat {
 public:
  /// @param origin  the grid's first cell centre, pad frame [mm]
  /// @param h       the cell spacing [mm], > 0
  /// @param n       cells to a side
  /// Uses the calling thread's buffers (one splat at a time a thread).
  GridSplat(const Eigen::Vector2d& origin, double h, int n);
  /// Adds weight w at the pad point (x_mm, y_mm); off the grid it counts toward the total only.
  void Deposit(double x_mm, double y_mm, double w);
  /// Appends the touched cells in cell order, each as a normal load, the weights scaled so
  /// that all deposited (on the grid or not) sum to force_N; nothing if no weight was.
  void Emit(double force_N, std::vector<SurfaceLoad>* loads);

 private:
  void Add(int col, int row, double w);

  Eigen::Vector2d origin_;
  double h_;
  int n_;
  double total_ = 0;
  std::vector<double>& grid_;
  std::vector<int>& touched_;
};

}  // namespace sedbridge::sensors
