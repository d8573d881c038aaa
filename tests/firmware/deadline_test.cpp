#include "sunvo/runtime/deadline.hpp"

#include <gtest/gtest.h>

namespace sunvo::runtime {
namespace {

// deadline 100 ms, front end + RANSAC 9 ms, margin 5 ms, budget within [5, 40] ms.
TEST(SolverBudget, ShrinksWithTheFramesAgeWithinItsBounds) {
  auto budget = [](double age_ms) { return solverBudgetMs(100.0, age_ms, 9.0, 5.0, 5.0, 40.0); };
  EXPECT_EQ(budget(0.2), 40.0);   // on time: the full budget
  EXPECT_EQ(budget(46.0), 40.0);  // 100 - 46 - 9 - 5 = 40
  EXPECT_DOUBLE_EQ(budget(66.0), 20.0);
  EXPECT_DOUBLE_EQ(budget(80.5), 5.5);
  EXPECT_EQ(budget(95.0), 5.0);  // past the point where the deadline can be met: the minimum
  EXPECT_EQ(budget(400.0), 5.0);
}

}  // namespace
}  // namespace sunvo::runtime
