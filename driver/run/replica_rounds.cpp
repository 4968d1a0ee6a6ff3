#include "driver/run/replica_rounds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "driver/store/store.hpp"
#include "stats/point_error.hpp"

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
    // Stein's two-stage rule (stats/point_error.hpp): the first plan.replicas replicas decide how
    // many the point needs, all of them added in one round.
    std::vector<double> stage_one;
    bool all_done = true;
    for (const auto* c : reps) {
      const auto v = result_settling_velocity(db, c->id);
      if (!v) all_done = false;
      if (v && c->replica < plan->second.replicas) stage_one.push_back(*v);
    }
    if (!all_done || static_cast<int>(stage_one.size()) < plan->second.replicas) {
      ++round.waiting;
      continue;
    }
    const int needed =
        stats::stein_replicas_needed(stage_one, *plan->second.target_rel_error, plan->second.max);
    const int have = static_cast<int>(reps.size());
    if (have >= needed) {
      // Needed more than replicas_max allows: at the limit, above the target.
      if (needed == plan->second.max &&
          stats::stein_replicas_needed(stage_one, *plan->second.target_rel_error, plan->second.max + 1) >
              needed)
        ++round.at_max;
      else
        ++round.precise;
      continue;
    }
    const StudyCase* first = nullptr;
    int next = 0;
    for (const auto* c : reps) {
      if (c->replica == 0) first = c;
      next = std::max(next, c->replica + 1);
    }
    for (int k = have; first && k < needed; ++k) round.added.push_back(replica_of(*first, next++));
  }
  return round;
}

}  // namespace boycott::driver
