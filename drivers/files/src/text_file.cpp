#include "sunvo/files/text_file.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace sunvo::files {

Expected<TextFile> TextFile::open(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (errno == ENOENT) return notFound(path + ": file not found");
    return ioError(path + ": cannot open: " + std::strerror(errno));
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return ioError(path + ": read failed");
  return TextFile(path, ss.str());
}

TextFile TextFile::fromString(std::string path, std::string content) {
  return TextFile(std::move(path), std::move(content));
}

bool TextFile::nextLine(std::string_view& line) {
  if (pos_ >= content_.size()) return false;
  const std::size_t end = content_.find('\n', pos_);
  const std::size_t stop = end == std::string::npos ? content_.size() : end;
  line = std::string_view(content_).substr(pos_, stop - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = end == std::string::npos ? content_.size() : end + 1;
  ++line_number_;
  return true;
}

Status TextFile::error(std::string_view field, std::string_view what) const {
  return parseError(path_ + ":" + std::to_string(line_number_) + ": field '" + std::string(field) +
                    "': " + std::string(what));
}

Status TextFile::lineError(std::string_view what) const {
  return parseError(path_ + ":" + std::to_string(line_number_) + ": " + std::string(what));
}

Expected<double> TextFile::parseDouble(std::string_view text, std::string_view field) const {
  double v = 0.0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end) {
    return error(field, "not a number: '" + std::string(text) + "'");
  }
  if (!std::isfinite(v)) return error(field, "not finite: '" + std::string(text) + "'");
  return v;
}

Expected<std::int64_t> TextFile::parseInt(std::string_view text, std::string_view field) const {
  std::int64_t v = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end) {
    return error(field, "not an integer: '" + std::string(text) + "'");
  }
  return v;
}

std::vector<std::string_view> splitFields(std::string_view line, char delimiter) {
  std::vector<std::string_view> out;
  auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  if (delimiter == 0) {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && is_space(line[i])) ++i;
      const std::size_t start = i;
      while (i < line.size() && !is_space(line[i])) ++i;
      if (i > start) out.push_back(line.substr(start, i - start));
    }
    return out;
  }
  if (isBlank(line)) return out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = line.find(delimiter, start);
    std::string_view f =
        line.substr(start, end == std::string_view::npos ? line.size() - start : end - start);
    while (!f.empty() && is_space(f.front())) f.remove_prefix(1);
    while (!f.empty() && is_space(f.back())) f.remove_suffix(1);
    out.push_back(f);
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return out;
}

bool isBlank(std::string_view line) {
  for (char c : line) {
    if (c != ' ' && c != '\t' && c != '\r') return false;
  }
  return true;
}

}  // namespace sunvo::files
