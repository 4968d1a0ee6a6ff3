#include "driver/study/cost_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <queue>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/scene_specs.hpp"

namespace boycott::driver {

namespace {
double num(const nlohmann::json& j, const char* section, const char* key, double fallback) {
  if (!j.contains(section) || !j[section].contains(key) || !j[section][key].is_number()) return fallback;
  return j[section][key].get<double>();
}

constexpr int kTerms = 4;  ///< start, particle-steps, cell-steps, bed particle-steps
using Row = std::array<double, kTerms>;

/// Solves the n x n system a x = b (n <= kTerms) by Gaussian elimination; false when singular.
bool solve(std::array<Row, kTerms> a, Row b, int n, Row& x) {
  for (int c = 0; c < n; ++c) {
    int piv = c;
    for (int r = c + 1; r < n; ++r)
      if (std::abs(a[r][c]) > std::abs(a[piv][c])) piv = r;
    if (std::abs(a[piv][c]) < 1e-300) return false;
    std::swap(a[c], a[piv]);
    std::swap(b[c], b[piv]);
    for (int r = c + 1; r < n; ++r) {
      const double f = a[r][c] / a[c][c];
      for (int k = c; k < n; ++k) a[r][k] -= f * a[c][k];
      b[r] -= f * b[c];
    }
  }
  for (int r = n - 1; r >= 0; --r) {
    double s = b[r];
    for (int k = r + 1; k < n; ++k) s -= a[r][k] * x[k];
    x[r] = s / a[r][r];
  }
  return true;
}
}  // namespace

CaseWork case_work(const nlohmann::json& p, double from_s, double to_s) {
  CaseWork w;
  w.scene = p.value("scene", "");
  const double span = std::max(0.0, to_s - from_s);
  const double count = num(p, "particles", "count", 0.0);
  const double dt_dem = num(p, "time", "dt_dem", 0.0), dt_cfd = num(p, "time", "dt_cfd", 0.0);
  if (count > 0 && dt_dem > 0) w.particle_steps = count * span / dt_dem;
  if (p.contains("gravity") && p["gravity"].contains("angle_deg") && p["gravity"]["angle_deg"].is_number()) {
    const double theta = p["gravity"]["angle_deg"].get<double>() * kPi / 180.0;
    if (std::abs(std::cos(theta)) > kBedGravityShare) w.bed_particle_steps = w.particle_steps;
  }
  // A scene without fluid (or one this program does not know) has no fluid cells to pay for.
  const auto& specs = scene_specs();
  const bool fluid = std::any_of(specs.begin(), specs.end(),
                                 [&](const SceneSpec& s) { return s.name == w.scene && s.has_fluid; });
  if (p.contains("domain") && p["domain"].contains("cells") && dt_cfd > 0 && fluid) {
    double cells = 1.0;
    for (const auto& n : p["domain"]["cells"]) cells *= n.get<double>();
    w.fluid_cell_steps = cells * span / dt_cfd;
  }
  return w;
}

MeasuredCost measured_cost(const std::string& case_id, const std::string& params_json,
                           const std::string& summary_json, bool* ok) {
  MeasuredCost m;
  m.case_id = case_id;
  *ok = false;
  try {
    const auto p = nlohmann::json::parse(params_json);
    const auto s = nlohmann::json::parse(summary_json);
    const double wall = s.value("wall_time_s", 0.0), t = s.value("simulated_time_s", 0.0);
    if (!(wall > 0) || !(t > 0)) return m;
    // A branch started from its parent's time: only its own interval was paid for.
    const double from = s.contains("parent") ? s["parent"].value("time_s", 0.0) : 0.0;
    m.work = case_work(p, from, t);
    // The fluid steps it took, where the CFL or the packed-bed limit cut time.dt_cfd: the work
    // done, not the work planned (a branch's count includes its parent's steps: planned there).
    const double dt_cfd = num(p, "time", "dt_cfd", 0.0), steps = s.value("cfd_steps", 0.0);
    if (!s.contains("parent") && dt_cfd > 0 && steps > 0) m.work.fluid_cell_steps *= steps / (t / dt_cfd);
    // Its CPU time over all attempts (steadier on a shared machine, and blind to a pause); from
    // a build that recorded only the last attempt's, that where the run was done in one, else
    // its wall time (earlier attempts are only there).
    const bool one_attempt = !s.value("resumed_from_checkpoint", false);
    const auto number = [&](const char* key) { return s.contains(key) && s[key].is_number(); };
    m.core_s = number("cpu_time_s")                          ? s["cpu_time_s"].get<double>()
               : one_attempt && number("attempt_cpu_time_s") ? s["attempt_cpu_time_s"].get<double>()
                                                             : wall * std::max(1, s.value("mpi_ranks", 1));
    *ok = true;
  } catch (const std::exception&) {
    // An unreadable row does not calibrate anything.
  }
  return m;
}

CostModel::CostModel(const std::vector<MeasuredCost>& finished) {
  std::map<std::string, std::vector<const MeasuredCost*>> runs;
  for (const auto& m : finished) runs[m.work.scene].push_back(&m);
  for (const auto& [scene, ms] : runs) {
    Coefficients c;
    c.runs = static_cast<int>(ms.size());
    // Relative least squares: sum over runs of ((prediction - measured) / measured)^2. A term
    // whose coefficient comes out negative (or that no run exercises) is dropped and the rest
    // refitted; the start-up term is dropped last.
    // Runs whose fluid and particle work stand in one proportion (one box, one particle count,
    // the time varied: a campaign's angles) cannot tell the two costs apart, and a free fit puts
    // all of it on one term: a case whose fluid step is later cut would then cost nothing more.
    // Such runs fit one scale on the defaults' split between particles and fluid instead.
    double lo = 0.0, hi = 0.0;
    for (const auto* m : ms) {
      if (!(m->work.particle_steps > 0 && m->work.fluid_cell_steps > 0)) {
        lo = hi = 0.0;
        break;
      }
      const double r = m->work.fluid_cell_steps / m->work.particle_steps;
      lo = lo > 0 ? std::min(lo, r) : r, hi = std::max(hi, r);
    }
    c.one_proportion = lo > 0 && hi < kSeparatingSpread * lo;
    // The bed term only where the runs have beds and runs without: otherwise it is the particle
    // term again and cannot be told apart from it.
    bool beds = false, no_beds = false;
    for (const auto* m : ms) (m->work.bed_particle_steps > 0 ? beds : no_beds) = true;
    const auto features = [&](const CaseWork& w) -> Row {
      if (c.one_proportion)
        return {1.0, kParticleStepS * w.particle_steps + kCellStepS * w.fluid_cell_steps, 0.0,
                kParticleStepS * w.bed_particle_steps};
      return {1.0, w.particle_steps, w.fluid_cell_steps, w.bed_particle_steps};
    };
    std::array<bool, kTerms> use = {true, true, !c.one_proportion, beds && no_beds};
    bool fitted = false;
    for (int tries = 0; tries < kTerms && ms.size() >= 3 && !fitted; ++tries) {
      std::vector<int> idx;
      for (int k = 0; k < kTerms; ++k)
        if (use[k]) idx.push_back(k);
      const int n = static_cast<int>(idx.size());
      std::array<Row, kTerms> a{};
      Row b{}, x{};
      for (const auto* m : ms) {
        const Row f = features(m->work);
        const double w = 1.0 / (m->core_s * m->core_s);
        for (int r = 0; r < n; ++r) {
          for (int q = 0; q < n; ++q) a[r][q] += w * f[idx[r]] * f[idx[q]];
          b[r] += w * f[idx[r]] * m->core_s;
        }
      }
      if (!solve(a, b, n, x)) {
        // No run varies this term: drop the one with the smallest diagonal.
        int worst = 0;
        for (int r = 1; r < n; ++r)
          if (a[r][r] < a[worst][worst]) worst = r;
        use[idx[worst]] = false;
        continue;
      }
      int negative = -1;
      for (int r = n - 1; r >= 0; --r)
        if (x[r] < 0) negative = idx[r];
      if (negative >= 0) {
        use[negative] = false;
        continue;
      }
      Row coef{};
      for (int r = 0; r < n; ++r) coef[idx[r]] = x[r];
      c.start_s = coef[0], c.particle_step_s = coef[1], c.cell_step_s = coef[2],
      c.bed_particle_step_s = coef[3];
      if (c.one_proportion)
        c.particle_step_s = coef[1] * kParticleStepS, c.cell_step_s = coef[1] * kCellStepS,
        c.bed_particle_step_s = coef[3] * kParticleStepS;
      fitted = true;
    }
    if (!fitted) {
      // Too few runs to fit: the defaults, scaled to what was measured.
      double ratio = 0.0;
      for (const auto* m : ms) ratio += m->core_s / core_s(m->work);
      ratio /= static_cast<double>(ms.size());
      c.start_s *= ratio, c.particle_step_s *= ratio, c.cell_step_s *= ratio;
    }
    c.fitted = fitted;
    by_scene_[scene] = c;
  }
}

double CostModel::core_s(const CaseWork& w) const {
  const auto it = by_scene_.find(w.scene);
  const Coefficients c = it == by_scene_.end() ? Coefficients{} : it->second;
  return c.start_s + c.particle_step_s * w.particle_steps + c.cell_step_s * w.fluid_cell_steps +
         c.bed_particle_step_s * w.bed_particle_steps;
}

std::string CostModel::basis(const std::string& scene) const {
  const auto it = by_scene_.find(scene);
  if (it == by_scene_.end()) return "default";
  const Coefficients& c = it->second;
  std::string s = (c.fitted ? "fit to " : "default scaled by ") + std::to_string(c.runs) + " runs";
  if (c.fitted && c.one_proportion)
    s += " (their particle and fluid work in one proportion: split as the defaults)";
  if (c.bed_particle_step_s > 0 && c.particle_step_s > 0)
    s += fmt::format("; a bed on a wall makes a particle-step {:.2f}x as dear",
                     1.0 + c.bed_particle_step_s / c.particle_step_s);
  return s;
}

double ranks_efficiency(int ranks) {
  return std::pow(0.9, std::log2(std::max(1, ranks)));
}

double study_wall_s(std::vector<double> core_s, int jobs, int ranks) {
  const double per_core = 1.0 / (std::max(1, ranks) * ranks_efficiency(ranks));
  std::sort(core_s.begin(), core_s.end(), std::greater<>());
  std::priority_queue<double, std::vector<double>, std::greater<>> slots;
  for (int j = 0; j < std::max(1, jobs); ++j) slots.push(0.0);
  double end = 0.0;
  for (double c : core_s) {
    const double t = slots.top() + c * per_core;
    slots.pop();
    slots.push(t);
    end = std::max(end, t);
  }
  return end;
}

}  // namespace boycott::driver
