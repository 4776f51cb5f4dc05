#include "cellsph/neighbors/neighbor_list.hpp"

namespace cellsph {

std::string_view method_name(Method m) {
  switch (m) {
    case Method::AllPairs:
      return "all-pairs";
    case Method::SpatialHash:
      return "spatial-hash";
    case Method::CellIndex:
      return "cell-index";
    case Method::SortedGrid:
      return "sorted-grid";
    case Method::KdTree:
      return "kd-tree";
  }
  return "unknown";
}

std::optional<Method> parse_method(std::string_view name) {
  for (Method m : kAllMethods)
    if (method_name(m) == name) return m;
  return std::nullopt;
}

std::string method_names_joined(std::string_view sep) {
  std::string s;
  for (Method m : kAllMethods) {
    if (!s.empty()) s += sep;
    s += method_name(m);
  }
  return s;
}

}  // namespace cellsph
