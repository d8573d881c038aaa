#pragma once
// The solver's time budget for one frame from how late the frame already is.
//
// A frame triggered at t_trigger must be published by t_trigger + deadline. When the estimator
// dequeues it at age a = t_dequeue - t_trigger, what is left for the window solve is the deadline
// minus the age, minus what the rest of the frame typically costs (front end + RANSAC, a running
// mean) and a margin for publishing:
//   budget = clamp(deadline - a - rest - margin, min_budget, max_budget)
// A frame on time gets max_budget; a late one gets less, never below min_budget (the window
// must still run a few iterations).

#include <algorithm>

namespace sunvo::runtime {

inline double solverBudgetMs(double deadline_ms, double age_ms, double rest_ms, double margin_ms,
                             double min_budget_ms, double max_budget_ms) {
  const double left_ms = deadline_ms - age_ms - rest_ms - margin_ms;
  return std::clamp(left_ms, min_budget_ms, max_budget_ms);
}

}  // namespace sunvo::runtime
