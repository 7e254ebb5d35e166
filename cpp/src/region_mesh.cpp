// The only translation unit with CGAL's 2D mesher: it compiles slowly.
#include "region_mesh.hpp"

#include <morphomap/errors.hpp>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>

#include <queue>
#include <unordered_map>

namespace morphomap::detail {

namespace {

struct VertexInfo {
  Index input = -1;
  Index index = -1;
};

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, Kernel>;
using FaceBase = CGAL::Delaunay_mesh_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
// Exact_predicates_tag: constraints may cross (crossing curves); CGAL adds the crossing points.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<Cdt>;
using Point = Cdt::Point;

constexpr std::size_t kMaxVertices = 8'000'000;

// Faces inside an odd number of loops: flood fill from the infinite faces, one connected
// component at a time, a constrained edge raising the nesting level by one.
void mark_odd_nesting(Cdt& cdt) {
  std::unordered_map<Cdt::Face_handle, int> level;
  std::queue<std::pair<Cdt::Face_handle, int>> border;
  border.push({cdt.infinite_face(), 0});
  while (!border.empty()) {
    const auto [start, depth] = border.front();
    border.pop();
    if (level.count(start)) continue;
    std::queue<Cdt::Face_handle> component;
    component.push(start);
    level[start] = depth;
    while (!component.empty()) {
      const Cdt::Face_handle f = component.front();
      component.pop();
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle g = f->neighbor(i);
        if (level.count(g)) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) {
          border.push({g, depth + 1});
        } else {
          level[g] = depth;
          component.push(g);
        }
      }
    }
  }
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) {
    f->set_in_domain(!cdt.is_infinite(f) && level[f] % 2 == 1);
  }
}

}  // namespace

RegionMesh mesh_region(const std::vector<Points2>& loops, double max_edge) {
  Cdt cdt;
  std::vector<Point> points;
  for (const Points2& loop : loops) {
    for (Index i = 0; i < loop.rows(); ++i) points.emplace_back(loop(i, 0), loop(i, 1));
  }
  // Inserting points in their order along a curve (nearly co-circular) costs many flips per point:
  // insert them in spatial (Hilbert) order, each near the last.
  std::vector<std::size_t> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  using SortTraits = CGAL::Spatial_sort_traits_adapter_2<Kernel, CGAL::Pointer_property_map<Point>::type>;
  CGAL::spatial_sort(order.begin(), order.end(), SortTraits(CGAL::make_property_map(points)));
  std::vector<Cdt::Vertex_handle> handles(points.size());
  try {
    Cdt::Face_handle hint;
    for (const std::size_t i : order) {
      const auto v = cdt.insert(points[i], hint);
      if (v->info().input < 0 || static_cast<Index>(i) < v->info().input) v->info().input = static_cast<Index>(i);
      handles[i] = v;
      hint = v->face();
    }
    Index first = 0;
    for (const Points2& loop : loops) {
      const Index n = loop.rows();
      for (Index i = 0; i < n; ++i) {
        const auto a = handles[first + i], b = handles[first + (i + 1) % n];
        if (a != b) cdt.insert_constraint(a, b);
      }
      first += n;
    }
    // Collinear loops (curves that run together all along) bound no area at all.
    if (cdt.dimension() < 2) throw GeometryError("the region between the curves is empty");
    mark_odd_nesting(cdt);
    // Refine step by step so that a degenerate input cannot run away with time and memory.
    CGAL::Delaunay_mesher_2<Cdt, Criteria> mesher(cdt, Criteria(0.125, max_edge > 0 ? max_edge : 0.0));
    mesher.init(true);
    while (mesher.try_one_step_refine_mesh()) {
      if (cdt.number_of_vertices() > kMaxVertices) {
        throw GeometryError("meshing the region between the curves needs more than " +
                            std::to_string(kMaxVertices) + " vertices: the region is degenerate, or "
                            "the mesh size far too small for it");
      }
    }
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("meshing the region between the curves failed: ") + e.what());
  }

  RegionMesh mesh;
  Index vertex_count = 0, triangle_count = 0;
  std::unordered_map<Cdt::Face_handle, Index> face_index;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->is_in_domain()) continue;
    face_index[f] = triangle_count++;
    for (int i = 0; i < 3; ++i) {
      if (f->vertex(i)->info().index < 0) f->vertex(i)->info().index = vertex_count++;
    }
  }
  mesh.vertices.resize(vertex_count, 2);
  mesh.input.assign(vertex_count, -1);
  mesh.on_boundary.assign(vertex_count, 0);
  mesh.triangles.resize(triangle_count, 3);
  mesh.neighbours.resize(triangle_count, 3);
  for (const auto& [f, t] : face_index) {
    for (int i = 0; i < 3; ++i) {
      const auto v = f->vertex(i);
      const Index k = v->info().index;
      mesh.triangles(t, i) = k;
      mesh.vertices(k, 0) = v->point().x();
      mesh.vertices(k, 1) = v->point().y();
      mesh.input[k] = v->info().input;
      const auto across = face_index.find(f->neighbor(i));
      mesh.neighbours(t, i) = across == face_index.end() ? -1 : across->second;
      if (cdt.is_constrained(Cdt::Edge(f, i))) {
        mesh.on_boundary[f->vertex(Cdt::cw(i))->info().index] = 1;
        mesh.on_boundary[f->vertex(Cdt::ccw(i))->info().index] = 1;
      }
    }
  }
  mesh.of_input.resize(handles.size());
  for (std::size_t i = 0; i < handles.size(); ++i) mesh.of_input[i] = handles[i]->info().index;
  return mesh;
}

}  // namespace morphomap::detail
