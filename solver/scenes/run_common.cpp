#include "scenes/run_common.hpp"

#include <mpi.h>
#include <petscversion.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "core/build_info.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "io/atomic_file.hpp"
#include "scenes/scene.hpp"

namespace boycott::scenes {

bool RunContext::should_stop() const {
  int local = stop_requested && stop_requested->load(std::memory_order_relaxed) ? 1 : 0;
  int initialized = 0, size = 1;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size == 1) return local != 0;
  int any = 0;
  MPI_Allreduce(&local, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return any != 0;
}

bool output_rank() {
  int initialized = 0, rank = 0;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank == 0;
}

void write_file_atomic(const std::filesystem::path& path, const std::string& text) {
  if (!output_rank()) return;
  io::write_file_atomic(path, text);
}

namespace {
nlohmann::json num_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
/// The machine's CPU model ("model name" of /proc/cpuinfo; "unknown" elsewhere).
std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(" \t", colon + 1));
    }
  return "unknown";
}

/// The run's MPI ranks (1 outside MPI).
int mpi_ranks() {
  int ranks = 1, initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  return ranks;
}

}  // namespace

nlohmann::json build_info() {
  return {{"compiler", kCompiler},
          {"build_type", kBuildType},
          {"flags", kCxxFlags},
          {"petsc_version",
           fmt::format("{}.{}.{}", PETSC_VERSION_MAJOR, PETSC_VERSION_MINOR, PETSC_VERSION_SUBMINOR)},
          {"cpu_model", cpu_model()}};
}

double process_cpu_core_s() {
  const int ranks = mpi_ranks();
  rusage use{};
  getrusage(RUSAGE_SELF, &use);
  const auto secs = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return (secs(use.ru_utime) + secs(use.ru_stime)) * ranks;
}

nlohmann::json make_summary(const CaseParams& p, const SummaryBase& s, const ModelTimers& timers) {
  nlohmann::json j;
  j["scene"] = p.scene;
  j["case_id"] = case_id(p);
  j["status"] = s.status;
  j["simulated_time_s"] = s.simulated_time_s;
  j["wall_time_s"] = s.wall_time_s;
  j["particle_steps"] = s.particle_steps;
  j["mean_settling_velocity_m_s"] = num_or_null(s.mean_settling_velocity_m_s);
  j["settling_velocity_stderr_m_s"] = num_or_null(s.settling_velocity_stderr_m_s);
  j["models"] = timers.to_json();
  j["model_times_from_s"] = timers.counted_from_s();
  j["program_version"] = fmt::format("{}+{}", kVersion, kGitRevision);
  j["build"] = build_info();
  j["mpi_ranks"] = mpi_ranks();
  // This process's CPU since it started: this attempt's cost (start-up included); cpu_time_s
  // is the run's over all attempts, from its checkpoints.
  j["attempt_cpu_time_s"] = process_cpu_core_s();
  j["cpu_time_s"] = num_or_null(s.cpu_time_s);
  if (!p.branch.parent_id.empty())
    j["parent"] = {{"case_id", p.branch.parent_id}, {"time_s", num_or_null(p.branch.parent_time_s)}};
  return j;
}

CsvWriter::CsvWriter(const std::filesystem::path& path, std::vector<std::string> columns, bool append)
    : path_(path), ncol_(columns.size()) {
  if (!output_rank()) return;
  const bool exists = std::filesystem::exists(path) && std::filesystem::file_size(path) > 0;
  f_ = std::fopen(path.c_str(), append && exists ? "a" : "w");
  if (!f_) throw StorageError(fmt::format("cannot write {}: {}", path.string(), std::strerror(errno)));
  if (!(append && exists)) {
    for (std::size_t i = 0; i < columns.size(); ++i) std::fprintf(f_, i ? ",%s" : "%s", columns[i].c_str());
    std::fputc('\n', f_);
    return;
  }
  // A file begun by a build with fewer columns (a column added at the end since) keeps its own:
  // a longer row would read as torn to the next resume (truncate_csv_after) and end the file there.
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  ncol_ = std::min(ncol_, static_cast<std::size_t>(std::count(header.begin(), header.end(), ',')) + 1);
}

CsvWriter::~CsvWriter() {
  if (f_) std::fclose(f_);
}

void CsvWriter::row(const std::vector<double>& values) {
  if (!f_) return;
  for (std::size_t i = 0; i < values.size() && i < ncol_; ++i)
    if (std::fprintf(f_, i ? ",%.10g" : "%.10g", values[i]) < 0 && !error_) error_ = errno;
  if (std::fputc('\n', f_) == EOF && !error_) error_ = errno;
  // Each row reaches the file as it is written: `study run`'s progress and `study status` read a
  // running case's last row, and a stdio buffer held a large case's rows for a quarter of an hour
  // (~30 rows of a 405 000-particle run). A failure is kept for flush() to report.
  if (std::fflush(f_) != 0 && !error_) error_ = errno;
}

void CsvWriter::flush() {
  if (!f_) return;
  if (std::fflush(f_) != 0 && !error_) error_ = errno;
  // A row that did not reach the file is a lost row: stop here (the checkpoint written next
  // would claim rows the file does not have).
  if (error_ || std::ferror(f_))
    throw StorageError(
        fmt::format("cannot write {}: {}", path_.string(), std::strerror(error_ ? error_ : EIO)));
}

void truncate_csv_after(const std::filesystem::path& path, double t_max) {
  if (!output_rank()) return;
  std::ifstream in(path);
  if (!in) return;
  std::string line, out;
  bool header = true;
  std::size_t ncomma = 0;
  while (std::getline(in, line)) {
    const auto commas = static_cast<std::size_t>(std::count(line.begin(), line.end(), ','));
    if (header) {
      ncomma = commas;
    } else {
      // A row cut short by a kill has fewer fields: it and everything after it go.
      if (commas != ncomma || in.eof()) break;
      const double t = std::strtod(line.c_str(), nullptr);
      if (t > t_max * (1.0 + 1e-12) + 1e-15) break;
    }
    header = false;
    out += line + "\n";
  }
  in.close();
  write_file_atomic(path, out);
}

}  // namespace boycott::scenes
