#pragma once
// One vocabulary for options: each options struct names its fields once, and every program that
// reads, overrides or prints options walks that list (sunvo_rover's YAML and --set keys, the
// start-up description). The key of a field is the field's name; units and ranges stay in the
// comment next to the field and in the struct's validate().
//
//   struct WindowOptions {
//     int max_num_iterations = 10;  // count, [1, 1000]: Ceres iterations per solve
//     Status validate() const;
//     template <class Self, class V> static void fields(Self& s, V& v) {
//       v("max_num_iterations", s.max_num_iterations);
//     }
//   };
//
// A field that is itself an options struct is a section (v("window", s.window)); a struct whose
// fields belong at the same level is listed by calling its own fields() (VoOptions::fields(s.vo,
// v)). An enum field is read and printed by name: an enumNames(E) function found by ADL returns
// its names in the enum's order. Self is the struct or the const struct, so one list serves
// readers and printers.

#include <concepts>
#include <span>
#include <string_view>
#include <type_traits>

namespace sunvo {

namespace fields_detail {
struct AnyVisitor {
  template <typename T>
  void operator()(const char*, T&) {}
};
}  // namespace fields_detail

// T lists its fields (T::fields(t, visitor)).
template <typename T>
concept OptionsStruct = requires(T& t, fields_detail::AnyVisitor& v) {
  T::fields(t, v);
};

// E is an enum with names for its values (enumNames(E) -> the names in value order).
template <typename E>
concept NamedEnum = std::is_enum_v<E> && requires(E e) {
  { enumNames(e) } -> std::convertible_to<std::span<const std::string_view>>;
};

// The name of an enum value ("?" if out of range).
template <NamedEnum E>
std::string_view enumName(E e) {
  const std::span<const std::string_view> names = enumNames(e);
  const auto i = static_cast<std::size_t>(e);
  return i < names.size() ? names[i] : std::string_view("?");
}

}  // namespace sunvo
