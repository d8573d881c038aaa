#pragma once
// Line-oriented text input with precise error messages: every parse error names the file, the
// line number and the field ("calib.txt:3: field 'P1'[4]: not a number: 'abc'").

#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sunvo/core/status.hpp"

namespace sunvo::files {

class TextFile {
 public:
  // Reads the whole file. Fails with kNotFound (missing) or kIoError (unreadable).
  static Expected<TextFile> open(const std::string& path);
  // A TextFile over in-memory text, labelled as `path` in messages (for tests and pipes).
  static TextFile fromString(std::string path, std::string content);

  // Advances to the next line (without its '\n' or '\r\n'); false at the end.
  bool nextLine(std::string_view& line);
  // 1-based number of the line last returned by nextLine (0 before the first).
  int lineNumber() const { return line_number_; }
  const std::string& path() const { return path_; }

  // "<path>:<line>: field '<field>': <what>" with code kParseError.
  Status error(std::string_view field, std::string_view what) const;
  // "<path>:<line>: <what>".
  Status lineError(std::string_view what) const;

  // Parses one field of the current line; the error names the field.
  Expected<double> parseDouble(std::string_view text, std::string_view field) const;
  Expected<std::int64_t> parseInt(std::string_view text, std::string_view field) const;

 private:
  TextFile(std::string path, std::string content)
      : path_(std::move(path)), content_(std::move(content)) {}
  std::string path_;
  std::string content_;
  std::size_t pos_ = 0;
  int line_number_ = 0;
};

// Splits a line into fields: on runs of spaces/tabs when delimiter == 0, else on `delimiter`
// (fields are then trimmed of surrounding spaces). Empty lines give no fields.
std::vector<std::string_view> splitFields(std::string_view line, char delimiter = 0);

// True for a line that is empty or whitespace only.
bool isBlank(std::string_view line);

}  // namespace sunvo::files
