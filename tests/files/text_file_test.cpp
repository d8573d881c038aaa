#include "sunvo/files/text_file.hpp"

#include <gtest/gtest.h>

namespace sunvo::files {
namespace {

TEST(TextFile, MissingFileIsNotFoundAndNamesThePath) {
  auto f = TextFile::open("/nonexistent/dir/calib.txt");
  ASSERT_FALSE(f);
  EXPECT_EQ(f.status().code(), StatusCode::kNotFound);
  EXPECT_NE(f.status().message().find("/nonexistent/dir/calib.txt"), std::string::npos);
}

TEST(TextFile, IteratesLinesAndStripsCarriageReturns) {
  auto f = TextFile::fromString("a.txt", "one\r\ntwo\n\nthree");
  std::string_view line;
  std::vector<std::string> got;
  while (f.nextLine(line)) got.emplace_back(line);
  EXPECT_EQ(got, (std::vector<std::string>{"one", "two", "", "three"}));
  EXPECT_EQ(f.lineNumber(), 4);
}

TEST(TextFile, ErrorsNameFileLineAndField) {
  auto f = TextFile::fromString("poses.txt", "1 2 3\n4 x 6\n");
  std::string_view line;
  f.nextLine(line);
  f.nextLine(line);
  auto fields = splitFields(line);
  ASSERT_EQ(fields.size(), 3u);
  auto v = f.parseDouble(fields[1], "r12");
  ASSERT_FALSE(v);
  EXPECT_EQ(v.status().message(), "poses.txt:2: field 'r12': not a number: 'x'");
  EXPECT_EQ(*f.parseDouble(fields[2], "r13"), 6.0);
  EXPECT_FALSE(f.parseInt("3.5", "frame"));
  EXPECT_FALSE(f.parseDouble("nan", "x"));
  EXPECT_FALSE(f.parseDouble("", "x"));
}

TEST(SplitFields, WhitespaceAndDelimited) {
  EXPECT_EQ(splitFields("  a\tb   c ").size(), 3u);
  EXPECT_TRUE(splitFields("   ").empty());
  auto csv = splitFields("frame, sx ,sy,", ',');
  ASSERT_EQ(csv.size(), 4u);
  EXPECT_EQ(csv[1], "sx");
  EXPECT_EQ(csv[3], "");
}

}  // namespace
}  // namespace sunvo::files
