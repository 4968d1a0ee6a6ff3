#include "core/timers.hpp"

#include "core/hash.hpp"

#include <fmt/format.h>

namespace boycott {

void ModelTimers::activate(const std::string& model, const std::string& detail) {
  auto& e = entries_[model];
  if (!detail.empty()) e.detail = detail;
}

void ModelTimers::add(const std::string& model, double seconds) {
  entries_[model].seconds += seconds;
}

double ModelTimers::seconds(const std::string& model) const {
  auto it = entries_.find(model);
  auto c = carried_s_.find(model);
  return (it == entries_.end() ? 0.0 : it->second.seconds) + (c == carried_s_.end() ? 0.0 : c->second);
}

void ModelTimers::carry(const std::map<std::string, double>& earlier_s, double from_s) {
  carried_s_ = earlier_s;
  from_s_ = from_s;
}

std::map<std::string, double> ModelTimers::totals() const {
  std::map<std::string, double> t = carried_s_;
  for (const auto& [name, e] : entries_) t[name] += e.seconds;
  return t;
}

nlohmann::json ModelTimers::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, seconds] : totals()) {
    auto it = entries_.find(name);
    j[name] = {{"detail", it == entries_.end() ? std::string() : it->second.detail},
               {"wall_time_s", seconds}};
  }
  return j;
}

std::string hex64(std::uint64_t v) {
  return fmt::format("{:016x}", v);
}

}  // namespace boycott
