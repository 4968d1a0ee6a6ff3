#include "driver/replica_rounds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "driver/store.hpp"

namespace boycott::driver {

bool has_replica_target(const Study& s) {
  return std::any_of(s.replica_plans.begin(), s.replica_plans.end(),
                     [](const auto& g) { return g.second.target_rel_error.has_value(); });
}

ReplicaRound next_replica_round(Database& db, const Study& s) {
  ReplicaRound round;
  std::map<std::string, std::vector<const StudyCase*>> replicas;  // point id -> its replicas
  std::vector<std::string> points;                                // in study order
  for (const auto& c : s.cases) {
    auto& r = replicas[c.point_id];
    if (r.empty()) points.push_back(c.point_id);
    r.push_back(&c);
  }
  for (const auto& point : points) {
    const auto& reps = replicas[point];
    const auto plan = s.replica_plans.find(reps.front()->group);
    if (plan == s.replica_plans.end() || !plan->second.target_rel_error) continue;
    std::vector<double> w;
    for (const auto* c : reps)
      if (const auto v = result_settling_velocity(db, c->id)) w.push_back(*v);
    if (w.size() < reps.size()) {
      ++round.waiting;
      continue;
    }
    const double n = static_cast<double>(w.size());
    double rel = std::numeric_limits<double>::infinity();
    if (w.size() >= 2) {
      double mean = 0.0, ss = 0.0;
      for (double x : w) mean += x / n;
      for (double x : w) ss += (x - mean) * (x - mean);
      rel = std::sqrt(ss / (n - 1.0)) / std::sqrt(n) / std::abs(mean);
    }
    if (rel <= *plan->second.target_rel_error) {
      ++round.precise;
      continue;
    }
    if (static_cast<int>(reps.size()) >= plan->second.max) {
      ++round.at_max;
      continue;
    }
    const StudyCase* first = nullptr;
    int next = 0;
    for (const auto* c : reps) {
      if (c->replica == 0) first = c;
      next = std::max(next, c->replica + 1);
    }
    if (first) round.added.push_back(replica_of(*first, next));
  }
  return round;
}

}  // namespace boycott::driver
