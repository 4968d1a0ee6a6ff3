// `boycott stats mean` (driver/report/series_table.hpp, series_mean.hpp): the run's rules on a
// user's CSV, its refusals of bad input, and its agreement with a run's summary.json.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "driver/report/series_mean.hpp"
#include "driver/report/series_table.hpp"
#include "stats/window_error.hpp"

using namespace boycott::driver::report;

namespace {

// t, a velocity (AR(1) of tau_int 5 rows around -0.2 m/s), a text column, a constant.
std::string sample_csv(std::size_t rows) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 0.01);
  std::string s = "time_s,w_m_s,label,k\n";
  double v = 0.0;
  for (std::size_t i = 0; i < rows; ++i) {
    v = 9.0 / 11.0 * v + g(rng);
    s += fmt::format("{},{},x{},3\n", 0.01 * static_cast<double>(i), -0.2 + v, i);
  }
  return s;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(SeriesMean, EveryNumericColumnGetsTheRunsWindowErrorAndTheTimeColumnIsTheClock) {
  const auto t = parse_series_table(sample_csv(2000), "s.csv");
  ASSERT_TRUE(t.time_s);
  ASSERT_EQ(t.names, (std::vector<std::string>{"w_m_s", "k"}));  // the text column left out
  const auto rows = series_means(t, {}, parse_average_from("5"));
  ASSERT_EQ(rows.size(), 2u);
  const std::vector<double> window(t.columns[0].begin() + 500, t.columns[0].end());
  const auto w = boycott::stats::window_error(window, 5.0, 20.0);
  EXPECT_EQ(rows[0].samples, 1500u);
  EXPECT_DOUBLE_EQ(rows[0].mean, w.e.mean);
  EXPECT_DOUBLE_EQ(rows[0].error, w.err.covering_error);
  EXPECT_EQ(rows[0].basis, boycott::stats::error_method_name(w.err.basis));
  EXPECT_TRUE(rows[0].velocity);
  // tau_int in seconds: rows 0.01 s apart.
  EXPECT_NEAR(rows[0].tau_int, 0.01 * w.e.tau_int, 1e-12);
  EXPECT_DOUBLE_EQ(rows[1].mean, 3.0);
  EXPECT_DOUBLE_EQ(rows[1].error, 0.0);
  const std::string json = format_series_means(rows, boycott::driver::ListingFormat::kJson, true);
  const auto j = nlohmann::json::parse(json);
  EXPECT_TRUE(j[0].contains("error_m_s"));
  EXPECT_TRUE(j[1].contains("error"));
}

TEST(SeriesMean, BadInputIsRefusedWithOneSentence) {
  auto refused = [](const std::string& csv, const std::vector<std::string>& cols, const std::string& from) {
    try {
      series_means(parse_series_table(csv, "s.csv"), cols, parse_average_from(from));
    } catch (const boycott::InputError& e) {
      const std::string m = e.what();
      return !m.empty() && m.find('\n') == std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(refused("a,b\nx,y\nz,w\n", {}, ""));                                // no numeric column
  EXPECT_TRUE(refused(sample_csv(100), {"nope"}, ""));                            // unknown column
  EXPECT_TRUE(refused(sample_csv(7), {}, ""));                                    // fewer than 8 rows
  EXPECT_TRUE(refused("t,a\n0,1\n1,nan\n2,3\n", {}, ""));                         // a NaN
  EXPECT_TRUE(refused(sample_csv(100) + "1.0,2.0\n", {}, ""));                    // a ragged row
  EXPECT_TRUE(refused(sample_csv(100), {}, "0.95"));                              // 5 rows left
  EXPECT_TRUE(refused(sample_csv(100), {}, "soon"));                              // not a time
  EXPECT_TRUE(refused("t,a\n0,1\n2,1\n1,1\n3,1\n4,1\n5,1\n6,1\n7,1\n", {}, ""));  // time goes back
  EXPECT_FALSE(refused(sample_csv(100), {}, "auto"));
}

TEST(SeriesMean, OnTheCommitted75DegreeRowsItAgreesWithTheRunsSummaryWithinTheSampling) {
  // The full-size 75 deg run's rows (every 0.01 s) against its summary (every step, ~0.9 ms):
  // the mean of the rows from 5 s differs from the mean of the steps by the sampling of a
  // series whose correlation time is ~0.3 s, well inside the error; the errors, both from the
  // window's two halves, agree to the same degree. Measured: -193.51 +- 4.71 mm/s from the 481
  // rows, -193.89 +- 4.92 from the 5695 steps (0.08 errors apart, errors 4 % apart).
  const std::string dir = BOYCOTT_SOURCE_DIR "/docs/results/runs/9592e8d74a5a4760/";
  const auto summary = nlohmann::json::parse(slurp(dir + "summary.json"));
  const auto t = parse_series_table(slurp(dir + "timeseries.csv"), "75 deg rows");
  const auto rows = series_means(t, {"mean_wp_m_s"}, parse_average_from("5"));
  ASSERT_EQ(rows.size(), 1u);
  const double mean = summary["mean_settling_velocity_m_s"], error = summary["settling_velocity_error_m_s"];
  std::printf("75 deg: rows %.6f +- %.6f (%s), steps %.6f +- %.6f\n", rows[0].mean, rows[0].error,
              rows[0].basis.c_str(), mean, error);
  EXPECT_EQ(rows[0].basis, summary["settling_velocity_error_method"]);
  EXPECT_LT(std::abs(rows[0].mean - mean), 0.1 * error);
  EXPECT_NEAR(rows[0].error / error, 1.0, 0.1);
}
