// A compile-time list of model types and a visit over it by runtime id or
// name. Replaces COLMAP's CAMERA_MODEL_CASES macro tables: one list per model
// family, one fold expression per lookup.
#pragma once

#include <string>
#include <string_view>
#include <utility>

namespace portcal {

template <typename... Ts>
struct TypeList {
  static constexpr int kSize = sizeof...(Ts);
};

// Calls f(M{}) for the model M with M::kId == id. Returns false when no model
// has that id (the caller decides which error to throw).
template <typename... Ms, typename F>
bool VisitModelById(TypeList<Ms...>, int id, F&& f) {
  return ((Ms::kId == id ? (f(Ms{}), true) : false) || ...);
}

template <typename... Ms, typename F>
bool VisitModelByName(TypeList<Ms...>, std::string_view name, F&& f) {
  return ((std::string_view(Ms::kName) == name ? (f(Ms{}), true) : false) || ...);
}

// Calls f(M{}) for every model of the list, in order.
template <typename... Ms, typename F>
void ForEachModel(TypeList<Ms...>, F&& f) {
  (f(Ms{}), ...);
}

// The models' names in the list's order, ", "-separated: what messages list,
// so that a model added to the list appears in them.
template <typename... Ms>
std::string ModelNames(TypeList<Ms...>) {
  std::string names;
  ((names += (names.empty() ? "" : ", ") + std::string(Ms::kName)), ...);
  return names;
}

}  // namespace portcal
