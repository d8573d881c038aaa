#include "sunvo/report/json_writer.hpp"

#include <array>
#include <charconv>
#include <cmath>

namespace sunvo::report {

std::string jsonQuote(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (u < 0x20) {
          static constexpr char kHex[] = "0123456789abcdef";
          out += "\\u00";
          out.push_back(kHex[u >> 4]);
          out.push_back(kHex[u & 0xF]);
        } else {
          out.push_back(c);
        }
    }
  }
  out.push_back('"');
  return out;
}

void JsonWriter::newline() {
  out_.push_back('\n');
  out_.append(2 * stack_.size(), ' ');
}

void JsonWriter::beforeValue() {
  if (stack_.empty()) {
    if (wrote_root_) misused_ = true;  // a second root value
    wrote_root_ = true;
    return;
  }
  Level& top = stack_.back();
  if (top.is_object) {
    if (!top.have_key) misused_ = true;
    top.have_key = false;
    return;  // key() already wrote the separator and the indentation
  }
  if (top.count > 0) out_.push_back(',');
  ++top.count;
  newline();
}

void JsonWriter::raw(std::string_view text) {
  beforeValue();
  out_ += text;
}

JsonWriter& JsonWriter::key(std::string_view name) {
  if (stack_.empty() || !stack_.back().is_object || stack_.back().have_key) {
    misused_ = true;
    return *this;
  }
  Level& top = stack_.back();
  if (top.count > 0) out_.push_back(',');
  ++top.count;
  top.have_key = true;
  newline();
  out_ += jsonQuote(name);
  out_ += ": ";
  return *this;
}

JsonWriter& JsonWriter::beginObject() {
  raw("{");
  stack_.push_back({true, 0, false});
  return *this;
}

JsonWriter& JsonWriter::beginArray() {
  raw("[");
  stack_.push_back({false, 0, false});
  return *this;
}

JsonWriter& JsonWriter::endObject() {
  if (stack_.empty() || !stack_.back().is_object || stack_.back().have_key) {
    misused_ = true;
    return *this;
  }
  const bool empty = stack_.back().count == 0;
  stack_.pop_back();
  if (!empty) newline();
  out_.push_back('}');
  return *this;
}

JsonWriter& JsonWriter::endArray() {
  if (stack_.empty() || stack_.back().is_object) {
    misused_ = true;
    return *this;
  }
  const bool empty = stack_.back().count == 0;
  stack_.pop_back();
  if (!empty) newline();
  out_.push_back(']');
  return *this;
}

JsonWriter& JsonWriter::value(double v) {
  if (!std::isfinite(v)) return null();
  std::array<char, 32> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  raw(std::string_view(buf.data(), static_cast<std::size_t>(res.ptr - buf.data())));
  return *this;
}

JsonWriter& JsonWriter::value(std::int64_t v) {
  raw(std::to_string(v));
  return *this;
}

JsonWriter& JsonWriter::value(std::uint64_t v) {
  raw(std::to_string(v));
  return *this;
}

JsonWriter& JsonWriter::value(bool v) {
  raw(v ? "true" : "false");
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view v) {
  raw(jsonQuote(v));
  return *this;
}

JsonWriter& JsonWriter::null() {
  raw("null");
  return *this;
}

}  // namespace sunvo::report
