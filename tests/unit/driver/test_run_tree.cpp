// The tree of readable names beside the run folders (driver/run/run_tree.hpp): one link per case,
// replicas of a point in a folder of their own, an older tree corrected in place.
#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>

#include "driver/run/run_tree.hpp"
#include "driver/study/study.hpp"

namespace bd = boycott::driver;
namespace fs = std::filesystem;

namespace {

const char* kReplicated = R"(
name = "tree"
replicas = 3
[base]
scene = "inclined_settling"
[base.time]
end = 1.0
average_from = 0.5
[[group]]
name = "swept"
[group.matrix]
"gravity.angle_deg" = [60, 90]
[[group]]
name = "fixed"
set = { "gravity.angle_deg" = 80 }
[[group]]
name = "single"
replicas = 1
set = { "gravity.angle_deg" = 70 }
)";

struct TreeDir {
  fs::path dir =
      fs::temp_directory_path() / ("run_tree_" + std::to_string(::getpid()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  TreeDir() { fs::remove_all(dir), fs::create_directories(dir / "runs"); }
  ~TreeDir() { fs::remove_all(dir); }
};

TEST(RunTree, EveryReplicaOfEveryPointGetsItsOwnLinkToItsRunFolder) {
  const auto study = bd::expand_study_string(kReplicated);
  ASSERT_EQ(study.cases.size(), 3u * 2u + 3u + 1u);
  TreeDir t;
  for (const auto& c : study.cases) fs::create_directories(t.dir / "runs" / c.id);
  const std::string db = (t.dir / "s.db").string();
  EXPECT_EQ(bd::update_run_tree(study, db, t.dir / "runs"), 0);
  for (const auto& c : study.cases) {
    const fs::path leaf = bd::names_root(db) / bd::case_name_path(study, c);
    ASSERT_TRUE(fs::is_symlink(leaf)) << leaf;
    EXPECT_TRUE(fs::equivalent(leaf, t.dir / "runs" / c.id)) << leaf;
  }
  const fs::path names = bd::names_root(db) / "tree";
  EXPECT_TRUE(fs::is_symlink(names / "swept/gravity.angle_deg=90/replica=0"));
  EXPECT_TRUE(fs::is_symlink(names / "swept/gravity.angle_deg=90/replica=2"));
  EXPECT_TRUE(fs::is_symlink(names / "fixed/gravity.angle_deg=80/replica=1"));
  // A group without replicas keeps its single link where it was.
  EXPECT_TRUE(fs::is_symlink(names / "single/gravity.angle_deg=70"));
  // Writing again changes nothing and fails nothing.
  EXPECT_EQ(bd::update_run_tree(study, db, t.dir / "runs"), 0);
}

TEST(RunTree, ALinkWhereAPointsReplicaFolderGoesIsReplacedByTheFolder) {
  const auto study = bd::expand_study_string(kReplicated);
  TreeDir t;
  for (const auto& c : study.cases) fs::create_directories(t.dir / "runs" / c.id);
  const std::string db = (t.dir / "s.db").string();
  // The layout of a tree written when replica 0 was linked at the point itself.
  const fs::path old_link = bd::names_root(db) / "tree/swept/gravity.angle_deg=60";
  fs::create_directories(old_link.parent_path());
  fs::create_directory_symlink(t.dir / "runs" / study.cases.front().id, old_link);
  EXPECT_EQ(bd::update_run_tree(study, db, t.dir / "runs"), 0);
  EXPECT_FALSE(fs::is_symlink(old_link));
  EXPECT_TRUE(fs::is_symlink(old_link / "replica=0"));
  EXPECT_TRUE(fs::is_empty(t.dir / "runs" / study.cases.front().id)) << "nothing written into a run folder";
}

}  // namespace
