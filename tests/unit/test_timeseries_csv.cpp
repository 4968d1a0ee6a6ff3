// timeseries.csv across a resume by a build that added a column at the end (cluster_index): the
// file keeps its own columns, so every row has the header's width and the next resume
// (truncate_csv_after) keeps them all instead of cutting the file at the first wider row.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scenes/run_common.hpp"

using namespace boycott;

namespace {
std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

TEST(TimeSeriesCsv, AResumeKeepsTheColumnsOfAnEarlierBuildsFile) {
  const auto dir = std::filesystem::temp_directory_path() / "boycott_timeseries_csv_test";
  std::filesystem::create_directories(dir);
  const auto path = dir / "timeseries.csv";
  { std::ofstream(path) << "time_s,a\n0.1,1\n0.2,2\n"; }
  {
    scenes::CsvWriter w(path, {"time_s", "a", "b"}, true);
    w.row({0.3, 3.0, 30.0});
    w.flush();
  }
  EXPECT_EQ(read(path), "time_s,a\n0.1,1\n0.2,2\n0.3,3\n");
  scenes::truncate_csv_after(path, 1.0);
  EXPECT_EQ(read(path), "time_s,a\n0.1,1\n0.2,2\n0.3,3\n");
  // A new file, or one written over, has every column.
  {
    scenes::CsvWriter w(path, {"time_s", "a", "b"}, false);
    w.row({0.1, 1.0, 10.0});
    w.flush();
  }
  EXPECT_EQ(read(path), "time_s,a,b\n0.1,1,10\n");
  std::filesystem::remove_all(dir);
}

// A running case is followed by its file's last row (`study run`'s progress, `study status`):
// every row is in the file once row() returns, not when a buffer fills or the writer closes.
TEST(TimeSeriesCsv, EachRowIsInTheFileAsSoonAsItIsWritten) {
  const auto dir = std::filesystem::temp_directory_path() / "boycott_timeseries_csv_rows";
  std::filesystem::create_directories(dir);
  const auto path = dir / "timeseries.csv";
  {
    scenes::CsvWriter w(path, {"time_s", "a"}, false);
    w.row({0.1, 1.0});
    EXPECT_EQ(read(path), "time_s,a\n0.1,1\n");
    w.row({0.2, 2.0});
    EXPECT_EQ(read(path), "time_s,a\n0.1,1\n0.2,2\n");
  }
  std::filesystem::remove_all(dir);
}
