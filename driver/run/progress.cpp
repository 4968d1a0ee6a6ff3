#include "driver/run/progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "driver/report/series_table.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

std::string count_of(long long n, const std::string& noun) {
  return fmt::format("{} {}{}", n, noun, n == 1 ? "" : "s");
}

std::string eta_text(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long v = std::lround(s);
  if (v >= 3600) return fmt::format("{}h{:02d}m", v / 3600, static_cast<int>(v % 3600 / 60));
  if (v >= 60) return fmt::format("{}m{:02d}s", v / 60, static_cast<int>(v % 60));
  return fmt::format("{}s", v);
}

namespace {
/// The last non-empty line of a file, read from its end (a run's series grows to megabytes).
std::string last_line(const fs::path& file) {
  std::ifstream in(file, std::ios::ate);
  if (!in) return {};
  const auto size = static_cast<std::streamoff>(in.tellg());
  const std::streamoff back = std::min<std::streamoff>(size, 4096);
  in.seekg(size - back);
  std::string chunk(static_cast<std::size_t>(back), '\0');
  in.read(chunk.data(), back);
  auto end = chunk.find_last_not_of("\n\r ");
  if (end == std::string::npos) return {};
  const auto newline = chunk.rfind('\n', end);
  const std::size_t begin = newline == std::string::npos ? 0 : newline + 1;
  return chunk.substr(begin, end + 1 - begin);
}
}  // namespace

double simulated_time_s(const fs::path& run_dir) {
  const std::string line = last_line(run_dir / "timeseries.csv");
  char* stop = nullptr;
  const double t = std::strtod(line.c_str(), &stop);
  return stop == line.c_str() ? 0.0 : t;
}

double last_row_value(const fs::path& run_dir, const std::string& column) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::ifstream in(run_dir / "timeseries.csv");
  std::string header;
  if (!in || !std::getline(in, header)) return nan;
  const auto names = report::series_cells(header);
  const auto at = std::find(names.begin(), names.end(), column);
  const std::string line = last_line(run_dir / "timeseries.csv");
  if (at == names.end() || line == header) return nan;
  const auto cells = report::series_cells(line);
  const auto index = static_cast<std::size_t>(at - names.begin());
  if (index >= cells.size()) return nan;
  char* stop = nullptr;
  const double v = std::strtod(cells[index].c_str(), &stop);
  return stop == cells[index].c_str() || *stop != '\0' ? nan : v;
}

void RecentRate::add(Clock::time_point now, double t_s) {
  const auto seconds = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  };
  if (samples_.empty()) {
    first_ = now;
    samples_.emplace_back(now, t_s);
    return;
  }
  if (seconds(samples_.back().first, now) >= kSampleEveryS) samples_.emplace_back(now, t_s);
  const double keep = std::max(kRecentMinS, kRecentFraction * seconds(first_, now));
  while (samples_.size() > 2 && seconds(samples_[1].first, now) >= keep) samples_.pop_front();
}

double RecentRate::wall_s_per_sim_s(Clock::time_point now, double t_s) const {
  if (samples_.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto& [w_old, t_old] = samples_.front();
  const double sim = t_s - t_old, wall = std::chrono::duration<double>(now - w_old).count();
  return sim > 0 && wall > 0 ? wall / sim : std::numeric_limits<double>::quiet_NaN();
}

double PlannedCase::wall_s_per_sim_s() const {
  return end_s > from_s ? wall_s / (end_s - from_s) : std::numeric_limits<double>::quiet_NaN();
}

void ProgressDisplay::set_plan(const std::map<std::string, PlannedCase>& cases) {
  plan_ = {cases.begin(), cases.end()};
  double sum = 0.0;
  for (const auto& [id, p] : plan_) sum += p.wall_s;
  planned_case_wall_s_ =
      plan_.empty() ? std::numeric_limits<double>::quiet_NaN() : sum / static_cast<double>(plan_.size());
}

void ProgressDisplay::add_finished_case(const std::string& id, double wall_s, double from_s) {
  finished_wall_s_.push_back(wall_s);
  last_t_s_.erase(id);
  const auto p = plan_.find(id);
  if (p == plan_.end() || !(p->second.wall_s_per_sim_s() > 0) || !(p->second.end_s > from_s) || !(wall_s > 0))
    return;
  speed_ratios_[id] = wall_s / (p->second.end_s - from_s) / p->second.wall_s_per_sim_s();
}

ProgressDisplay::ProgressDisplay(std::string study, int jobs, bool live, double plain_every_s)
    : study_(std::move(study)),
      jobs_(jobs),
      live_(live),
      plain_every_s_(plain_every_s),
      last_draw_(Clock::now()) {}

void ProgressDisplay::redraw_if_due(const std::function<ProgressCounts()>& counts,
                                    const std::vector<RunningCase>& running) {
  const auto every =
      live_ ? std::chrono::duration<double>(0.5) : std::chrono::duration<double>(plain_every_s_);
  if ((live_ || plain_every_s_ > 0) && Clock::now() - last_draw_ >= every) {
    draw(counts(), running);
    last_draw_ = Clock::now();
  }
}

void ProgressDisplay::draw_at(const ProgressCounts& counts, const std::vector<RunningCase>& running,
                              Clock::time_point now) {
  if (!live_ && plain_every_s_ <= 0) return;
  std::string s;
  if (live_) {
    if (printed_lines_ > 0) s += fmt::format("\033[{}A", printed_lines_);
    s += "\033[J";
  }
  double remaining_s = 0, estimated_case_s = 0;
  int estimated = 0;
  std::vector<const RunningCase*> unknown;  // running cases without a rate yet
  std::string rows;
  std::map<std::string, RecentRate> rates;
  for (const auto& j : running) {
    const double t_s = simulated_time_s(j.dir);
    last_t_s_[j.c->id] = t_s;
    const double wall_s = std::chrono::duration<double>(now - j.started).count();
    // The recent rate, from the samples of this case's earlier draws (the first at its start).
    RecentRate& rate = rates[j.dir.string()] = std::move(rates_[j.dir.string()]);
    if (rate.empty()) rate.add(j.started, j.t_start_s);
    rate.add(now, t_s);
    const double recent = rate.wall_s_per_sim_s(now, t_s);
    const double sim_s_per_s =
        std::isfinite(recent) ? 1.0 / recent : (wall_s > 0 ? (t_s - j.t_start_s) / wall_s : 0);
    const double end_s = j.c->params.time.end_s;
    if (sim_s_per_s > 0) {
      remaining_s += (end_s - t_s) / sim_s_per_s;
      estimated_case_s += end_s / sim_s_per_s;
      ++estimated;
      if (const auto p = plan_.find(j.c->id); p != plan_.end() && p->second.wall_s_per_sim_s() > 0)
        speed_ratios_[j.c->id] = 1.0 / sim_s_per_s / p->second.wall_s_per_sim_s();
    } else {
      unknown.push_back(&j);
    }
    rows += fmt::format("  {} {:<12} {:5.1f} deg  t = {:8.3f} / {:g} s  {:8.4f} sim s/s\n", j.c->id,
                        j.c->group, j.c->params.gravity.angle_deg, t_s, end_s, sim_s_per_s);
  }
  // A case the plan does not price: the mean wall time of the cases finished in this run, else an
  // estimate from the running ones, else the plan's mean.
  double per_case_s = estimated > 0 ? estimated_case_s / estimated : planned_case_wall_s_;
  if (!finished_wall_s_.empty()) {
    per_case_s = 0;
    for (double w : finished_wall_s_) per_case_s += w;
    per_case_s /= static_cast<double>(finished_wall_s_.size());
  }
  // How fast the cases run against the plan: it prices each case the plan knows.
  double speed_ratio = 1.0;
  if (!speed_ratios_.empty()) {
    speed_ratio = 0;
    for (const auto& [id, r] : speed_ratios_) speed_ratio += r;
    speed_ratio /= static_cast<double>(speed_ratios_.size());
  }
  const auto planned_rest_s = [&](const std::string& id) {
    const auto p = plan_.find(id);
    if (p == plan_.end()) return per_case_s;
    const auto seen = last_t_s_.find(id);
    const double from_s =
        seen == last_t_s_.end() ? p->second.from_s : std::max(p->second.from_s, seen->second);
    const double per_sim = p->second.wall_s_per_sim_s();
    const double planned = std::isfinite(per_sim) ? per_sim * (p->second.end_s - from_s) : p->second.wall_s;
    return speed_ratio * std::max(0.0, planned);
  };
  for (const RunningCase* j : unknown) remaining_s += planned_rest_s(j->c->id);
  for (const auto& id : counts.pending_ids) remaining_s += planned_rest_s(id);
  const std::size_t unnamed = counts.pending - std::min(counts.pending, counts.pending_ids.size());
  const double eta_s = (remaining_s + static_cast<double>(unnamed) * per_case_s) / jobs_;
  s += fmt::format("study {}: {} done, {} running, {} failed, {} pending; ETA {}{}\n", study_, counts.done,
                   running.size(), counts.failed, counts.pending, eta_text(eta_s),
                   counts.stopping ? " (stopping)" : "");
  s += rows;
  rates_ = std::move(rates);  // a case that stopped running drops its samples
  printed_lines_ = 1 + static_cast<int>(running.size());
  std::fputs(s.c_str(), stderr);
  std::fflush(stderr);
}

}  // namespace boycott::driver
