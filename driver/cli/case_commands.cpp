#include "driver/cli/case_commands.hpp"

#include <mpi.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "checks/check_case.hpp"
#include "core/case_params.hpp"
#include "core/error.hpp"
#include "core/key_docs.hpp"
#include "driver/cli/case_progress.hpp"
#include "driver/report/listing_format.hpp"
#include "driver/report/report_util.hpp"
#include "driver/report/terminal_text.hpp"
#include "driver/run/run_folder_lock.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"
#include "fluid/petsc_session.hpp"
#include "io/atomic_file.hpp"
#include "runs/run_case.hpp"
#include "scenes/scene.hpp"
#include "scenes/summarize.hpp"

namespace boycott::driver {

namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) {
  g_stop.store(true);
}

/// The solver's stop signals (the driver's own are run/solver_process.hpp's): a stop, or a Slurm
/// task's wall-time warning, sets g_stop; the run checkpoints and exits 75.
void catch_stop_signals() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGUSR1, &sa, nullptr);  // a Slurm task's wall-time warning (study submit)
}

/// --stop-after: the same stop, asked by a timer after `seconds` of wall time (every rank sets its
/// own; the run agrees on the step to stop at as for a signal, RunContext::should_stop).
void stop_after(double seconds) {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGALRM, &sa, nullptr);
  itimerval t{};
  t.it_value.tv_sec = static_cast<time_t>(seconds);
  t.it_value.tv_usec = static_cast<suseconds_t>(1e6 * (seconds - static_cast<double>(t.it_value.tv_sec)));
  if (t.it_value.tv_sec == 0 && t.it_value.tv_usec == 0) t.it_value.tv_usec = 1;
  setitimer(ITIMER_REAL, &t, nullptr);
}

/// One line at the end of a run: its status, how far, how long, and its main result.
void print_outcome(const std::filesystem::path& dir) {
  try {
    std::ifstream in(dir / "summary.json");
    if (!in) return;
    const auto j = nlohmann::json::parse(in);
    std::string result;
    if (j.contains("mean_settling_velocity_m_s") && j["mean_settling_velocity_m_s"].is_number()) {
      const auto& e = j.value("settling_velocity_stderr_m_s", nlohmann::json());
      result = fmt::format(", <<w_p>> = {:.5g} m/s +- {}", j["mean_settling_velocity_m_s"].get<double>(),
                           e.is_number() ? fmt::format("{:.2g}", e.get<double>()) : std::string("n/a"));
    }
    // The result, on stdout (progress and warnings are on stderr): `case run ... > result.txt`.
    std::printf("%s at t = %.6g s after %.1f s of wall time%s (%s)\n", j.value("status", "?").c_str(),
                j.value("simulated_time_s", 0.0), j.value("wall_time_s", 0.0), result.c_str(),
                (dir / "summary.json").c_str());
    std::fflush(stdout);
  } catch (const std::exception&) {
    // The summary is the record; a line about it is not worth failing the run.
  }
}

// The run folder's lock (the one `study run` holds for its solvers), taken by rank 0 before
// anything is written, unless the parent holds it for this process (kRunFolderLockedEnv); all
// ranks learn the outcome. Kept until the process exits. Returns whether it made the folder (a
// run refused before writing removes it again: see forget_unused_run_folder).
bool hold_run_folder(const std::string& out_dir, int rank) {
  namespace fs = std::filesystem;
  enum : int { kHeld = 1, kLocked = 0, kCannotCreate = -1, kStorage = -2 };
  int state = kHeld;
  std::string holder, why;
  bool made = false;
  if (rank == 0) {
    std::error_code ec;
    made = !fs::exists(out_dir, ec);
    fs::create_directories(out_dir, ec);
    if (ec || !fs::is_directory(out_dir)) {
      // A place the user chose that cannot hold a folder is bad input; a full or failing disk is
      // a storage error (74), which a study retries.
      const int e = ec.value();
      state = e == ENOSPC || e == EIO || e == EDQUOT ? kStorage : kCannotCreate;
      why = ec ? ec.message() : std::string("it is not a folder");
    } else {
      const auto dir = fs::weakly_canonical(out_dir, ec);
      const char* parent = std::getenv(kRunFolderLockedEnv);
      if (!(parent && !ec && fs::path(parent) == dir)) {
        state = lock_run_folder(out_dir).has_value() ? kHeld : kLocked;
        if (state == kLocked) holder = run_folder_holder(out_dir);
      }
    }
  }
  MPI_Bcast(&state, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (state == kCannotCreate)
    throw InputError(
        fmt::format("--out '{}': cannot make the run folder there ({}): choose a folder you can write",
                    out_dir, why.empty() ? "see rank 0" : why));
  if (state == kStorage)
    throw StorageError(fmt::format("--out '{}': cannot make the run folder ({})", out_dir, why));
  if (state == kLocked)
    throw CheckpointError(fmt::format(
        "run folder '{}' is in use: {} holds its .lock (a `case run` or `study run` still running); "
        "nothing was written",
        out_dir, holder.empty() ? std::string("another process") : "process " + holder));
  return made;
}

// A folder this run made for its lock and then wrote nothing into (the case was refused): gone,
// so that a refused run leaves nothing behind.
void forget_unused_run_folder(const std::string& out_dir, bool made) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!made) return;
  for (const auto& e : fs::directory_iterator(out_dir, ec))
    if (e.path().filename() != ".lock") return;
  fs::remove_all(out_dir, ec);
}

}  // namespace

int case_run(const CaseRunOptions& opt, int argc, char** argv) {
  CaseParams p = load_case_file(opt.case_file, opt.overrides);
  std::string petsc_opts = "-no_signal_handler";
  for (const auto& o : opt.petsc_options) petsc_opts += " " + o;
  int pargc = 1;
  char** pargv = argv;
  fluid::PetscSession petsc(&pargc, &pargv, petsc_opts);
  catch_stop_signals();
  if (opt.stop_after_s > 0.0) stop_after(opt.stop_after_s);
  scenes::RunContext ctx;
  ctx.out_dir = opt.out_dir;
  ctx.stop_requested = &g_stop;
  ctx.quiet = opt.quiet;
  ctx.branch_from = opt.from_dir;
  if (opt.at_s >= 0.0) ctx.branch_at_s = opt.at_s;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const bool made_folder = hold_run_folder(opt.out_dir, rank);
  CaseProgress progress(p.time.end_s, isatty(STDERR_FILENO) != 0, opt.progress_every_s);
  if (rank == 0 && !opt.quiet) {
    ctx.progress = [&](double t) { progress.at(t); };
    ctx.progress_note = [&](const std::string& s) { progress.note(s); };
  }
  try {
    // The key rules were applied as the file was loaded; the pre-flight is on this run's ranks.
    const checks::Preflight pre = checks::preflight_case(p, runs::run_ranks(), false);
    const int rc = runs::run_case(p, pre, ctx);
    if (rank == 0 && !opt.quiet) {
      progress.finish();
      print_outcome(ctx.out_dir);
    }
    // A PETSc option nothing read is most often misspelt: say so rather than ignore it.
    if (rank == 0)
      for (const auto& o : fluid::PetscSession::unused_options())
        std::fprintf(stderr, "warning: the PETSc option %s was given after -- but nothing used it\n",
                     o.c_str());
    return rc;
  } catch (const std::exception& e) {
    if (rank == 0) forget_unused_run_folder(opt.out_dir, made_folder);
    // On several ranks an error is most often met by one rank (the writer, or the one whose
    // particles went wrong) while the others wait in the run's next collective: finalizing, or
    // returning to main, would wait for them forever (seen under srun --mpi=pmix). Say why, on
    // the rank that knows, and end them all with the error's own exit code.
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size == 1) throw;
    std::fprintf(stderr, "error (rank %d of %d): %s\n", rank, size, printable(e.what()).c_str());
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, exit_code_of(e));
    throw;
  }
}

int case_check(const std::string& file, const std::vector<std::string>& sets) {
  CaseParams p = load_case_file(file, sets);
  const checks::Preflight pre = checks::preflight_case(p, 1, false);
  std::printf("case %s (scene %s): %s\n", case_id(p).c_str(), p.scene.c_str(),
              pre.errors.empty()
                  ? (pre.warnings.empty() && pre.machine_errors.empty() ? "valid" : "valid, with warnings")
                  : "REFUSED");
  std::printf("  box %g x %g x %g m (x, y, z), cells [%lld, %lld, %lld], inclination %g deg\n",
              p.domain.length_x_m, p.domain.width_y_m, p.domain.height_z_m,
              static_cast<long long>(p.domain.cells[0]), static_cast<long long>(p.domain.cells[1]),
              static_cast<long long>(p.domain.cells[2]), p.gravity.angle_deg);
  std::printf("  particles %lld, solid fraction %.4f, dt_dem %.4g us, dt_cfd %.4g ms\n",
              static_cast<long long>(p.particles.count), p.solid_fraction(), p.time.dt_dem_s * 1e6,
              p.time.dt_cfd_s * 1e3);
  std::fputs(pre.text().c_str(), stdout);
  if (!pre.errors.empty()) {
    std::fprintf(stderr, "error: %s\n", printable(pre.errors.front()).c_str());
    return kExitInputError;
  }
  return 0;
}

int case_summarize(const std::vector<std::string>& run_dirs, const std::string& db_path) {
  namespace fs = std::filesystem;
  // Every folder is recomputed before anything is written: a folder that cannot be stops all.
  std::vector<nlohmann::json> summaries;
  for (const auto& dir : run_dirs) summaries.push_back(scenes::resummarize_run(dir));
  std::optional<Database> db;
  if (!db_path.empty()) db.emplace(db_path, OpenMode::kExisting);
  for (std::size_t i = 0; i < run_dirs.size(); ++i) {
    const fs::path dir(run_dirs[i]);
    const auto& j = summaries[i];
    fs::copy_file(dir / "summary.json", dir / "summary.previous.json", fs::copy_options::overwrite_existing);
    io::write_file_atomic(dir / "summary.json", j.dump(2) + "\n");
    const std::string id = j.value("case_id", "");
    const bool updated = db && update_result_summary(*db, id, j);
    auto num = [&](const char* k) {
      return j.contains(k) && j[k].is_number() ? fmt::format("{:.6g}", j[k].get<double>())
                                               : std::string("n/a");
    };
    const std::string dof = num("settling_velocity_error_dof");
    std::printf(
        "%s: <<w_p>> %s m/s +- %s (covering, %s %s of freedom; plain %s), transient ends at %s s, "
        "window from %s s%s\n",
        dir.string().c_str(), num("mean_settling_velocity_m_s").c_str(),
        num("settling_velocity_error_m_s").c_str(), dof.c_str(), dof == "1" ? "degree" : "degrees",
        num("settling_velocity_stderr_m_s").c_str(), num("transient_end_s").c_str(),
        num("average_from_s").c_str(),
        db ? (updated ? "; database row updated" : "; no row of this case in the database") : "");
  }
  return 0;
}

int case_keys(const std::string& scene, const std::string& format) {
  const ListingFormat listing = parse_listing_format(format);
  // A scene's keys at its own defaults (resolved for Table III's box), or every key.
  CaseParams p;
  if (!scene.empty()) {
    apply_override(p, "scene=\"" + scene + "\"");
    validate(p);
  }
  const auto j = to_json_all_keys(p);
  nlohmann::json out = nlohmann::json::array();
  std::string table;
  for (const auto& k : scene.empty() ? case_key_names() : case_key_names(scene)) {
    std::string ptr = "/" + k;
    for (auto& c : ptr)
      if (c == '.') c = '/';
    const auto& value = j.at(nlohmann::json::json_pointer(ptr));
    const auto doc = key_doc(k);
    const std::string unit(doc ? doc->unit : ""), meaning(doc ? doc->meaning : "");
    out.push_back({{"key", k}, {"default", value}, {"unit", unit}, {"meaning", meaning}});
    table += fmt::format("{:<38} {:<22} {:<7} {}\n", k, value.dump(), unit, meaning);
  }
  if (listing == ListingFormat::kJson) {
    std::printf("%s\n", out.dump(1).c_str());
    return 0;
  }
  if (listing == ListingFormat::kCsv) {
    // The default as its JSON text (a string quoted, an array bracketed), as the table shows it.
    std::string csv = "key,default,unit,meaning\n";
    for (const auto& r : out)
      csv +=
          fmt::format("{},{},{},{}\n", report::csv_field(r["key"].get<std::string>()),
                      report::csv_field(r["default"].dump()), report::csv_field(r["unit"].get<std::string>()),
                      report::csv_field(r["meaning"].get<std::string>()));
    std::fputs(csv.c_str(), stdout);
    return 0;
  }
  if (!scene.empty()) std::printf("scene %s: %s\n", scene.c_str(), scene_spec(scene).measures.c_str());
  std::printf("%-38s %-22s %-7s %s\n%s", "key", "default", "unit", "meaning", table.c_str());
  return 0;
}

}  // namespace boycott::driver
