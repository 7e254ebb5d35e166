// The names of the methods: the one registry that the core's messages, the bindings, the command
// line and the demo read.
#include <morphomap/field.hpp>
#include <morphomap/mapping.hpp>

#include "common/validation.hpp"

#include <iterator>
#include <string>

namespace morphomap {

std::string method_name(Method method) {
  switch (method) {
    case Method::minimal_distance:
      return "minimal_distance";
    case Method::normal:
      return "normal";
    case Method::diffusion:
      return "diffusion";
    case Method::uniform:
      return "uniform";
    case Method::reverse_minimal_distance:
      return "reverse_minimal_distance";
    case Method::reverse_normal:
      return "reverse_normal";
    case Method::reverse_diffusion:
      return "reverse_diffusion";
    case Method::reverse_uniform:
      return "reverse_uniform";
    case Method::optimal:
      return "optimal";
    case Method::reverse_optimal:
      return "reverse_optimal";
  }
  return "unknown";
}

const char* map_method_name(MapMethod method) {
  switch (method) {
    case MapMethod::automatic:
      return "auto";
    case MapMethod::paper:
      return "paper";
    case MapMethod::minimal_distance:
      return "minimal_distance";
    case MapMethod::normal:
      return "normal";
    case MapMethod::diffusion:
      return "diffusion";
    case MapMethod::uniform:
      return "uniform";
    case MapMethod::optimal:
      return "optimal";
  }
  return "unknown";
}

std::string quoted_method_names(const MapMethod* first, const MapMethod* last) {
  std::string names;
  for (const MapMethod* m = first; m != last; ++m) {
    if (m != first) names += m + 1 == last ? " or " : ", ";
    names += std::string("'") + map_method_name(*m) + "'";
  }
  return names;
}

MapMethod map_method_named(const std::string& name) {
  for (const MapMethod method : kMapMethods) {
    if (name == map_method_name(method)) return method;
  }
  detail::invalid("method", "expected one of " + quoted_method_names(std::begin(kMapMethods), std::end(kMapMethods)) +
                                ", got '" + name + "'");
}

}  // namespace morphomap
