#pragma once
// One mapping job of map_curves: a piece of the source (the whole curve, or the stretch between two
// meetings) with its start points and the piece of the target it maps onto; the basic algorithms on
// a job (basic_curve.cpp), the paper's Algorithm 1 and the default choice (automatic.cpp).
#include <morphomap/curve_queries.hpp>
#include <morphomap/field.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/mapping.hpp>
#include <morphomap/transform.hpp>

#include "curves/arc_curve.hpp"
#include "curves/unchecked.hpp"

#include <memory>
#include <vector>

namespace morphomap::detail {

// A piece of the source (the whole curve, or the stretch between two crossings) with its start
// points, and the piece of the target it maps onto.
struct Job {
  Points2 source;  // the source polyline
  bool source_closed = false;
  std::vector<Index> start_rows;  // rows of source that are start points, in order along it
  Points2 normals;                // normal mapping: the normal of the whole curve at each start
  Vector fractions;               // uniform: arc position along the source / its length
  Points2 target;
  bool target_closed = false;
  // The first / last rows of source and target are the two ends of a meeting (a crossing or a
  // contact stretch), whose own vectors map them: no start point there, either way round.
  bool shared_begin = false, shared_end = false;
  double anchor = 0.0;  // uniform: target arc position where fraction 0 lands
  int direction = 1;    // uniform: +1 forward along the target, -1 backward
  // The query indexes of source and target, built on first use and shared by every attempt on
  // the job (Algorithm 1 may try four) and by its reverse.
  mutable std::shared_ptr<const CurveIndex> source_index, target_index;
};

// A job's index of one of its curves, built into `slot` on first use.
inline const CurveIndex& built_index(std::shared_ptr<const CurveIndex>& slot, const Points2& curve, bool closed) {
  if (!slot) slot = std::make_shared<const CurveIndex>(CurveIndexUnchecked::build(curve, closed));
  return *slot;
}

inline const CurveIndex& source_index(const Job& job) {
  return built_index(job.source_index, job.source, job.source_closed);
}

inline const CurveIndex& target_index(const Job& job) {
  return built_index(job.target_index, job.target, job.target_closed);
}

// Vectors with the arc position of their start along the whole source curve, to order them.
struct Vectors {
  Points2 starts, ends;
  std::vector<Method> methods;
  std::vector<double> keys;
};

inline Points2 start_points(const Job& job) {
  Points2 starts(job.start_rows.size(), 2);
  for (std::size_t j = 0; j < job.start_rows.size(); ++j) starts.row(j) = job.source.row(job.start_rows[j]);
  return starts;
}

// What every job of one mapping shares.
struct Settings {
  double density_threshold = 0.0;
  double contact_tolerance = -1.0;  // < 0: default_contact_tolerance
  DiffusionOptions diffusion;
  Index pair_points = 0;  // points of both mapped curves: diffusion's pieces share their mesh budget
  double stretch_weight = kDefaultStretchWeight;  // "optimal"
  // The curves are the ones map_curves checked to be simple (not resampled or transformed), so
  // diffusion need not check them again.
  bool simple_curves = false;
};

inline bool complete(const Vectors& v) { return v.starts.allFinite() && v.ends.allFinite(); }

// A basic algorithm (not "auto" or "paper") on one job, from its start points.
Vectors forward(MapMethod method, const Job& job, const std::vector<double>& start_keys, const Settings& settings);

// A basic algorithm run backwards on one job (the paper's reverse mapping): from the target's
// points (but shared meetings) to the source, flipped. Keys from the whole source curve; a miss
// keeps its point on the target (ends) and has a NaN start.
Vectors reverse(MapMethod method, const Job& job, const ArcCurve& whole_source, const CurveIndex& whole_source_index,
                const Settings& settings);

// The Method that labels the vectors of a basic algorithm.
Method basic_method(MapMethod method);

// Closed curves without a known pair of anchors: the start of the target (walking in direction)
// such that equally spaced points of both curves, matched in order, are closest.
double best_anchor(const ArcCurve& source, const ArcCurve& target, int direction);

// +1 when both closed curves turn the same way.
int relative_direction(const ArcCurve& source, const ArcCurve& target);

// "paper": the paper's Algorithm 1 on one job (automatic.cpp).
Vectors paper_algorithm(const Job& job, const std::vector<double>& start_keys, const ArcCurve& whole_source,
                        const CurveIndex& whole_source_index, const Settings& settings);

// "auto": the default's choice on one job (automatic.cpp).
Vectors default_choice(const Job& job, const std::vector<double>& start_keys, const ArcCurve& whole_source,
                       const CurveIndex& whole_source_index, const Settings& settings);

// map_curves after its curves' checks: c1, c2 passed require_simple_curve, n1, n2 points of them
// take part, and index1, index2 are their query indices where the caller has them (PreparedCurve),
// else null. With `moved`, C1 is moved by that similarity before mapping and the start points are
// carried back, as options.transform does with Appendix A's (mapping.cpp).
DisplacementField2 mapped_pair(const Points2Ref& c1, Index n1, const CurveIndex* index1, const Points2Ref& c2, Index n2,
                               const CurveIndex* index2, const CurveMappingOptions& options,
                               const Similarity2* moved = nullptr);

// mapped_pair, or for "auto" without transform the better of two whole fields (automatic.cpp).
DisplacementField2 mapped_choice(const Points2Ref& c1, Index n1, const CurveIndex* index1, const Points2Ref& c2,
                                 Index n2, const CurveIndex* index2, const CurveMappingOptions& options);

}  // namespace morphomap::detail
