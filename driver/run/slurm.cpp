#include "driver/run/slurm.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"
#include "driver/run/collect.hpp"
#include "driver/run/refine_rounds.hpp"
#include "driver/run/run_tree.hpp"
#include "driver/run/slurm_commands.hpp"
#include "driver/run/solver_process.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"
#include "driver/store/store_slurm.hpp"
#include "driver/study/study.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {
namespace {

/// The wall-time warning: seconds before the limit, as #SBATCH --signal=B:USR1@<this> asks.
constexpr int kWarningLeadS = 120;

/// `s` in single quotes for bash.
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

std::string words_quoted(const std::vector<std::string>& words) {
  std::string s;
  // Appended in two steps: GCC 12 warns (-Wrestrict, a false positive) about the inlined
  // const char* + std::string&& it would otherwise build.
  for (const auto& w : words) {
    if (!s.empty()) s += ' ';
    s += shell_quote(w);
  }
  return s;
}

/// A name for the job: the study's, in characters that need no quoting.
std::string job_name(const std::string& study) {
  std::string n = "boycott-";
  for (char ch : study)
    n += std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' ? ch : '_';
  return n;
}

void validate(const SlurmSubmitOptions& opt) {
  if (opt.scheduler != "slurm")
    throw InputError(fmt::format("--scheduler {}: the only scheduler is slurm", opt.scheduler));
  if (opt.ranks < 1) throw InputError(fmt::format("--ranks = {} must be >= 1", opt.ranks));
  if (opt.retries < 0) throw InputError(fmt::format("--retries = {} must be >= 0", opt.retries));
  if (opt.max_running < 0) throw InputError(fmt::format("--max-running = {} must be >= 0", opt.max_running));
  // Slurm's forms: minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS.
  static const std::regex time_re(R"(^(\d+|\d+:\d{1,2}|\d+:\d{1,2}:\d{1,2}|\d+-\d+(:\d{1,2}){0,2})$)");
  if (!opt.time.empty() && !std::regex_match(opt.time, time_re))
    throw InputError(
        fmt::format("--time {}: not a Slurm time limit (HH:MM:SS, D-HH:MM:SS or minutes)", opt.time));
  if (opt.partition.find_first_of(" \t\n'\"\\$`") != std::string::npos)
    throw InputError(fmt::format("--partition '{}' is not a partition name", opt.partition));
  if (opt.launcher != "srun" && opt.launcher != "mpirun")
    throw InputError(fmt::format("--launcher {}: use srun (srun --mpi=pmix) or mpirun", opt.launcher));
  for (const auto& a : opt.sbatch_args)
    if (a.empty() || a[0] != '-' || a.find_first_of("\n\r") != std::string::npos)
      throw InputError(
          fmt::format("--sbatch-arg '{}': give one sbatch option, e.g. --sbatch-arg=--account=X", a));
}

struct ScriptPaths {
  fs::path folder;  ///< where the script, the tasks file and Slurm's output files go
  fs::path tasks;
  fs::path runs_root;
};

/// What an array task does (see slurm.hpp), in bash; @NAME@ are filled in by batch_script.
constexpr const char* kTaskScript = R"SH(#
# Array task i runs the case on line i+1 of the tasks file (case id, failed attempts before this
# submission) in its run folder <runs>/<case_id>/ as `boycott study run` would, and records each
# attempt there (attempts/*.json, attempt.json the newest) for `boycott study collect`: it never
# opens the database. The wall-time warning (USR1) is handed to the solver, which checkpoints and
# exits 75, and the task requeues its job; a storage error (74) requeues it after a pause; other
# failures run the case again here until the retries are spent.
set -u
tasks=@TASKS@
runs=@RUNS@
ranks=@RANKS@
retries=@RETRIES@
version=@VERSION@
storage_pause_s=${BOYCOTT_STORAGE_PAUSE_S:-60}
solver=(@SOLVER@)
launcher=(@LAUNCHER@)

task=${SLURM_ARRAY_TASK_ID:?run this script with sbatch}
restart=${SLURM_RESTART_COUNT:-0}
read -r case_id failures_before < <(sed -n "$((task + 1))p" "$tasks")
dir=$runs/${case_id:-}
if [ -z "${case_id:-}" ] || [ ! -f "$dir/case.json" ]; then
  echo "task $task: no case on line $((task + 1)) of $tasks, or no $dir/case.json" >&2
  exit 2
fi
# The run folder's lock, as `study run` takes it: held here and by the solver while it runs. Where
# the file system has no locks the task goes on: records and summary.json are written atomically.
exec 9>>"$dir/.lock"
flock -n -E 99 9
if [ $? -eq 99 ]; then
  echo "case $case_id: $dir/.lock is held by another process (a study run?); not started" >&2
  exit 1
fi
# The solver's `case run` takes the lock itself unless told that this folder's is held for it.
export BOYCOTT_RUN_FOLDER_LOCKED="$(cd "$dir" && pwd -P)"
mkdir -p "$dir/attempts"

pid=
trapped=0
warned=0
stopped=0
# Bash runs a trap only between commands or in `wait`: the solver runs in the background.
trap 'warned=1; trapped=1; [ -z "$pid" ] || kill -USR1 "$pid" 2>/dev/null' USR1
trap 'stopped=1; trapped=1; [ -z "$pid" ] || kill -TERM "$pid" 2>/dev/null' TERM INT

now() { date -u +%Y-%m-%dT%H:%M:%S.%3NZ; }
log_size() { stat -c %s "$dir/solver.log" 2>/dev/null || echo 0; }
json_str() { local v=${1//\\/\\\\}; v=${v//\"/\\\"}; printf '"%s"' "$v"; }
write_attempt() {
  local tmp=$dir/attempts/.$name.tmp
  cat > "$tmp" <<EOF
{
  "case_id": "$case_id",
  "slurm_job_id": $SLURM_JOB_ID,
  "slurm_array_job_id": $SLURM_ARRAY_JOB_ID,
  "slurm_array_task_id": $task,
  "restart_count": $restart,
  "try": $try,
  "host": $(json_str "$(hostname)"),
  "ranks": $ranks,
  "program_version": $(json_str "$version"),
  "started_at": "$started",
  "log_offset_bytes": $offset,
  "ended_at": $ended,
  "exit_code": $exit_code,
  "log_end_bytes": $log_end,
  "warned": $warned_json,
  "set_aside": $aside,
  "counted_failure": $counted
}
EOF
  mv -f "$tmp" "$dir/attempts/$name" && cp -f "$dir/attempts/$name" "$dir/.attempt.json.tmp" &&
    mv -f "$dir/.attempt.json.tmp" "$dir/attempt.json" ||
    echo "case $case_id: cannot write $dir/attempts/$name" >&2
}
# How many of this submission's attempt records of the case hold the line $1.
count_records() {
  grep -l -x -F "  \"slurm_array_job_id\": $SLURM_ARRAY_JOB_ID," "$dir"/attempts/*.json 2>/dev/null |
    xargs -r grep -l -x -F "$1" | wc -l
}
requeue() {
  echo "case $case_id: $1; requeueing job $SLURM_JOB_ID"
  scontrol requeue "$SLURM_JOB_ID" ||
    echo "case $case_id: scontrol requeue failed; submit the study again to resume" >&2
  exit 0
}

try=0
while :; do
  [ "$warned" = 0 ] || requeue "the wall-time warning came before the solver started"
  [ "$stopped" = 0 ] || exit 75
  name=$(date -u +%Y%m%dT%H%M%S)-$SLURM_JOB_ID-r$restart-t$try.json
  started=$(now); offset=$(log_size); ended=null; exit_code=null; log_end=null
  aside=null; counted=false; warned_json=false
  write_attempt
  "${launcher[@]}" "${solver[@]}" case run "$dir/case.json" --out "$dir" --quiet >> "$dir/solver.log" 2>&1 &
  pid=$!
  while :; do
    trapped=0
    wait "$pid"
    rc=$?
    [ "$trapped" = 1 ] || break
  done
  pid=
  ended="\"$(now)\""; exit_code=$rc; log_end=$(log_size)
  [ "$warned" = 0 ] || warned_json=true
  case $rc in
    0)
      write_attempt
      exit 0 ;;
    75|130|138|143)  # checkpointed and stopped (or stopped before the solver's handlers)
      write_attempt
      [ "$warned" = 0 ] || requeue "checkpointed on the wall-time warning"
      exit 75 ;;
    74)  # storage error: the last good checkpoint is kept; not a failure of the case
      write_attempt
      if [ "$(count_records '  "exit_code": 74,')" -ge 5 ]; then
        echo "case $case_id: 5 storage errors; not requeued: submit the study again once the storage works" >&2
        exit 74
      fi
      sleep "$storage_pause_s" &
      pid=$!
      wait "$pid"
      pid=
      [ "$stopped" = 0 ] || exit 74
      requeue "storage error (exit 74), not counted as a failure" ;;
    *)
      counted=true
      if [ "$rc" = 4 ]; then  # unusable checkpoint or folder: set aside, start afresh
        aside_dir=$dir.bad-$SLURM_JOB_ID-r$restart-t$try
        mkdir -p "$aside_dir"
        for f in "$dir"/* "$dir"/.[!.]*; do
          case ${f##*/} in
            case.json|attempts|attempt.json|.lock|'*'|'.[!.]*') ;;
            *) mv -f "$f" "$aside_dir/" ;;
          esac
        done
        aside=$(json_str "$aside_dir")
      fi
      write_attempt
      [ "$rc" != 2 ] || exit 2  # bad input: running it again cannot help
      failures=$((failures_before + $(count_records '  "counted_failure": true')))
      if [ "$failures" -gt "$retries" ]; then
        echo "case $case_id: failed $failures times (last exit $rc); not retried" >&2
        exit "$rc"
      fi
      try=$((try + 1)) ;;
  esac
done
)SH";

void replace_all(std::string& s, const std::string& what, const std::string& with) {
  for (auto pos = s.find(what); pos != std::string::npos; pos = s.find(what, pos + with.size()))
    s.replace(pos, what.size(), with);
}

/// The batch script of a job array of n_tasks tasks.
std::string batch_script(const SlurmSubmitOptions& opt, const std::string& study, std::size_t n_tasks,
                         const ScriptPaths& paths, const std::vector<std::string>& solver) {
  std::string s = "#!/bin/bash\n";
  s += fmt::format("# boycott study submit: study {}, {} cases, one per array task ({}, boycott {}+{}).\n",
                   study, n_tasks, utc_now(), kVersion, kGitRevision);
  s += fmt::format("#SBATCH --job-name={}\n", job_name(study));
  s += fmt::format("#SBATCH --array=0-{}{}\n", n_tasks - 1,
                   opt.max_running > 0 ? fmt::format("%{}", opt.max_running) : "");
  s += fmt::format("#SBATCH --ntasks={}\n", opt.ranks);
  if (!opt.time.empty()) s += fmt::format("#SBATCH --time={}\n", opt.time);
  if (!opt.partition.empty()) s += fmt::format("#SBATCH --partition={}\n", opt.partition);
  s += fmt::format("#SBATCH --signal=B:USR1@{}\n", kWarningLeadS);
  s += "#SBATCH --requeue\n#SBATCH --open-mode=append\n";
  s += fmt::format("#SBATCH --output={}\n", (paths.folder / "slurm-%A_%a.out").string());
  for (const auto& a : opt.sbatch_args) s += fmt::format("#SBATCH {}\n", a);
  std::string body = kTaskScript;
  replace_all(body, "@TASKS@", shell_quote(paths.tasks.string()));
  replace_all(body, "@RUNS@", shell_quote(paths.runs_root.string()));
  replace_all(body, "@RANKS@", std::to_string(opt.ranks));
  replace_all(body, "@RETRIES@", std::to_string(opt.retries));
  replace_all(body, "@VERSION@", shell_quote(fmt::format("{}+{}", kVersion, kGitRevision)));
  replace_all(body, "@SOLVER@", words_quoted(solver));
  replace_all(body, "@LAUNCHER@",
              opt.ranks == 1           ? ""
              : opt.launcher == "srun" ? "srun --mpi=pmix -n \"$ranks\""
                                       : "mpirun -n \"$ranks\" --allow-run-as-root");
  return s + body;
}

void write_file(const fs::path& p, const std::string& text, fs::perms extra = fs::perms::none) {
  const fs::path tmp = p.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw StorageError(fmt::format("cannot write '{}': {}", tmp.string(), std::strerror(errno)));
  }
  if (extra != fs::perms::none) fs::permissions(tmp, extra, fs::perm_options::add);
  fs::rename(tmp, p);
}

/// A new folder for this submission's script, tasks file and Slurm output: <db>.slurm/<study>-<time>.
fs::path submission_folder(const std::string& db_path, const std::string& study) {
  std::string stamp = utc_now().substr(0, 19);
  stamp.erase(std::remove(stamp.begin(), stamp.end(), ':'), stamp.end());
  stamp.erase(std::remove(stamp.begin(), stamp.end(), '-'), stamp.end());
  const fs::path base = fs::path(db_path + ".slurm") / fmt::format("{}-{}", job_name(study).substr(8), stamp);
  fs::path p = base;
  for (int i = 2; fs::exists(p); ++i) p = base.string() + fmt::format("-{}", i);
  return p;
}

/// The cases a dry run would submit: neither done nor failed in the database as it is (none yet:
/// every case). Reads only.
std::vector<const StudyCase*> pending_dry_run(Study& study, const std::string& db_path, int retries) {
  std::map<std::string, CaseStatus> status;
  if (fs::exists(db_path)) {
    Database db(db_path, OpenMode::kReadOnly);
    add_recorded_refinements(db, study);
    for (const auto& s : case_states(db, study.name, retries)) status[s.id] = s.status;
  }
  std::vector<const StudyCase*> pending;
  for (const auto& c : study.cases) {
    const auto it = status.find(c.id);
    if (it == status.end() || (it->second != CaseStatus::kDone && it->second != CaseStatus::kFailed))
      pending.push_back(&c);
  }
  return pending;
}

/// The cases to submit, after collecting what the run folders hold: neither done nor failed, not
/// in a Slurm job already, not run here by `study run`.
std::vector<const StudyCase*> pending_to_submit(Database& db, const Study& study, const fs::path& root,
                                                int retries) {
  prepare_study_database(db, study, root);
  const CollectResult collected = collect_run_folders(db, study, root);
  if (collected.results > 0 || collected.attempts > 0 || collected.abandoned > 0)
    std::printf("collected %d results and %d attempt ends, closed %d abandoned attempts\n", collected.results,
                collected.attempts, collected.abandoned);
  std::map<std::string, CaseState> states;
  for (auto& s : case_states(db, study.name, retries)) states[s.id] = s;
  std::vector<const StudyCase*> pending;
  int in_slurm = 0, held = 0;
  for (const auto& c : study.cases) {
    const auto it = states.find(c.id);
    const CaseStatus st = it == states.end() ? CaseStatus::kPending : it->second.status;
    if (st == CaseStatus::kDone || st == CaseStatus::kFailed) continue;
    if (collected.in_slurm.count(c.id)) {
      ++in_slurm;
      continue;
    }
    // An open attempt of `study run` whose solver still holds the folder here.
    if (st == CaseStatus::kRunning && fs::exists(root / c.id / ".lock") && !run_folder_unheld(root / c.id)) {
      ++held;
      continue;
    }
    pending.push_back(&c);
  }
  if (in_slurm > 0) std::printf("%d cases are in Slurm jobs already (queued or running)\n", in_slurm);
  if (held > 0) std::printf("%d cases are running here (study run) and are not submitted\n", held);
  return pending;
}

/// The cases to submit (pending_to_submit) with the points [refine] recorded before, and those its
/// next round adds where a curve's cases have all finished: each submit/collect round adds the
/// next points.
std::vector<const StudyCase*> submittable(Database& db, Study& study, const fs::path& root, int retries) {
  add_recorded_refinements(db, study);
  auto pending = pending_to_submit(db, study, root, retries);
  if (!study.refine) return pending;
  const RefineRound round = next_refine_round(db, study, retries);
  std::set<std::string> told;
  print_refine_round(round, told);
  if (round.added.empty()) return pending;
  study.cases.insert(study.cases.end(), round.added.begin(), round.added.end());
  return pending_to_submit(db, study, root, retries);
}

/// Writes the pending cases' case files, the tasks file and the script, and submits the script;
/// returns the job id sbatch gave.
std::int64_t submit_array(const std::vector<const StudyCase*>& pending, const ScriptPaths& paths,
                          const std::string& script, const std::string& tasks) {
  const auto sbatch = find_program("sbatch");
  if (!sbatch) throw std::runtime_error("no sbatch on PATH: Slurm's client commands are needed to submit");
  fs::create_directories(paths.folder);
  for (const auto* c : pending) {
    fs::create_directories(paths.runs_root / c->id);
    write_file(paths.runs_root / c->id / kCaseFileName, case_file_text(c->params));
  }
  write_file(paths.tasks, tasks);
  const fs::path script_path = paths.folder / "job.sh";
  write_file(script_path, script, fs::perms::owner_exec);
  const Captured sub = run_captured({*sbatch, "--parsable", script_path.string()});
  const auto job = to_int(trim(sub.out).substr(0, trim(sub.out).find(';')));
  if (sub.exit_code != 0 || !job)
    throw std::runtime_error(fmt::format("sbatch {} failed (exit {}): {}", script_path.string(),
                                         sub.exit_code, trim(sub.err + " " + sub.out)));
  return *job;
}

}  // namespace

int study_submit(const SlurmSubmitOptions& opt) {
  validate(opt);
  Study study = expand_study_file(opt.study_file);
  const std::string db_path = fs::absolute(opt.db_path).lexically_normal().string();
  const fs::path root = runs_root(db_path);
  auto solver = solver_argv(opt.solver_command);

  std::optional<Database> db;
  if (!opt.dry_run) db.emplace(db_path, OpenMode::kCreate);
  std::vector<const StudyCase*> pending =
      db ? submittable(*db, study, root, opt.retries) : pending_dry_run(study, db_path, opt.retries);
  if (pending.empty()) {
    std::printf("study %s: nothing to submit\n", study.name.c_str());
    return 0;
  }

  ScriptPaths paths;
  paths.folder = submission_folder(db_path, study.name);
  paths.tasks = paths.folder / "tasks";
  paths.runs_root = root;
  const std::string script = batch_script(opt, study.name, pending.size(), paths, solver);
  std::string tasks;
  std::map<std::string, int> failures;
  if (db)
    for (const auto& s : case_states(*db, study.name, opt.retries)) failures[s.id] = s.failures;
  for (const auto* c : pending) tasks += fmt::format("{} {}\n", c->id, failures[c->id]);
  if (opt.dry_run) {
    std::fputs(script.c_str(), stdout);
    std::fprintf(stderr, "dry run: %zu cases as array 0-%zu; the tasks file %s would list:\n%s",
                 pending.size(), pending.size() - 1, paths.tasks.c_str(), tasks.c_str());
    return 0;
  }

  const std::int64_t job = submit_array(pending, paths, script, tasks);
  std::vector<SubmittedCase> submitted;
  for (std::size_t i = 0; i < pending.size(); ++i)
    submitted.push_back({pending[i]->id, (root / pending[i]->id).string(), static_cast<std::int64_t>(i)});
  record_submission(*db, job, opt.ranks, submitted);
  std::printf(
      "study %s: submitted job %lld, %zu cases as array 0-%zu%s, %d rank%s each (script %s)\n"
      "record the finished ones with: boycott study collect %s --db %s\n",
      study.name.c_str(), static_cast<long long>(job), pending.size(), pending.size() - 1,
      opt.max_running > 0 ? fmt::format("%{}", opt.max_running).c_str() : "", opt.ranks,
      opt.ranks > 1 ? "s" : "", (paths.folder / "job.sh").c_str(), opt.study_file.c_str(),
      opt.db_path.c_str());
  return 0;
}

}  // namespace boycott::driver
