#include <morphomap/growth.hpp>

#include "common/validation.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace morphomap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <class Points, class Cells>
void require_growth_input(const Points& before, const Points& after, const Cells& cells, double dt, const char* name) {
  if (after.rows() != before.rows()) {
    detail::invalid("after", "has " + std::to_string(after.rows()) + " points but before has " +
                                 std::to_string(before.rows()) + ": give the same points at the two times");
  }
  for (Index c = 0; c < cells.rows(); ++c) {
    for (Index i = 0; i < cells.cols(); ++i) {
      if (cells(c, i) < 0 || cells(c, i) >= before.rows()) {
        detail::invalid(name, "row " + std::to_string(c) + " refers to point " + std::to_string(cells(c, i)) +
                                  ", outside 0.." + std::to_string(before.rows() - 1));
      }
    }
  }
  if (!(dt > 0) || !std::isfinite(dt)) detail::invalid("dt", "must be a finite time > 0");
}

}  // namespace

CurveGrowth curve_growth(const Points2Ref& before, const Points2Ref& after, const SegmentsRef& segments, double dt,
                         bool counter_clockwise) {
  require_growth_input(before, after, segments, dt, "segments");
  const Index count = segments.rows();
  CurveGrowth out{Vector(count), Points2(count, 2), Vector(count), Points2(count, 2)};
  const double side = counter_clockwise ? 1.0 : -1.0;
  tbb::parallel_for(tbb::blocked_range<Index>(0, count, 4096), [&](const tbb::blocked_range<Index>& range) {
    for (Index s = range.begin(); s < range.end(); ++s) {
      const Index a = segments(s, 0), b = segments(s, 1);
      const Vec2 edge = (before.row(b) - before.row(a)).transpose();
      const Vec2 moved = (after.row(b) - after.row(a)).transpose();
      const double length = edge.norm();
      if (!(length > 0) || !moved.allFinite() || !edge.allFinite()) {
        out.stretch(s) = out.normal_velocity(s) = kNaN;
        out.direction.row(s).setConstant(kNaN);
        out.tangential_velocity.row(s).setConstant(kNaN);
        continue;
      }
      const Vec2 tangent = edge / length, normal = side * Vec2(tangent.y(), -tangent.x());
      const Vec2 velocity = 0.5 * ((after.row(a) - before.row(a)) + (after.row(b) - before.row(b))).transpose() / dt;
      out.stretch(s) = moved.norm() / length;
      out.direction.row(s) = tangent.transpose();
      out.normal_velocity(s) = velocity.dot(normal);
      out.tangential_velocity.row(s) = (velocity.dot(tangent) * tangent).transpose();
    }
  });
  return out;
}

SurfaceGrowth surface_growth(const Points3Ref& before, const Points3Ref& after, const FacesRef& faces, double dt) {
  require_growth_input(before, after, faces, dt, "faces");
  const Index count = faces.rows();
  SurfaceGrowth out{Stretches(count, 2), Points3(count, 3), Points3(count, 3), Vector(count), Points3(count, 3)};
  tbb::parallel_for(tbb::blocked_range<Index>(0, count, 2048), [&](const tbb::blocked_range<Index>& range) {
    for (Index f = range.begin(); f < range.end(); ++f) {
      const Index a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
      const Eigen::Vector3d u = (before.row(b) - before.row(a)).transpose(),
                            v = (before.row(c) - before.row(a)).transpose();
      Eigen::Matrix<double, 3, 2> moved;
      moved.col(0) = (after.row(b) - after.row(a)).transpose();
      moved.col(1) = (after.row(c) - after.row(a)).transpose();
      const Eigen::Vector3d cross = u.cross(v);
      const double twice_area = cross.norm();
      if (!(twice_area > 0) || !moved.allFinite() || !u.allFinite() || !v.allFinite()) {
        out.stretches.row(f).setConstant(kNaN);
        out.major.row(f).setConstant(kNaN);
        out.minor.row(f).setConstant(kNaN);
        out.normal_velocity(f) = kNaN;
        out.tangential_velocity.row(f).setConstant(kNaN);
        continue;
      }
      // An orthonormal basis (e1, e2) of the triangle's plane before, the edges in it (P), and
      // the map G = moved P^-1 from those plane coordinates to the triangle after.
      const Eigen::Vector3d normal = cross / twice_area, e1 = u.normalized(), e2 = normal.cross(e1);
      Eigen::Matrix2d plane;
      plane << e1.dot(u), e1.dot(v), e2.dot(u), e2.dot(v);
      const Eigen::Matrix<double, 3, 2> map = moved * plane.inverse();
      // G^T G = V diag(lambda^2) V^T: the right Cauchy-Green tensor in the plane.
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> tensor;
      tensor.computeDirect(map.transpose() * map);
      const double major = std::sqrt(std::max(tensor.eigenvalues()(1), 0.0)),
                   minor = std::sqrt(std::max(tensor.eigenvalues()(0), 0.0));
      out.stretches(f, 0) = major;
      out.stretches(f, 1) = minor;
      if (major - minor > kIsotropicTolerance * major) {
        const Eigen::Vector2d first = tensor.eigenvectors().col(1), second = tensor.eigenvectors().col(0);
        out.major.row(f) = (first.x() * e1 + first.y() * e2).transpose();
        out.minor.row(f) = (second.x() * e1 + second.y() * e2).transpose();
      } else {
        out.major.row(f).setConstant(kNaN);
        out.minor.row(f).setConstant(kNaN);
      }
      const Eigen::Vector3d velocity =
          ((after.row(a) - before.row(a)) + (after.row(b) - before.row(b)) + (after.row(c) - before.row(c)))
              .transpose() /
          (3.0 * dt);
      out.normal_velocity(f) = velocity.dot(normal);
      out.tangential_velocity.row(f) = (velocity - velocity.dot(normal) * normal).transpose();
    }
  });
  return out;
}

}  // namespace morphomap
