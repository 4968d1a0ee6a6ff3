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
  double seconds(const std::string& model) const;
  bool active(const std::string& model) const { return entries_.count(model) > 0; }
  /// {"model": {"detail": ..., "wall_time_s": ...}, ...}
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
};

}  // namespace boycott
