#pragma once
// Which physics models a run switched on, and the wall time each took: every summary.json lists
// them so a user sees what a scene left out and where the time went.
#include <chrono>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

namespace boycott {

/// Wall time since t0, s (the engines' own phase timers).
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

class ModelTimers {
 public:
  /// Marks a model active; `detail` names the variant (e.g. drag law "difelice_paper").
  void activate(const std::string& model, const std::string& detail = "");
  void add(const std::string& model, double seconds);
  /// This attempt's and the carried earlier attempts' wall time of a model, s.
  double seconds(const std::string& model) const;
  bool active(const std::string& model) const { return entries_.count(model) > 0; }
  /// Resuming from a checkpoint: each model's wall time over the earlier attempts (s), counted
  /// from simulated time from_s (s): the run's start when the checkpoint carried them all, the
  /// resume point when it carried none (a build that recorded none), so that a summary never
  /// presents one attempt's times as the whole run's.
  void carry(const std::map<std::string, double>& earlier_s, double from_s);
  /// Each model's wall time, s: the carried attempts' plus this one's (what a checkpoint records).
  std::map<std::string, double> totals() const;
  /// The simulated time from which the wall times count, s.
  double counted_from_s() const { return from_s_; }
  /// {"model": {"detail": ..., "wall_time_s": ...}, ...}, the wall times over the attempts
  /// since counted_from_s().
  nlohmann::json to_json() const;

  /// RAII scope that adds its lifetime to a model's total.
  class Scope {
   public:
    Scope(ModelTimers& t, const char* model)
        : t_(t), model_(model), start_(std::chrono::steady_clock::now()) {}
    ~Scope() {
      t_.add(model_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    ModelTimers& t_;
    const char* model_;
    std::chrono::steady_clock::time_point start_;
  };

 private:
  struct Entry {
    std::string detail;
    double seconds = 0.0;
  };
  std::map<std::string, Entry> entries_;
  std::map<std::string, double> carried_s_;
  double from_s_ = 0.0;
};

}  // namespace boycott
