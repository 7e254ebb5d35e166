#pragma once
// Displacement fields between two curves: the paper's basic algorithms and extensions.
#include <morphomap/field.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/optimal.hpp>
#include <morphomap/prepared_curve.hpp>
#include <morphomap/types.hpp>

#include <array>
#include <cstddef>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

namespace morphomap {

enum class MapMethod { minimal_distance, normal, diffusion, uniform, automatic, optimal, paper };

// One row per method that map_curves or map_surfaces takes, in the order users see them listed:
// the one table of the methods' names and forms, which the core's messages, reversed(), the
// Python bindings (and through them the command line, the demo and "best") read.
struct MethodRow {
  MapMethod method;
  const char* name;
  // A basic algorithm labels each of its vectors with one of two Methods: `forward` for a vector
  // found from C1 (named `name`), `backward` for one found from C2 and flipped ("reverse_" +
  // name); reversed() swaps them. The workflows (auto, paper) have neither: their vectors carry
  // the labels of the basic algorithms they ran.
  std::optional<Method> forward, backward;
  bool from_paper;  // the paper's own: its four basic algorithms and its Algorithm 1
  bool curves;      // has a 2D form (map_curves)
  bool surfaces;    // has a 3D form (map_surfaces)

  constexpr bool basic() const { return forward.has_value(); }
};

constexpr MethodRow kMethodTable[] = {
    {MapMethod::automatic, "auto", std::nullopt, std::nullopt, false, true, true},
    {MapMethod::minimal_distance, "minimal_distance", Method::minimal_distance, Method::reverse_minimal_distance, true,
     true, true},
    {MapMethod::normal, "normal", Method::normal, Method::reverse_normal, true, true, true},
    {MapMethod::diffusion, "diffusion", Method::diffusion, Method::reverse_diffusion, true, true, true},
    {MapMethod::uniform, "uniform", Method::uniform, Method::reverse_uniform, true, true, false},
    {MapMethod::optimal, "optimal", Method::optimal, Method::reverse_optimal, false, true, true},
    {MapMethod::paper, "paper", std::nullopt, std::nullopt, true, true, false},
};

// The table's methods alone, in its order.
constexpr auto kMapMethods = [] {
  std::array<MapMethod, std::size(kMethodTable)> methods{};
  for (std::size_t i = 0; i < methods.size(); ++i) methods[i] = kMethodTable[i].method;
  return methods;
}();

// The row of `method` in kMethodTable.
const MethodRow& method_row(MapMethod method);

// The row's name: "auto" for automatic, else the enumerator's name.
const char* map_method_name(MapMethod method);

// The MapMethod called `name`: InvalidInput naming "method" (and listing the names) otherwise.
MapMethod map_method_named(const std::string& name);

// The names of [first, last) in quotes: "'a', 'b' or 'c'" (for messages).
std::string quoted_method_names(const MapMethod* first, const MapMethod* last);
// The same for the rows of kMethodTable that have a form: &MethodRow::curves or ::surfaces.
std::string quoted_method_names(bool MethodRow::*form);

struct CurveMappingOptions {
  MapMethod method = MapMethod::automatic;  // the default's choice (map_curves below); paper: Algorithm 1
  bool closed = true;                       // both curves closed, or both open
  Index n = 0;                              // 0: the given points of the source curve are the start points;
                                            // > 0: both curves are first resampled to n equally spaced points
  bool reverse = false;                     // map C2 -> C1 and flip the vectors
  bool transform = false;                   // Appendix A: align a scaled C1 with C2 first, then carry back
  bool split = true;                        // map each pair of segments between intersection points on its own
  double density_threshold = 0.0;           // "paper": where the start points of a pair of segments are
                                            // denser than this many per gap (mean distance to C2 over
                                            // mean spacing), try reverse minimal distance before normal
                                            // mapping (the paper's density rule); 0: off
  std::optional<Vec2> anchor;               // uniform mapping of closed curves that do not cross: a point
                                            // of C1 (its nearest curve point) that maps onto its nearest
                                            // point of C2
  // Where the curves touch or run together closer than this (a stretch of source points within
  // it of the target, or a single touching point), they are split there as at a crossing, and
  // the points on the stretch map to their closest point of the target; whatever `split` says.
  // < 0: 1% of the finer of the two curves' median segment lengths; 0: exact contact only.
  double contact_tolerance = -1.0;
  DiffusionOptions diffusion;  // the mesh of diffusion mapping (also within "auto" and "paper")
  // "optimal": the weight of the stretch term against the squared displacements (see
  // monotone_match in optimal.hpp); 0 gives the nearest order-preserving matching.
  double stretch_weight = kDefaultStretchWeight;
};

// Both curves must be simple (no self-intersection, one loop) and, when closed, enclose an area:
// InvalidInput naming "c1" or "c2" otherwise.
// "auto" (the default): on each piece between split points (or the whole pair), the candidate
// with no crossings (counted with the split points' own vectors) and no misses and the lowest QM
// on the piece, among normal mapping, the order-preserving optimal matching, minimal distance, and
// reverse minimal distance and reverse optimal carried onto the piece's start points; where none
// qualifies with QM <= 1, also diffusion and reverse diffusion carried so. Every candidate maps
// the piece's own start points, so the field has one vector per start point of C1 (and per
// crossing), in order along C1. Where no candidate qualifies on a piece, or the pieces' fields
// cross each other, GeometryError says how many start points and where: a crossing or incomplete
// field is never returned. Without n or reverse, the same is done for C1 moved near C2 by
// Appendix A's similarity
// without its greedy search, carried back onto C1, and the field of lower QM kept (the moved one
// only without crossings on the curves as given). With transform, the transformed C1 only, and
// GeometryError where that field crosses once carried back.
// "paper": the paper's Algorithm 1 as stated: normal mapping on each piece, reverse diffusion where
// it gives crossings or misses; where reverse diffusion fails on a piece (its mesh cannot be made,
// streamlines stall) it falls back to diffusion, then to normal mapping (if that missed nothing),
// then to minimal distance. Its reverse vectors start from C2's points, and straight vectors of
// streamlines that curve can cross.
// methods names what each vector used, with reverse_ variants for vectors found from C2 (reverse =
// true flips every name). A vector that found nothing keeps the point it came from: NaN ends on
// forward vectors, NaN starts on reverse ones. With n > 0 the start and end points are put onto c1
// and c2 as given (the resampled curves cut their corners).
DisplacementField2 map_curves(const Points2Ref& c1, const Points2Ref& c2, const CurveMappingOptions& options = {});
// The same on curves checked and indexed once (not checked again; their indices are reused),
// with the same result bit for bit. Both must have been prepared as options.closed asks
// (InvalidInput naming "c1" or "c2" otherwise).
DisplacementField2 map_curves(const PreparedCurve& c1, const PreparedCurve& c2,
                              const CurveMappingOptions& options = {});

// The checks of the options that map_curves makes (after the curves', before any work):
// InvalidInput naming the option. For callers that run several mappings with one set of options.
void validate_options(const CurveMappingOptions& options);

// One subproblem of a pair: the stretch of C1 between two consecutive split points (crossings when
// splitting, contact stretches always; or an end of open curves) and the stretch of C2 between
// the same two, as open polylines: source runs from the first split point through the vertices of
// C1 it maps to the second, target between the same points in the source's direction.
struct CurvePiece {
  Points2 source, target;
  bool begin_meeting = false, end_meeting = false;  // the ends are split points (else curve ends)
  double source_begin = 0.0, source_length = 0.0;   // arc position on C1 where it begins, its length
  double target_begin = 0.0, target_length = 0.0;   // on C2, walking in the pair's direction
};

// The pieces map_curves maps one by one (the same rule, one owner): in order along C1; without
// split points one piece, the whole pair. c1 and c2 as the pieces' arc positions refer to them.
struct CurveSplit {
  std::vector<CurvePiece> pieces;
  Points2 c1, c2;
  bool closed = true;
  int direction = 1;  // +1 when C2 runs the same way round as C1 (closed), else -1
};
CurveSplit split_curves(const Points2Ref& c1, const Points2Ref& c2, bool closed = true, bool split = true,
                        double contact_tolerance = -1.0);

// For points on C1 (on_c1) or on C2: the piece whose open stretch holds each one's closest curve
// point (-1 at a split point, within rounding, and for rows with a NaN), and its distance along
// the piece from the piece's beginning.
struct PieceLabels {
  std::vector<Index> piece;
  Vector along;
};
PieceLabels piece_labels(const CurveSplit& split, const Points2Ref& points, bool on_c1);

}  // namespace morphomap
