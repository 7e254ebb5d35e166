// Readers of the method table (kMethodTable, mapping.hpp): the methods' names, the names of the
// labels their vectors carry, and the label of the same algorithm run the other way.
#include <morphomap/field.hpp>
#include <morphomap/mapping.hpp>

#include "common/validation.hpp"

#include <string>
#include <vector>

namespace morphomap {

const MethodRow& method_row(MapMethod method) {
  for (const MethodRow& row : kMethodTable) {
    if (row.method == method) return row;
  }
  detail::invalid("method", "code " + std::to_string(static_cast<int>(method)) + " has no row in the method table");
}

std::string method_name(Method method) {
  for (const MethodRow& row : kMethodTable) {
    if (row.forward == method) return row.name;
    if (row.backward == method) return std::string("reverse_") + row.name;
  }
  return "unknown";
}

Method reversed(Method method) {
  for (const MethodRow& row : kMethodTable) {
    if (row.forward == method) return *row.backward;
    if (row.backward == method) return *row.forward;
  }
  return method;  // not a label of the table's (only a cast integer can be)
}

const char* map_method_name(MapMethod method) {
  for (const MethodRow& row : kMethodTable) {
    if (row.method == method) return row.name;
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

std::string quoted_method_names(bool MethodRow::*form) {
  std::vector<MapMethod> methods;
  for (const MethodRow& row : kMethodTable) {
    if (row.*form) methods.push_back(row.method);
  }
  return quoted_method_names(methods.data(), methods.data() + methods.size());
}

MapMethod map_method_named(const std::string& name) {
  for (const MethodRow& row : kMethodTable) {
    if (name == row.name) return row.method;
  }
  detail::invalid("method", "expected one of " +
                                quoted_method_names(kMapMethods.data(), kMapMethods.data() + kMapMethods.size()) +
                                ", got '" + name + "'");
}

}  // namespace morphomap
