#include "scenes/coupled_checkpoint.hpp"

#include <mpi.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"
#include "io/state_checks.hpp"
#include "io/state_io.hpp"
#include "scenes/run_common.hpp"

namespace boycott::scenes {

namespace {

/// The fluid's state over the whole grid on rank 0, in natural order: the ranks' z-slabs are
/// consecutive blocks of whole planes in rank order, so their owned arrays follow each other.
fluid::FluidState gather_fluid(const fluid::FluidSolver& f) {
  fluid::FluidState st = f.export_state();
  int size = 1, rank = 0;
  MPI_Comm_size(f.comm(), &size);
  MPI_Comm_rank(f.comm(), &rank);
  if (size == 1) return st;
  const auto& g = f.settings().grid;
  for (auto& field : st.fields) {
    const int n = static_cast<int>(field.size());
    std::vector<int> counts(size), displs(size);
    MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, f.comm());
    int total = 0;
    for (int r = 0; r < size; ++r) displs[r] = total, total += counts[r];
    std::vector<double> all(rank == 0 ? static_cast<std::size_t>(total) : 0);
    MPI_Gatherv(field.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0,
                f.comm());
    field.swap(all);
  }
  st.box.lo = {0, 0, 0};
  st.box.size = {g.n[0], g.n[1], g.n[2]};
  return st;
}

/// This rank's planes of a whole-grid fluid state.
fluid::FluidState own_part(const fluid::FluidState& whole, const fluid::FluidSolver& f,
                           const std::string& file) {
  const auto box = f.owned_box();
  const auto& g = f.settings().grid;
  if (whole.box.lo != box.lo || whole.box.size != box.size) {
    const bool whole_grid = whole.box.lo == std::array<std::int64_t, 3>{0, 0, 0} &&
                            whole.box.size == std::array<std::int64_t, 3>{g.n[0], g.n[1], g.n[2]};
    if (!whole_grid || box.lo[0] != 0 || box.lo[1] != 0 || box.size[0] != g.n[0] || box.size[1] != g.n[1])
      throw CheckpointError(fmt::format("{}: the fluid grid was decomposed differently", file));
  } else {
    return whole;
  }
  fluid::FluidState st = whole;
  st.box = box;
  const std::size_t plane = static_cast<std::size_t>(g.n[0] * g.n[1]);
  for (auto& field : st.fields) {
    const auto first =
        field.begin() + static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(box.lo[2]));
    field = std::vector<double>(
        first, first + static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(box.size[2])));
  }
  return st;
}

}  // namespace

void save_coupled(io::CheckpointWriter* w, const coupling::CoupledSystem& run) {
  const auto c = run.counters();
  // Collective: every rank contributes, rank 0 writes. After a step interrupted inside its
  // particle sub-steps, the particles and coupler as they were at its start (the counters and
  // the fluid have not moved since).
  const auto* start = run.interrupted_state();
  const auto dem = start ? start->dem : run.dem().export_state();
  const auto fluid = gather_fluid(run.fluid());
  const auto coupler = start ? start->coupler : run.coupler().export_state();
  if (!w) return;
  w->put("run.time_s", c.time_s);
  w->put("run.dt_prev_s", c.dt_prev_s);
  w->put_int("run.steps", c.steps);
  w->put_int("run.unconverged_fluid_steps", c.unconverged_fluid_steps);
  w->put_int("run.pressure_fallbacks", c.pressure_fallbacks);
  io::save(*w, "dem.", dem);
  io::save(*w, "fluid.", fluid);
  io::save(*w, "coupler.", coupler);
}

namespace {

/// What a coupled run resumes from, read from a checkpoint and checked before any of it reaches
/// the run (so that a refused file leaves the run as it was, for the next older one).
struct CoupledCheckpoint {
  coupling::CoupledCounters counters;
  particles::DemState dem;
  fluid::FluidState fluid;
  std::vector<std::vector<double>> coupler;
  RunSpent spent;
};

/// Each model's wall time over the attempts that wrote the checkpoint, s. Absent (a build that
/// recorded none): the models' times count from the resume point, t_s, instead of from the start.
void read_model_times(const io::CheckpointReader& r, double t_s, RunSpent& spent) {
  if (!r.has("run.model_names")) {
    spent.models_from_s = t_s;
    return;
  }
  const auto names = r.strings("run.model_names");
  const auto seconds = r.doubles("run.model_wall_time_s");
  spent.models_from_s = r.scalar("run.model_times_from_s");
  const std::string file = r.path().string();
  if (seconds.size() != names.size())
    throw CheckpointError(fmt::format("checkpoint {}: 'run.model_wall_time_s' holds {} values for {} models",
                                      file, seconds.size(), names.size()));
  if (!(spent.models_from_s >= 0.0 && spent.models_from_s <= t_s))
    throw CheckpointError(
        fmt::format("checkpoint {}: dataset 'run.model_times_from_s' fails the check: {} is not in [0, {}] s",
                    file, spent.models_from_s, t_s));
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (!(seconds[k] >= 0.0 && std::isfinite(seconds[k])))
      throw CheckpointError(
          fmt::format("checkpoint {}: dataset 'run.model_wall_time_s' fails the check: {} ({}) is not a time",
                      file, seconds[k], names[k]));
    spent.model_wall_s[names[k]] = seconds[k];
  }
}

CoupledCheckpoint read_coupled(const io::CheckpointReader& r, const CaseParams& p) {
  CoupledCheckpoint c;
  c.counters.time_s = r.scalar("run.time_s");
  c.counters.dt_prev_s = r.scalar("run.dt_prev_s");
  c.counters.steps = r.integer("run.steps");
  // absent from checkpoints written before these counters existed
  c.counters.unconverged_fluid_steps =
      r.has("run.unconverged_fluid_steps") ? r.integer("run.unconverged_fluid_steps") : 0;
  c.counters.pressure_fallbacks = r.has("run.pressure_fallbacks") ? r.integer("run.pressure_fallbacks") : 0;
  io::load(r, "dem.", c.dem);
  io::load(r, "fluid.", c.fluid);
  c.coupler = io::load_arrays(r, "coupler.");
  c.spent.wall_s = r.scalar("run.wall_time_s");
  // absent from checkpoints written before runs recorded their CPU time: unknown, not zero
  c.spent.cpu_core_s = r.has("run.cpu_time_s") ? r.scalar("run.cpu_time_s") : kUnset;
  if (r.has("run.cpu_time_s") && !(c.spent.cpu_core_s >= 0.0))
    throw CheckpointError(
        fmt::format("checkpoint {}: dataset 'run.cpu_time_s' fails the check: {} is not a time",
                    r.path().string(), c.spent.cpu_core_s));
  const std::string file = r.path().string();
  const io::StateBounds box{{p.domain.length_x_m, p.domain.width_y_m, p.domain.height_z_m},
                            {true, p.domain.periodic_y, true}};
  io::check_state(c.dem, box, file, "dem.");
  io::check_state(c.fluid, file, "fluid.");
  io::check_finite(c.coupler, file, "coupler.");
  for (const auto& [name, v] : {std::pair{"run.time_s", c.counters.time_s},
                                {"run.dt_prev_s", c.counters.dt_prev_s},
                                {"run.wall_time_s", c.spent.wall_s}})
    if (!std::isfinite(v))
      throw CheckpointError(
          fmt::format("checkpoint {}: dataset '{}' fails the check: {} is not finite", file, name, v));
  read_model_times(r, c.counters.time_s, c.spent);
  return c;
}

void import_coupled(const CoupledCheckpoint& c, coupling::CoupledSystem& run, const std::string& file) {
  run.restore_counters(c.counters);
  run.decompose();
  run.dem().import_state(c.dem);
  run.fluid().import_state(own_part(c.fluid, run.fluid(), file));
  run.coupler().import_state(c.coupler, run.dem());
}

/// How one candidate checkpoint fared on this rank.
enum Verdict : int { kUsable = 0, kRefused = 1, kOtherCase = 2 };

/// A branch: the parent's state under this case's parameters (run_case checked what may
/// differ); the particles take this case's size and density.
void start_from_parent(coupling::CoupledSystem& run, const std::filesystem::path& parent, bool quiet) {
  io::CheckpointReader r(parent);
  import_coupled(read_coupled(r, run.params()), run, parent.string());
  const auto& pp = run.params().particles;
  run.dem().set_particle_properties(0.5 * pp.diameter_m, pp.density_kg_m3);
  if (!quiet && output_rank())
    std::fprintf(stderr, "branching from %s at t = %g s\n", parent.c_str(), run.time_s());
}

/// Reads and checks one candidate on this rank: kUsable with `r` and `state` set, or a verdict
/// and the reason in `why`. Never throws, so that every rank reaches the reduction after it.
int judge_checkpoint(const std::filesystem::path& ck, const std::string& id, const CaseParams& params,
                     std::optional<io::CheckpointReader>& r, std::optional<CoupledCheckpoint>& state,
                     std::string& why) {
  try {
    r.emplace(ck);
    // The identity of the parameters it holds, in this program's scheme (a checkpoint written
    // before case identity version 2 names its case by the older id).
    const std::string stored =
        r->has("case_json") ? case_id_of_json(r->string("case_json")) : r->string("case_id");
    if (stored != id) {
      why = fmt::format("{} belongs to case {}, not {}; it is left in place", ck.string(), stored, id);
      return kOtherCase;
    }
    state = read_coupled(*r, params);
    return kUsable;
  } catch (const CheckpointError& e) {
    why = e.what();
  } catch (const std::exception& e) {
    // What a damaged file without a hash can make a reader throw (a size beyond memory, say).
    why = fmt::format("checkpoint {} is unreadable: {}", ck.string(), e.what());
  }
  return kRefused;
}

/// After resuming from candidates[k]: the newer, refused ones set aside (out of the way of this
/// run's later checkpoints of the same steps, and of pruning), the time series cut to the
/// checkpoint's time, and what happened said.
void settle_after_resume(const std::vector<std::filesystem::path>& candidates, std::size_t k,
                         const io::CheckpointReader& r, const coupling::CoupledSystem& run,
                         const std::filesystem::path& run_dir, bool quiet) {
  const auto& ck = candidates[k];
  if (output_rank()) {
    for (std::size_t j = 0; j < k; ++j) {
      const auto kept = io::set_aside(candidates[j]);
      std::fprintf(stderr, "refused checkpoint kept as %s\n", kept.c_str());
    }
    if (r.integrity() == io::Integrity::kUnverified)
      std::fprintf(stderr,
                   "note: %s carries no hash (written before checkpoints did): resumed from it "
                   "unverified\n",
                   ck.c_str());
  }
  truncate_csv_after(run_dir / "timeseries.csv", run.time_s());
  if (!quiet && output_rank())
    std::fprintf(stderr, "resuming from %s at t = %g s%s\n", ck.c_str(), run.time_s(),
                 k > 0 ? " (an older checkpoint: the newer ones were refused)" : "");
}

}  // namespace

void load_coupled(const io::CheckpointReader& r, coupling::CoupledSystem& run) {
  import_coupled(read_coupled(r, run.params()), run, r.path().string());
}

std::optional<RunSpent> resume_coupled(coupling::CoupledSystem& run, const std::filesystem::path& run_dir,
                                       bool quiet,
                                       const std::function<void(const io::CheckpointReader&)>& load_scene,
                                       const std::filesystem::path& branch_checkpoint) {
  // Listed once, before any is set aside, so that every rank walks the same list.
  const auto candidates = io::checkpoints_newest_first(run_dir);
  if (candidates.empty()) {
    if (branch_checkpoint.empty()) return std::nullopt;
    start_from_parent(run, branch_checkpoint, quiet);
    RunSpent own;  // a branch pays for its own steps, from the parent's time
    own.models_from_s = run.time_s();
    return own;
  }
  const std::string id = case_id(run.params());
  std::vector<std::string> refused;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const auto& ck = candidates[k];
    // Every rank reads and checks the same bytes; the verdicts are combined all the same, so
    // that no rank resumes from a file another one refused.
    std::optional<io::CheckpointReader> r;
    std::optional<CoupledCheckpoint> state;
    std::string why;
    const int verdict = judge_checkpoint(ck, id, run.params(), r, state, why);
    int worst = verdict;
    MPI_Allreduce(&verdict, &worst, 1, MPI_INT, MPI_MAX, run.fluid().comm());
    if (worst == kOtherCase)
      throw CheckpointError(why.empty() ? fmt::format("{} belongs to another case", ck.string()) : why);
    if (worst == kRefused) {
      if (why.empty()) why = fmt::format("checkpoint {} was refused on another rank", ck.string());
      if (output_rank()) std::fprintf(stderr, "checkpoint refused: %s\n", why.c_str());
      refused.push_back(why);
      continue;
    }
    import_coupled(*state, run, ck.string());
    load_scene(*r);
    settle_after_resume(candidates, k, *r, run, run_dir, quiet);
    return state->spent;
  }
  std::string all;
  for (const auto& w : refused) all += (all.empty() ? "" : "; ") + w;
  throw CheckpointError(fmt::format(
      "no usable checkpoint in {}: {} refused ({}); they are left in place: move them away to start over",
      (run_dir / "checkpoints").string(), refused.size(), all));
}

void checkpoint_coupled(const coupling::CoupledSystem& run, const std::filesystem::path& run_dir,
                        const RunSpent& spent, const std::function<void(io::CheckpointWriter&)>& save_scene) {
  // One file for all ranks, written by rank 0 from the gathered state.
  std::optional<io::CheckpointWriter> w;
  if (output_rank()) {
    w.emplace(io::checkpoint_path(run_dir, run.steps()));
    w->put_string("case_id", case_id(run.params()));
    w->put_string("case_json", to_json(run.params()).dump());
    w->put_string("program_version", std::string(kVersion));
  }
  save_coupled(w ? &*w : nullptr, run);
  if (!w) return;
  save_scene(*w);
  w->put("run.wall_time_s", spent.wall_s);
  if (std::isfinite(spent.cpu_core_s)) w->put("run.cpu_time_s", spent.cpu_core_s);
  std::vector<std::string> names;
  std::vector<double> seconds;
  for (const auto& [name, s] : spent.model_wall_s) names.push_back(name), seconds.push_back(s);
  w->put_strings("run.model_names", names);
  w->put("run.model_wall_time_s", seconds);
  w->put("run.model_times_from_s", spent.models_from_s);
  w->commit();
  io::prune_checkpoints(run_dir, static_cast<int>(run.params().output.keep_checkpoints));
}

}  // namespace boycott::scenes
