#include "driver/run/run_tree.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <system_error>

#include <fmt/format.h>

namespace fs = std::filesystem;

namespace boycott::driver {

std::string runs_root(const std::string& db_path) {
  return db_path + ".runs";
}

namespace {
/// A value as a path component: strings unquoted, arrays without spaces or brackets, and the
/// characters a file name cannot hold replaced.
std::string component_value(std::string v) {
  if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
  std::string out;
  for (char ch : v) {
    if (ch == ' ' || ch == '[' || ch == ']') continue;
    out += (ch == '/' || ch == '\0') ? '_' : ch;
  }
  out = readable_value(out);
  return out.empty() ? "_" : out;
}
}  // namespace

fs::path names_root(const std::string& db_path) {
  return fs::path(db_path + ".names");
}

fs::path case_name_path(const Study& study, const StudyCase& c) {
  fs::path p = fs::path(component_value(study.name)) / component_value(c.group);
  for (const auto& [key, value] : c.swept) p /= key + "=" + component_value(value);
  // A point that has (or may grow) replicas is a folder of replica=<k> links, replica 0 included:
  // a link for replica 0 at the point itself would stand where its replicas' folder must be.
  const auto plan = study.replica_plans.find(c.group);
  // resolve_replicas guarantees max >= replicas.
  const bool replicated = c.replica > 0 || (plan != study.replica_plans.end() && plan->second.max > 1);
  if (replicated) p /= fmt::format("replica={}", c.replica);
  return p;
}

int update_run_tree(const Study& study, const std::string& db_path, const fs::path& runs_root) {
  int failed = 0;
  const fs::path root = names_root(db_path);
  for (const auto& c : study.cases) {
    std::error_code ec;
    // A case with nothing varied and no replicas is its group's only case: the group is the link.
    const fs::path leaf = root / case_name_path(study, c);
    // A tree written before the point had replicas holds a link where their folder goes now.
    if (fs::is_symlink(leaf.parent_path(), ec)) fs::remove(leaf.parent_path(), ec);
    const fs::path target =
        fs::relative(fs::absolute(runs_root / c.id, ec), fs::absolute(leaf.parent_path(), ec), ec);
    if (ec) {
      ++failed;
      continue;
    }
    if (fs::is_symlink(leaf, ec)) {
      if (fs::read_symlink(leaf, ec) == target) continue;
      fs::remove(leaf, ec);
    } else if (fs::exists(leaf, ec)) {
      ++failed;  // something that is not our link: left as it is
      continue;
    }
    fs::create_directories(leaf.parent_path(), ec);
    if (!ec) fs::create_directory_symlink(target, leaf, ec);
    if (ec) ++failed;
  }
  if (failed > 0)
    std::fprintf(stderr, "note: %d links of %s could not be written (the run folders are unaffected)\n",
                 failed, root.c_str());
  return failed;
}

}  // namespace boycott::driver
