// The public CurveIndex: the arguments' checks and the answers' layout around the segment tree
// (curve_tree.hpp).
#include <morphomap/curve_queries.hpp>

#include "common/validation.hpp"
#include "curves/curve_tree.hpp"
#include "curves/unchecked.hpp"

namespace morphomap {

struct CurveIndex::Impl : curve_tree::Tree {
  using Tree::Tree;
};

namespace {

CurveHits allocate_hits(Index rows) {
  CurveHits hits;
  hits.points.resize(rows, 2);
  hits.distances.resize(rows);
  hits.segments.resize(rows);
  hits.arc_lengths.resize(rows);
  return hits;
}

}  // namespace

CurveIndex::CurveIndex(const Points2Ref& curve, bool closed)
    : impl_(std::make_unique<Impl>(curve, closed, detail::require_curve(curve, closed, "curve"))) {}
CurveIndex::CurveIndex(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CurveIndex::~CurveIndex() = default;
CurveIndex::CurveIndex(CurveIndex&&) noexcept = default;
CurveIndex& CurveIndex::operator=(CurveIndex&&) noexcept = default;

Index CurveIndex::size() const { return impl_->points; }
bool CurveIndex::closed() const { return impl_->closed; }

CurveHits CurveIndex::closest_points(const Points2Ref& queries) const {
  detail::require_finite(queries, "queries");
  return detail::CurveIndexUnchecked::closest_points(*this, queries);
}

CurveHits CurveIndex::line_intersections(const Points2Ref& origins, const Points2Ref& directions) const {
  detail::require_finite(origins, "origins");
  detail::require_finite(directions, "directions");
  detail::require_directions(origins, directions);
  return detail::CurveIndexUnchecked::line_intersections(*this, origins, directions);
}

CurveIndex detail::CurveIndexUnchecked::build(const Points2Ref& curve, bool closed) {
  return CurveIndex(std::make_unique<CurveIndex::Impl>(curve, closed, curve_size(curve, closed)));
}

CurveHits detail::CurveIndexUnchecked::closest_points(const CurveIndex& index, const Points2Ref& queries) {
  CurveHits hits = allocate_hits(queries.rows());
  index.impl_->closest_points(queries, hits);
  return hits;
}

CurveHits detail::CurveIndexUnchecked::line_intersections(const CurveIndex& index, const Points2Ref& origins,
                                                          const Points2Ref& directions) {
  CurveHits hits = allocate_hits(origins.rows());
  index.impl_->line_intersections(origins, directions, hits);
  return hits;
}

CurveHits closest_points(const Points2Ref& queries, const Points2Ref& curve, bool closed) {
  return CurveIndex(curve, closed).closest_points(queries);
}

CurveHits line_intersections(const Points2Ref& origins, const Points2Ref& directions, const Points2Ref& curve,
                             bool closed) {
  return CurveIndex(curve, closed).line_intersections(origins, directions);
}

}  // namespace morphomap
