#pragma once
// A small streaming JSON writer (RFC 8259 output, 2-space indentation). Numbers are printed in
// the shortest form that reads back to the same double; NaN and infinities, which JSON cannot
// represent, are written as null. Strings are escaped ('"', '\\', control characters as \uXXXX).
//
// Usage: w.beginObject().key("a").value(1.5).key("b").beginArray().value("x").endArray()
//         .endObject(); then w.str(). Misuse (a value in an object without a key, unbalanced
// begin/end) is recorded and reported by ok(); str() is valid JSON only when ok().

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace sunvo::report {

class JsonWriter {
 public:
  JsonWriter& beginObject();
  JsonWriter& endObject();
  JsonWriter& beginArray();
  JsonWriter& endArray();
  JsonWriter& key(std::string_view name);
  JsonWriter& value(double v);
  JsonWriter& value(int v) { return value(static_cast<std::int64_t>(v)); }
  JsonWriter& value(std::int64_t v);
  JsonWriter& value(std::uint64_t v);
  JsonWriter& value(bool v);
  JsonWriter& value(std::string_view v);
  JsonWriter& value(const char* v) { return value(std::string_view(v)); }
  JsonWriter& null();

  // True when every begin has its end and every object member had a key.
  bool ok() const { return !misused_ && stack_.empty() && wrote_root_; }
  const std::string& str() const { return out_; }

 private:
  struct Level {
    bool is_object = false;
    std::size_t count = 0;
    bool have_key = false;
  };
  void beforeValue();
  void newline();
  void raw(std::string_view text);

  std::string out_;
  std::vector<Level> stack_;
  bool misused_ = false;
  bool wrote_root_ = false;
};

// s as a quoted, escaped JSON string.
std::string jsonQuote(std::string_view s);

}  // namespace sunvo::report
