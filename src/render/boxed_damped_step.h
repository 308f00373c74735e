#pragma once
// The damped Gauss-Newton step minimized on a box: the step d over variables u in [0, box]
// that minimizes g.d + 1/2 d^T H d with u + d kept in the box by holding each variable
// that the step would take past a bound at that bound, and solving the others again with it
// held, until none leaves (a projected active set from the unconstrained step). The
// unconstrained step clipped to the box is not that: with coupled variables the model can
// say the clipped step raises the cost, and a trial evaluated there is wasted.

#include <Eigen/Core>

namespace sedbridge::render {

/// @param H    symmetric positive definite (the damped Gauss-Newton matrix), m x m
/// @param g    gradient at u, m
/// @param u    current values, each in [0, box]
/// @param box  upper bounds, m (>= 0)
/// @return d, with 0 <= u + d <= box; non-finite solves give 0 for that variable.
Eigen::VectorXd BoxedDampedStep(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const Eigen::VectorXd& u,
                                const Eigen::VectorXd& box);

}  // namespace sedbridge::render
