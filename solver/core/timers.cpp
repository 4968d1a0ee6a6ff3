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
  return it == entries_.end() ? 0.0 : it->second.seconds;
}

nlohmann::json ModelTimers::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, e] : entries_) {
    j[name] = {{"detail", e.detail}, {"wall_time_s", e.seconds}};
  }
  return j;
}

std::string hex64(std::uint64_t v) {
  return fmt::format("{:016x}", v);
}

}  // namespace boycott
