#include "curves/arc_curve.hpp"

#include "common/validation.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace morphomap::detail {

ArcCurve::ArcCurve(const Points2Ref& points, bool closed, const char* name)
    : ArcCurve(points, closed, require_curve(points, closed, name)) {}

ArcCurve ArcCurve::unchecked(const Points2Ref& points, bool closed) {
  return ArcCurve(points, closed, curve_size(points, closed));
}

ArcCurve::ArcCurve(const Points2Ref& points, bool closed, Index n) : closed_(closed) {
  points_ = points.topRows(n);
  arc_.resize(n + 1);
  arc_[0] = 0.0;
  for (Index i = 1; i <= n; ++i) {
    const Index j = i % n;
    arc_[i] = arc_[i - 1] + (points_.row(j) - points_.row(i - 1)).norm();
  }
  if (!closed) arc_[n] = arc_[n - 1];
  length_ = arc_[n];
}

double ArcCurve::wrap(double s) const {
  if (!closed_) return std::min(std::max(s, 0.0), length_);
  double r = std::fmod(s, length_);
  if (r < 0) r += length_;
  return r >= length_ ? 0.0 : r;
}

double ArcCurve::forward(double a, double b) const {
  if (!closed_) return std::abs(b - a);
  return wrap(b - a);
}

double ArcCurve::between(double a, double b) const {
  if (!closed_) return std::abs(b - a);
  const double f = wrap(b - a);
  return std::min(f, length_ - f);
}

Index ArcCurve::segment_at(double s) const {
  const Index segments = closed_ ? size() : size() - 1;
  // Last segment whose start lies at or before s.
  const auto it = std::upper_bound(arc_.data(), arc_.data() + segments, s);
  return std::max<Index>(0, (it - arc_.data()) - 1);
}

Index ArcCurve::vertex_after(double s) const {
  return std::upper_bound(arc_.data(), arc_.data() + size(), s) - arc_.data();
}

Vec2 ArcCurve::point_at(double s) const {
  s = wrap(s);
  const Index i = segment_at(s);
  const Index j = (i + 1) % size();
  const double len = arc_[i + 1] - arc_[i];
  const double t = len > 0 ? std::min(std::max((s - arc_[i]) / len, 0.0), 1.0) : 0.0;
  return points_.row(i).transpose() + t * (points_.row(j) - points_.row(i)).transpose();
}

Points2 ArcCurve::piece(double a, double b) const {
  a = wrap(a), b = wrap(b);
  std::vector<Vec2> out;
  out.push_back(point_at(a));
  const Index n = size();
  if (closed_) {
    // Vertices met walking forward from a to b, wrapping past the first point.
    const double span = forward(a, b);
    Index k = segment_at(a) + 1;
    for (Index step = 0; step < n; ++step, ++k) {
      const Index v = k % n;
      const double d = forward(a, arc_[v]);
      if (d >= span) break;
      if (d > 0.0) out.push_back(points_.row(v).transpose());
    }
  } else if (b >= a) {
    for (Index v = segment_at(a) + 1; v < n && arc_[v] < b; ++v) {
      if (arc_[v] > a) out.push_back(points_.row(v).transpose());
    }
  } else {
    for (Index v = segment_at(a); v >= 0 && arc_[v] > b; --v) {
      if (arc_[v] < a) out.push_back(points_.row(v).transpose());
    }
  }
  out.push_back(point_at(b));
  Points2 result(out.size(), 2);
  for (std::size_t k = 0; k < out.size(); ++k) result.row(k) = out[k].transpose();
  return result;
}

}  // namespace morphomap::detail
