// `query validation` and `query work-precision` on a database built through the real study API
// (register_study, begin_attempt, record_result) with hand-made summaries.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "driver/report/curve.hpp"
#include "driver/report/curve_query.hpp"
#include "driver/report/plot_cairo.hpp"
#include "driver/report/runs_query.hpp"
#include "driver/report/terminal_text.hpp"
#include "driver/report/validation_query.hpp"
#include "driver/report/work_precision.hpp"
#include "driver/run/replica_rounds.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"
#include "driver/study/study.hpp"
#include "stats/distributions.hpp"

namespace bd = boycott::driver;
namespace fs = std::filesystem;

namespace {

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/boycott_querytest_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path); }
};

// A work-precision study: fine reference, one coarser DEM step, one coarser mesh, at two angles.
const char* kWorkPrecisionStudy = R"(
name = "wp"
[base.time]
end = 2.0
average_from = 1.0
[[group]]
name = "reference"
set = { "time.dt_dem" = 1e-5 }
[[group]]
name = "dt_dem"
set = { "time.dt_dem" = 4e-5 }
[[group]]
name = "cells"
set = { "domain.cells" = [100, 6, 50] }
[matrix]
"gravity.angle_deg" = [65, 90]
)";

struct Run {
  double w, err, wall;
};

nlohmann::json summary_of(const bd::StudyCase& c, const Run& r) {
  return {{"scene", "inclined_settling"},
          {"case_id", c.id},
          {"status", "done"},
          {"mean_settling_velocity_m_s", r.w},
          {"settling_velocity_stderr_m_s", r.err},
          {"simulated_time_s", 2.0},
          {"wall_time_s", r.wall},
          {"particle_steps", 1000}};
}

/// Records a result for every case of `study` that `runs` names by (group, angle).
void record(bd::Database& db, const bd::Study& study,
            const std::map<std::pair<std::string, double>, Run>& runs) {
  for (const auto& c : study.cases) {
    auto it = runs.find({c.group, c.params.gravity.angle_deg});
    if (it == runs.end()) continue;
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, summary_of(c, it->second));
  }
}

const bd::WorkPrecisionRow& row(const bd::WorkPrecision& wp, const std::string& group, double angle) {
  for (const auto& r : wp.rows)
    if (r.group == group && r.angle_deg == angle) return r;
  throw std::runtime_error("no row " + group);
}

// Reference: w(65) = -0.1 +- 0.001, w(90) = -0.08 +- 0.0008.
const std::map<std::pair<std::string, double>, Run> kRuns = {
    {{"reference", 65}, {-0.1, 0.001, 400}}, {{"reference", 90}, {-0.08, 0.0008, 380}},
    {{"dt_dem", 65}, {-0.11, 0.002, 100}},   {{"dt_dem", 90}, {-0.084, 0.0, 95}},
    {{"cells", 65}, {-0.1, 0.001, 50}},      {{"cells", 90}, {-0.078, 0.0008, 60}},
};

std::string what_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const boycott::InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace

TEST(WorkPrecision, ErrorIsRelativeToTheReferenceOfTheSameAngle) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  record(db, study, kRuns);
  const auto wp = bd::query_work_precision(db, "wp");
  ASSERT_EQ(wp.rows.size(), 4u);  // the reference group is not compared with itself
  const auto& r65 = row(wp, "dt_dem", 65);
  EXPECT_DOUBLE_EQ(r65.w_ref_m_s, -0.1);
  // w = -0.11 against w_ref = -0.1: settles 10 % faster.
  EXPECT_NEAR(r65.rel_error_w, 0.10, 1e-12);
  EXPECT_NEAR(row(wp, "dt_dem", 90).rel_error_w, -0.084 / -0.08 - 1.0, 1e-12);
  EXPECT_NEAR(row(wp, "cells", 65).rel_error_w, 0.0, 1e-15);
  EXPECT_EQ(r65.setting.size(), 1u);
  EXPECT_EQ(r65.setting[0].key, "time.dt_dem");
  EXPECT_DOUBLE_EQ(*r65.setting[0].value_num, 4e-5);
  EXPECT_EQ(*r65.particle_steps, 1000);
  ASSERT_EQ(wp.references.size(), 2u);
  EXPECT_EQ(wp.references[0].angle_deg, 65.0);
  EXPECT_DOUBLE_EQ(*wp.references[1].wall_time_s, 380.0);
}

TEST(WorkPrecision, UncertaintyPropagatesBothStandardErrorsToFirstOrder) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  record(db, study, kRuns);
  const auto wp = bd::query_work_precision(db, "wp");
  // e = w/w_ref - 1: sigma_e^2 = (s/w_ref)^2 + (w s_ref / w_ref^2)^2.
  const double expected = std::sqrt(std::pow(0.002 / 0.1, 2) + std::pow(0.11 * 0.001 / 0.01, 2));
  EXPECT_NEAR(row(wp, "dt_dem", 65).rel_error_w_unc, expected, 1e-12);
  // A case without a standard error keeps the reference's.
  EXPECT_NEAR(row(wp, "dt_dem", 90).rel_error_w_unc, 0.084 * 0.0008 / (0.08 * 0.08), 1e-12);
}

TEST(WorkPrecision, AccelerationRatioErrorComparesRatiosOfTheSameSetting) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  record(db, study, kRuns);
  const auto wp = bd::query_work_precision(db, "wp");
  const auto& r65 = row(wp, "dt_dem", 65);
  // r_acc = 0.11/0.084 against the reference's 0.1/0.08 = 1.25.
  const double R = (0.11 / 0.084) / 1.25;
  ASSERT_TRUE(r65.rel_error_r_acc.has_value());
  EXPECT_NEAR(*r65.rel_error_r_acc, R - 1.0, 1e-12);
  // Independent relative errors add in quadrature (the 90 deg case has none).
  EXPECT_NEAR(*r65.rel_error_r_acc_unc, R * std::sqrt(std::pow(0.002 / 0.11, 2) + 2 * std::pow(0.01, 2)),
              1e-12);
  EXPECT_NEAR(*row(wp, "cells", 65).rel_error_r_acc, (0.1 / 0.078) / 1.25 - 1.0, 1e-12);
  // At 90 deg r_acc is 1 by definition: nothing to compare.
  EXPECT_FALSE(row(wp, "dt_dem", 90).rel_error_r_acc.has_value());
}

TEST(WorkPrecision, RowsAreInStudyGroupOrderThenByWallTime) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  record(db, study, kRuns);
  const auto wp = bd::query_work_precision(db, "wp");
  std::vector<std::pair<std::string, double>> got;
  for (const auto& r : wp.rows) got.emplace_back(r.group, *r.wall_time_s);
  const std::vector<std::pair<std::string, double>> want = {
      {"dt_dem", 95}, {"dt_dem", 100}, {"cells", 50}, {"cells", 60}};
  EXPECT_EQ(got, want);
  const auto table = bd::format_work_precision(wp, bd::ListingFormat::kTable);
  EXPECT_NE(table.find("+10.00 % +- 2.28 %"), std::string::npos) << table;
  EXPECT_NE(table.find("time.dt_dem=4e-05"), std::string::npos) << table;
  const auto csv = bd::format_work_precision(wp, bd::ListingFormat::kCsv);
  EXPECT_NE(csv.find("\"domain.cells=[100, 6, 50]\""), std::string::npos) << csv;  // quoted: it holds commas
  const auto json = nlohmann::json::parse(bd::format_work_precision(wp, bd::ListingFormat::kJson));
  EXPECT_EQ(json["rows"].size(), 4u);
  EXPECT_TRUE(json["rows"][0]["rel_error_r_acc"].is_null());
}

TEST(WorkPrecision, MissingReferenceIsAnInputErrorNamingTheGroupAndAngle) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  auto runs = kRuns;
  runs.erase({"reference", 65});
  record(db, study, runs);
  const auto msg = what_of([&] { bd::query_work_precision(db, "wp"); });
  EXPECT_NE(msg.find("reference group 'reference'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("gravity.angle_deg = 65"), std::string::npos) << msg;
  // A reference group the study does not have is named together with the groups it does have.
  const auto msg2 = what_of([&] { bd::query_work_precision(db, "wp", "fine"); });
  EXPECT_NE(msg2.find("no group 'fine'"), std::string::npos) << msg2;
  EXPECT_NE(msg2.find("reference, dt_dem, cells"), std::string::npos) << msg2;
  EXPECT_NE(what_of([&] { bd::query_work_precision(db, "nope"); }).find("no study 'nope'"),
            std::string::npos);
}

namespace {
// A fine reference group and one with a coarser DEM step; `head`: the study's top-level keys,
// `matrix`: its [matrix] lines.
bd::Study dt_dem_study(const std::string& head, const std::string& matrix) {
  return bd::expand_study_string(head + R"(
[base.time]
end = 2.0
average_from = 1.0
[[group]]
name = "reference"
set = { "time.dt_dem" = 1e-5 }
[[group]]
name = "dt_dem"
set = { "time.dt_dem" = 4e-5 }
[matrix]
)" + matrix);
}
}  // namespace

TEST(WorkPrecision, TwoReferenceCasesAtOneAngleAreAnInputErrorNamingThem) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  // Two seeds per angle make the reference group ambiguous.
  const auto study = dt_dem_study("name = \"wp2\"", "\"gravity.angle_deg\" = [90]\nseed = [1, 2]\n");
  bd::register_study(db, study);
  std::vector<std::string> ref_ids;
  for (const auto& c : study.cases) {
    if (c.group == "reference") ref_ids.push_back(c.id);
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, summary_of(c, {-0.08, 0.001, 10}));
  }
  ASSERT_EQ(ref_ids.size(), 2u);
  const auto msg = what_of([&] { bd::query_work_precision(db, "wp2"); });
  EXPECT_NE(msg.find("2 finished cases at gravity.angle_deg = 90"), std::string::npos) << msg;
  for (const auto& id : ref_ids) EXPECT_NE(msg.find(id), std::string::npos) << msg;
}

TEST(WorkPrecision, ReplicasOfAPointCountOnceAsTheirMeanWithTheirStandardErrorAndOneRunsCost) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  // Two replicas (seeds 1 and 2) of every point, the reference's among them.
  const auto study = dt_dem_study("name = \"wp3\"\nreplicas = 2", "\"gravity.angle_deg\" = [65, 90]\n");
  bd::register_study(db, study);
  ASSERT_EQ(study.cases.size(), 8u);
  // Each point's replicas at its centre -+ a half-spread h: mean the centre, standard error of
  // the mean sd / sqrt(2) = (h sqrt(2)) / sqrt(2) = h; wall times 10 and 30 s (one run: 20).
  const std::map<std::pair<std::string, double>, std::pair<double, double>> centre_h = {
      {{"reference", 65}, {-0.1, 0.001}},
      {{"reference", 90}, {-0.08, 0.0008}},
      {{"dt_dem", 65}, {-0.11, 0.002}},
      {{"dt_dem", 90}, {-0.084, 0.0004}}};
  for (const auto& c : study.cases) {
    const auto [w, h] = centre_h.at({c.group, c.params.gravity.angle_deg});
    const bool first = c.replica == 0;
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id,
                      summary_of(c, {first ? w - h : w + h, 0.01, first ? 10.0 : 30.0}));
  }
  const auto wp = bd::query_work_precision(db, "wp3");
  ASSERT_EQ(wp.rows.size(), 2u);
  ASSERT_EQ(wp.references.size(), 2u);
  const auto& r65 = row(wp, "dt_dem", 65);
  EXPECT_EQ(r65.n_replicas, 2);
  EXPECT_EQ(r65.ref_n_replicas, 2);
  EXPECT_NEAR(r65.w_m_s, -0.11, 1e-15);
  EXPECT_NEAR(r65.w_err_m_s, 0.002, 1e-15);  // the replicas' scatter, not their own 0.01
  EXPECT_NEAR(r65.w_ref_m_s, -0.1, 1e-15);
  EXPECT_NEAR(r65.w_ref_err_m_s, 0.001, 1e-15);
  EXPECT_NEAR(r65.rel_error_w, 0.1, 1e-12);
  EXPECT_NEAR(r65.rel_error_w_unc, std::hypot(0.002 / 0.1, 0.11 * 0.001 / 0.01), 1e-12);
  ASSERT_TRUE(r65.wall_time_s.has_value());
  EXPECT_DOUBLE_EQ(*r65.wall_time_s, 20.0);
  // r_acc from the means: (0.11 / 0.084) / (0.1 / 0.08) - 1.
  ASSERT_TRUE(r65.rel_error_r_acc.has_value());
  EXPECT_NEAR(*r65.rel_error_r_acc, (0.11 / 0.084) / (0.1 / 0.08) - 1.0, 1e-12);
  EXPECT_EQ(wp.references[0].n_replicas, 2);
  EXPECT_DOUBLE_EQ(*wp.references[0].wall_time_s, 20.0);
  const auto json = nlohmann::json::parse(bd::format_work_precision(wp, bd::ListingFormat::kJson));
  EXPECT_EQ(json["rows"][0]["n_replicas"], 2);
  EXPECT_EQ(json["rows"][0]["reference_n_replicas"], 2);
  const auto csv = bd::format_work_precision(wp, bd::ListingFormat::kCsv);
  EXPECT_NE(csv.find("case_id,reference_case_id,n_replicas,reference_n_replicas\n"), std::string::npos)
      << csv;
}

// Occurrences of `needle` in `s`.
std::size_t count_in(const std::string& s, const std::string& needle) {
  std::size_t n = 0;
  for (auto p = s.find(needle); p != std::string::npos; p = s.find(needle, p + 1)) ++n;
  return n;
}

// A Cairo SVG document of the given size in CSS pixels, with strokes and text (glyphs) drawn.
void expect_svg(const std::string& svg, int width, int height) {
  const auto root = svg.find("<svg");
  ASSERT_NE(root, std::string::npos) << svg.substr(0, 200);
  EXPECT_EQ(svg.find_first_not_of(" \n"), svg.rfind("<?xml", 0) == 0 ? 0u : root);
  const auto head = svg.substr(root, svg.find('>', root) - root);
  EXPECT_NE(head.find("xmlns=\"http://www.w3.org/2000/svg\""), std::string::npos) << head;
  EXPECT_NE(head.find(fmt::format("width=\"{}px\"", width)), std::string::npos) << head;
  EXPECT_NE(head.find(fmt::format("height=\"{}px\"", height)), std::string::npos) << head;
  EXPECT_EQ(svg.substr(svg.find_last_not_of(" \n") - 5, 6), "</svg>");
  EXPECT_EQ(count_in(svg, "<"), count_in(svg, ">"));  // every tag closed
  EXPECT_GT(count_in(svg, "<path"), 20u);             // lines, markers, glyph outlines
  EXPECT_GT(count_in(svg, "<use"), 20u);              // the glyphs of the text, placed
}

TEST(WorkPrecision, PlotHasAPanelPerAngleALinePerGroupSignedErrorsWithBarsAndLabelsInTheKeysUnits) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  record(db, study, kRuns);
  const auto wp = bd::query_work_precision(db, "wp");
  const auto plot = bd::work_precision_plot(wp, "wp & co");
  expect_svg(plot.data, 90 + 2 * 490 + 170, 520);  // two angles
  EXPECT_EQ(plot.count("panel"), 2);               // one per angle
  EXPECT_TRUE(plot.has_text("θ = 65°"));
  EXPECT_TRUE(plot.has_text("θ = 90°"));
  EXPECT_EQ(plot.count("group"), 4);  // one line per group in each panel
  EXPECT_EQ(plot.count("legend"), 2);
  EXPECT_TRUE(plot.has_text("dt_dem"));
  EXPECT_TRUE(plot.has_text("cells"));
  EXPECT_TRUE(plot.has_text("reference (reference)"));
  EXPECT_EQ(plot.count("zero"), 2);       // the reference's 0 in each panel
  EXPECT_EQ(plot.count("reference"), 2);  // its wall time, one per angle
  EXPECT_EQ(plot.count("errorbar"), 4);   // every point: both runs have an error
  // Each point is labelled with its key's last part and its value in the key's unit.
  EXPECT_EQ(plot.count("setting"), 4);
  EXPECT_TRUE(plot.has_text("dt_dem 40 µs"));
  EXPECT_TRUE(plot.has_text("cells [100, 6, 50]"));
  EXPECT_TRUE(plot.has_text("wp & co"));
  EXPECT_TRUE(plot.has_text("wall time of one run (s)"));
  // Signed: cells at 65 deg equals the reference, a filled marker on the 0 line like the others.
  EXPECT_EQ(plot.count("hollow marker"), 0);
  EXPECT_EQ(plot.count("marker"), 6);  // four points, the groups' keys
  EXPECT_EQ(plot.count("caption"), 2);

  // The same drawing as PDF.
  const auto pdf = bd::work_precision_plot(wp, "wp & co", bd::plot::Format::kPdf);
  EXPECT_EQ(pdf.data.rfind("%PDF-", 0), 0u);
  EXPECT_GT(pdf.data.size(), 2000u);
  EXPECT_NE(pdf.data.find("%%EOF"), std::string::npos);
  EXPECT_EQ(pdf.drawn, plot.drawn);
  EXPECT_EQ(pdf.texts, plot.texts);
}

// The bar of a work-precision point covers like r_acc's: the two points' plain errors (here the
// replicas' scatter, 2 degrees of freedom each) propagated, times Student's t at Welch's degrees
// of freedom, 6 for two equal parts of 2 each; with runs of unknown dof it is the plain error.
TEST(WorkPrecision, ErrorBarIsTheRatiosCoveringErrorAtWelchsDegreesOfFreedom) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = dt_dem_study("name = \"wpr\"\nreplicas = 3\n", "\"gravity.angle_deg\" = [65]\n");
  bd::register_study(db, study);
  // Replicas: dt_dem -0.110 +- {0, -0.002, +0.002} (sd 0.002), reference -0.1 +- {0, -0.0018,
  // +0.0018} (sd 0.0018): parts (0.002/sqrt 3 / 0.1)^2 and (1.1 * 0.0018/sqrt 3 / 0.1)^2, nearly equal.
  for (const auto& c : study.cases) {
    const double k = c.replica == 0 ? 0.0 : (c.replica == 1 ? -1.0 : 1.0);
    const double w = c.group == "reference" ? -0.1 + 0.0018 * k : -0.110 + 0.002 * k;
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, summary_of(c, {w, 0.0005, 10.0}));
  }
  const auto wp = bd::query_work_precision(db, "wpr");
  const auto& r = row(wp, "dt_dem", 65);
  EXPECT_NEAR(r.rel_error_w, 0.10, 1e-12);
  const double a = 0.002 / std::sqrt(3.0) / 0.1, b = 1.1 * 0.0018 / std::sqrt(3.0) / 0.1;
  const double var = a * a + b * b;
  const double nu = var * var / (a * a * a * a / 4.0 + b * b * b * b / 4.0) - 2.0;
  EXPECT_NEAR(nu, 6.0, 0.01);
  ASSERT_TRUE(r.rel_error_w_err.has_value());
  EXPECT_NEAR(*r.rel_error_w_err, std::sqrt(var) * boycott::stats::one_sigma_t_factor(nu), 1e-9);
  EXPECT_GT(*r.rel_error_w_err, 1.08 * r.rel_error_w_unc);  // t_6 at 68 %: 1.09
  const auto csv = bd::format_work_precision(wp, bd::ListingFormat::kCsv);
  EXPECT_NE(csv.find("rel_error_w_uncertainty,rel_error_w_error,"), std::string::npos) << csv;
  EXPECT_NE(bd::format_work_precision(wp, bd::ListingFormat::kTable).find("error <<w_p>> +- 68 %"),
            std::string::npos);
  // Runs without degrees of freedom (the fixture's): the plain propagated error.
  TempDir d2;
  bd::Database db2((d2.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto plain = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db2, plain);
  record(db2, plain, kRuns);
  const auto wp2 = bd::query_work_precision(db2, "wp");
  EXPECT_NEAR(*row(wp2, "dt_dem", 65).rel_error_w_err, row(wp2, "dt_dem", 65).rel_error_w_unc, 1e-12);
}

TEST(CurvePlot, DrawsBothPanelsWithErrorBarsReplicasAndThePaperOverlayAsSvgPdfAndPng) {
  std::vector<bd::CurvePoint> pts;
  for (const double angle : {45.0, 90.0}) {
    bd::CurvePoint p;
    p.group = "Ga";
    p.angle_deg = angle;
    p.w_m_s = angle == 90.0 ? -0.02 : -0.03;
    p.w_err_m_s = 0.001;
    p.error.error_m_s = 0.0013;
    p.error.basis = "between_replicas_t";
    p.n_replicas = 3;
    p.replica_w_m_s = {p.w_m_s - 0.001, p.w_m_s, p.w_m_s + 0.001};
    p.r_acc = p.w_m_s / -0.02;
    p.r_acc_err = 0.05;
    pts.push_back(p);
  }
  const std::vector<bd::PaperValue> paper = {{"Ga", 60.0, "r_acc", 1.4, "Fig. 14"},
                                             {"Ga", std::nullopt, "r_acc", 1.6, "text"}};
  const auto plot = bd::curve_plot(pts, "study <s>", &paper);
  expect_svg(plot.data, 1000, 470);
  EXPECT_EQ(plot.count("panel"), 2);
  EXPECT_EQ(plot.count("group"), 2);     // one line per series in each panel
  EXPECT_EQ(plot.count("errorbar"), 4);  // each point in each panel
  EXPECT_EQ(plot.count("replica"), 12);  // 3 replicas x 2 points x 2 panels
  EXPECT_EQ(plot.count("paper"), 2);     // both r_acc values, on the right panel only
  EXPECT_EQ(plot.count("legend"), 2);    // the series and the paper
  EXPECT_TRUE(plot.has_text("study <s>"));
  EXPECT_TRUE(plot.has_text("inclination angle θ (deg)"));
  EXPECT_TRUE(
      plot.has_text("error bars: the interval that covers the mean ~68 % of the time (Student's t); faint "
                    "dots: replicas (seeds)"));

  const auto pdf = bd::curve_plot(pts, "study <s>", &paper, bd::plot::format_of_path("c.PDF"));
  EXPECT_EQ(pdf.data.rfind("%PDF-", 0), 0u);
  EXPECT_GT(pdf.data.size(), 2000u);
  EXPECT_EQ(pdf.drawn, plot.drawn);
  const auto png = bd::curve_plot(pts, "study <s>", &paper, bd::plot::format_of_path("c.png"));
  EXPECT_EQ(png.data.rfind("\x89PNG\r\n\x1a\n", 0), 0u);
  EXPECT_GT(png.data.size(), 2000u);
  EXPECT_EQ(bd::plot::format_of_path("c.svg"), bd::plot::Format::kSvg);
  // Any other extension is refused (a .jpg holding SVG would mislead).
  EXPECT_THROW(bd::plot::format_of_path("pdf"), boycott::InputError);
  EXPECT_THROW(bd::plot::format_of_path("c.jpg"), boycott::InputError);
}

TEST(CurvePlot, OverlaysOnlyTheStudysGroupsDrawsPointsWithoutAnErrorOpenAndTypesetsItsLabels) {
  std::vector<bd::CurvePoint> pts;
  for (const double angle : {45.0, 90.0}) {
    bd::CurvePoint p;
    p.group = "base";
    p.angle_deg = angle;
    p.w_m_s = angle == 90.0 ? -0.08 : -0.15;
    if (angle == 90.0) p.error.error_m_s = 0.001;  // 45 deg: none
    p.r_acc = p.w_m_s / -0.08;
    if (angle == 90.0) p.r_acc_err = 0.0;
    pts.push_back(p);
  }
  const std::vector<bd::PaperValue> paper = {{"base", 65.0, "mean_settling_velocity_m_s", -0.1816, "Table"},
                                             {"Sg1.5", 65.0, "mean_settling_velocity_m_s", -0.05, "Fig. 14"},
                                             {"Ga145.6", std::nullopt, "r_acc", 1.6, "text"}};
  const auto plot = bd::curve_plot(pts, "s", &paper);
  EXPECT_EQ(plot.count("paper"), 1);  // the base value; not Sg1.5's nor Ga145.6's
  EXPECT_TRUE(plot.has_text(
      "Zeng et al. 2021, group base: stated values (dashed: a peak whose angle is not stated)"));
  EXPECT_EQ(plot.count("errorbar"), 1);         // 90 deg's <<w_p>>; the 45 deg point is open, barless
  EXPECT_TRUE(plot.has_text("⟨⟨wp⟩⟩ (mm/s)"));  // w_{p}: p drawn as a subscript
  EXPECT_TRUE(plot.has_text("racc = ⟨⟨wp⟩⟩ / ⟨⟨wp⟩⟩(90°)"));
  EXPECT_TRUE(plot.has_text(
      "error bars: the interval that covers the mean ~68 % of the time (Student's t); open markers: no error "
      "available"));
  EXPECT_EQ(plot.data.find("w_p"), std::string::npos);
}

TEST(CurvePlot, ALegendWiderThanThePageWrapsIntoRowsAndThePageGrowsByThem) {
  // Eight groups and the paper's entry: far more than the 960 px a legend row may fill.
  std::vector<bd::CurvePoint> pts;
  std::vector<std::string> names;
  for (int g = 0; g < 8; ++g) {
    names.push_back(fmt::format("group number {} with a long name", g));
    for (const double angle : {65.0, 90.0}) {
      bd::CurvePoint p;
      p.group = names.back();
      p.angle_deg = angle;
      p.w_m_s = angle == 90.0 ? -0.08 : -0.15;
      p.error.error_m_s = 0.001;
      pts.push_back(p);
    }
  }
  const std::vector<bd::PaperValue> paper = {{names[0], 65.0, "mean_settling_velocity_m_s", -0.18, "Table"}};
  const std::string paper_entry =
      "Zeng et al. 2021, group " + names[0] + ": stated values (dashed: a peak whose angle is not stated)";
  // The rows a greedy fill of 960 px makes: each entry a 16 px marker, its text and a 24 px gap.
  std::vector<std::string> entries = names;
  entries.push_back(paper_entry);
  int rows = 1;
  double used = 0.0;
  for (const auto& e : entries) {
    const double w = 16.0 + bd::plot::text_width(e) + 24.0;
    if (used > 0.0 && used + w - 24.0 > 960.0) ++rows, used = 0.0;
    used += w;
  }
  ASSERT_GE(rows, 3);
  const auto plot = bd::curve_plot(pts, "s", &paper);
  expect_svg(plot.data, 1000, 470 + 18 * (rows - 1));
  EXPECT_EQ(plot.count("legend"), 9);
  for (const auto& e : entries) EXPECT_TRUE(plot.has_text(e)) << e;
}

TEST(ValidationQuery, RowsListExactlyTheStoredErrorKeysWithTheirValues) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  const auto& c = study.cases[2];  // dt_dem, 65 deg
  auto s = summary_of(c, {-0.11, 0.002, 100});
  s["max_rel_error_vs_analytic"] = 0.0123;
  s["rel_error"] = nullptr;  // NaN in the solver: no reference value
  s["hindered_settling_rel_error"] = nlohmann::json::array({0.01, -0.02, nullptr});
  s["mean_fluid_velocity_m_s"] = 0.001;
  bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, s);

  const auto rows = bd::query_validation(db, "wp");
  ASSERT_EQ(rows.size(), 1u);
  const auto& r = rows[0];
  EXPECT_EQ(r.study, "wp");
  EXPECT_EQ(r.group, "dt_dem");
  EXPECT_EQ(r.case_id, c.id);
  EXPECT_EQ(r.scene, "inclined_settling");
  std::vector<std::string> keys;
  for (const auto& e : r.errors) keys.push_back(e.first);
  // The stored standard error contains "error" too but is not a validation error.
  EXPECT_EQ(keys, (std::vector<std::string>{"hindered_settling_rel_error", "max_rel_error_vs_analytic",
                                            "rel_error"}));
  EXPECT_DOUBLE_EQ(r.errors[1].second.get<double>(), 0.0123);
  EXPECT_TRUE(r.errors[2].second.is_null());
  EXPECT_DOUBLE_EQ(*r.w_m_s, -0.11);
  EXPECT_DOUBLE_EQ(*r.wall_time_s, 100.0);
  ASSERT_EQ(r.values.size(), 2u);
  EXPECT_EQ(r.values[0].key, "gravity.angle_deg");
  EXPECT_EQ(r.values[1].key, "time.dt_dem");

  const auto table = bd::format_validation(rows, bd::ListingFormat::kTable);
  EXPECT_NE(table.find("max_rel_error_vs_analytic=+1.23 %"), std::string::npos) << table;
  EXPECT_NE(table.find("rel_error=-"), std::string::npos) << table;
  EXPECT_NE(table.find("hindered_settling_rel_error=[+1.00 %, -2.00 %, -]"), std::string::npos) << table;
  EXPECT_NE(table.find("gravity.angle_deg=65; time.dt_dem=4e-05"), std::string::npos) << table;
  const auto csv = bd::format_validation(rows, bd::ListingFormat::kCsv);
  EXPECT_EQ(
      csv.substr(0, csv.find('\n')),
      "study,group,case_id,scene,values,mean_settling_velocity_m_s,wall_time_s,hindered_settling_rel_error,"
      "max_rel_error_vs_analytic,rel_error");
  EXPECT_NE(csv.find(",0.0123,\n"), std::string::npos) << csv;  // raw number; null is empty
  const auto json = nlohmann::json::parse(bd::format_validation(rows, bd::ListingFormat::kJson));
  EXPECT_TRUE(json[0]["errors"]["rel_error"].is_null());
  EXPECT_DOUBLE_EQ(json[0]["values"]["time.dt_dem"].get<double>(), 4e-5);
}

TEST(ValidationQuery, OnlyFinishedCasesOfTheNamedStudyAreListed) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  record(db, study, {{{"reference", 90}, {-0.08, 0.001, 10}}, {{"cells", 65}, {-0.1, 0.001, 5}}});
  // An unfinished attempt is not a result.
  bd::begin_attempt(db, study.cases[2].id, 1, "x");
  const auto rows = bd::query_validation(db, "wp");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].group, "reference");  // study order
  EXPECT_EQ(rows[1].group, "cells");
  EXPECT_TRUE(rows[0].errors.empty());
  EXPECT_NE(bd::format_validation(rows, bd::ListingFormat::kTable).find("  -\n"), std::string::npos);
  EXPECT_EQ(bd::query_validation(db).size(), 2u);
  EXPECT_NE(what_of([&] { bd::query_validation(db, "nope"); }).find("no study 'nope'"), std::string::npos);
}

// The per-run listing behind docs/results.md's cost table: what each point rests on and what it
// cost, read back from the summaries the runs recorded.
TEST(RunsQuery, EachFinishedRunListsItsWindowErrorBasisCorrelationTimesAndCoreHours) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kWorkPrecisionStudy);
  bd::register_study(db, study);
  const auto& c65 = study.cases[0];  // reference, 65 deg
  auto s = summary_of(c65, {-0.1, 0.001, 7200});
  s["average_from_s"] = 1.0;
  s["particle_count"] = 120000;
  s["settling_velocity_error_m_s"] = 0.00184;
  s["settling_velocity_error_method"] = "two_halves";
  s["settling_velocity_error_dof"] = 1.0;
  s["settling_velocity_correlation_time_s"] = 0.1;
  s["settling_velocity_window_correlation_times"] = 10.0;
  s["mpi_ranks"] = 2;
  s["cpu_time_s"] = 5400.0;  // over all attempts: less than the 4 core-hours held
  bd::record_result(db, bd::begin_attempt(db, c65.id, 2, "x"), c65.id, s);
  // A run of an older build: no error basis, no rank count.
  const auto& c90 = study.cases[1];  // reference, 90 deg
  bd::record_result(db, bd::begin_attempt(db, c90.id, 1, "x"), c90.id, summary_of(c90, {-0.08, 0.001, 3600}));
  bd::begin_attempt(db, study.cases[2].id, 1, "x");  // running: not a run yet

  const auto rows = bd::query_runs(db, "wp");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].case_id, c65.id);  // study order
  EXPECT_EQ(rows[0].group, "reference");
  EXPECT_DOUBLE_EQ(rows[0].angle_deg, 65.0);
  EXPECT_EQ(*rows[0].n_particles, 120000);
  EXPECT_DOUBLE_EQ(*rows[0].average_from_s, 1.0);
  EXPECT_DOUBLE_EQ(*rows[0].end_s, 2.0);
  EXPECT_DOUBLE_EQ(*rows[0].error_m_s, 0.00184);
  EXPECT_EQ(*rows[0].error_method, "two_halves");
  EXPECT_DOUBLE_EQ(*rows[0].window_correlation_times, 10.0);
  EXPECT_DOUBLE_EQ(*bd::core_hours(rows[0]), 4.0);  // 2 h of wall time on 2 ranks
  EXPECT_FALSE(rows[1].error_method.has_value());
  EXPECT_FALSE(bd::core_hours(rows[1]).has_value());
  EXPECT_DOUBLE_EQ(*bd::cpu_core_hours(rows[0]), 1.5);
  EXPECT_FALSE(bd::cpu_core_hours(rows[1]).has_value());

  const auto table = bd::format_runs(rows, bd::ListingFormat::kTable);
  EXPECT_NE(table.find("-100.00 ± 1.84"), std::string::npos) << table;
  EXPECT_NE(table.find("two_halves (1 dof)"), std::string::npos) << table;
  EXPECT_NE(table.find("1-2"), std::string::npos) << table;  // the window, s
  EXPECT_NE(table.find("2 runs, 4.0 core-hours"), std::string::npos) << table;
  EXPECT_NE(table.find("1 without a wall time or rank count"), std::string::npos) << table;
  EXPECT_NE(table.find("1.5 CPU core-hours in the 1 runs that record them"), std::string::npos) << table;
  const auto csv = bd::format_runs(rows, bd::ListingFormat::kCsv);
  EXPECT_EQ(
      csv.substr(0, csv.find('\n')),
      "case_id,group,angle_deg,n_particles,end_s,average_from_s,mean_settling_velocity_m_s,error_m_s,"
      "error_method,error_dof,correlation_time_s,window_correlation_times,wall_time_s,mpi_ranks,core_hours,"
      "cpu_core_hours");
  EXPECT_NE(csv.find(c65.id + ",reference,65,120000,2,1,-0.1,0.00184,two_halves,1,0.1,10,7200,2,4,1.5\n"),
            std::string::npos)
      << csv;
  const auto json = nlohmann::json::parse(bd::format_runs(rows, bd::ListingFormat::kJson));
  EXPECT_DOUBLE_EQ(json[0]["core_hours"].get<double>(), 4.0);
  EXPECT_TRUE(json[1]["core_hours"].is_null());
  EXPECT_DOUBLE_EQ(json[0]["cpu_core_hours"].get<double>(), 1.5);
  EXPECT_TRUE(json[1]["cpu_core_hours"].is_null());
  EXPECT_NE(what_of([&] { bd::query_runs(db, "nope"); }).find("no study 'nope'"), std::string::npos);
}

TEST(CurveQuery, GroupSweepingMoreThanTheAngleGetsOneCurvePerSetting) {
  // Two viscosities x two angles in one group: r_acc of each viscosity against its own 90 deg.
  TempDir tmp;
  bd::Database db((tmp.path / "c.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(R"(
name = "c"
[[group]]
name = "g"
set = { "fluid.density" = 1000.0 }
[matrix]
"fluid.viscosity" = [1e-3, 1e-2]
"gravity.angle_deg" = [65, 90]
)");
  bd::register_study(db, study);
  for (const auto& c : study.cases) {
    const bool thin = c.params.fluid.viscosity_pa_s < 5e-3, steep = c.params.gravity.angle_deg == 90.0;
    const double w = thin ? (steep ? -0.08 : -0.18) : (steep ? -0.02 : -0.06);
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, summary_of(c, ::Run{w, 0.0, 1.0}));
  }
  const auto pts = bd::query_curve(db, "c");
  ASSERT_EQ(pts.size(), 4u);
  for (const auto& p : pts) {
    // Only what varies within the group names the setting (not the group's own `set`).
    EXPECT_EQ(p.setting.find("fluid.density"), std::string::npos) << p.setting;
    ASSERT_TRUE(p.r_acc.has_value());
    const bool thin = p.setting == "fluid.viscosity=0.001";
    EXPECT_TRUE(thin || p.setting == "fluid.viscosity=0.01") << p.setting;
    const double expect = p.angle_deg == 90.0 ? 1.0 : (thin ? 0.18 / 0.08 : 0.06 / 0.02);
    EXPECT_NEAR(*p.r_acc, expect, 1e-12) << p.setting << " at " << p.angle_deg;
  }
}

TEST(CurveQuery, KeysZippedWithTheAngleBelongToItsPointNotToASecondCurve) {
  // Each angle its own run length (as the full-size campaign): one curve, r_acc against its 90 deg.
  TempDir tmp;
  bd::Database db((tmp.path / "z.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(R"(
name = "z"
[[group]]
name = "base"
[group.zip]
"gravity.angle_deg" = [90, 65, 15]
"time.end" = [20.0, 20.0, 5.0]
"time.average_from" = [5.0, 5.0, 2.0]
)");
  bd::register_study(db, study);
  for (const auto& c : study.cases) {
    const double w =
        c.params.gravity.angle_deg == 90.0 ? -0.08 : (c.params.gravity.angle_deg == 65.0 ? -0.18 : -0.01);
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, summary_of(c, ::Run{w, 0.0, 1.0}));
  }
  const auto pts = bd::query_curve(db, "z");
  ASSERT_EQ(pts.size(), 3u);
  for (const auto& p : pts) {
    EXPECT_EQ(p.setting, "") << p.angle_deg;
    ASSERT_TRUE(p.r_acc.has_value()) << p.angle_deg;
  }
  EXPECT_NEAR(*pts[1].r_acc, 0.18 / 0.08, 1e-12);  // 65 deg, angles ascending
}

TEST(ValidationQuery, ErrorsWithAToleranceShowItAndPassOrFail) {
  // Two single_particle cases: one within the scene's 2 % of the drag law's terminal velocity,
  // one outside it. An error without a tolerance (none for this key) gets no verdict.
  TempDir d;
  bd::Database db((d.path / "v.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(R"(
name = "sp"
[base]
scene = "single_particle"
[matrix]
"fluid.viscosity" = [0.001, 0.002]
)");
  bd::register_study(db, study);
  const double rel[] = {0.012, -0.031};
  for (std::size_t i = 0; i < study.cases.size(); ++i) {
    const auto& c = study.cases[i];
    nlohmann::json s = {{"scene", "single_particle"}, {"case_id", c.id},      {"status", "completed"},
                        {"simulated_time_s", 2.0},    {"wall_time_s", 3.0},   {"particle_steps", 10},
                        {"rel_error", rel[i]},        {"drift_error_m", 1e-9}};
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, s);
  }
  const auto rows = bd::query_validation(db, "sp");
  const auto json = nlohmann::json::parse(bd::format_validation(rows, bd::ListingFormat::kJson));
  ASSERT_EQ(json.size(), 2u);
  std::map<double, bool> verdicts;
  for (const auto& r : json) {
    ASSERT_EQ(r["checks"].size(), 1u) << r.dump();  // rel_error only
    EXPECT_EQ(r["checks"][0]["error"], "rel_error");
    EXPECT_DOUBLE_EQ(r["checks"][0]["tolerance"].get<double>(), 0.02);
    verdicts[r["checks"][0]["value"].get<double>()] = r["checks"][0]["pass"].get<bool>();
  }
  EXPECT_TRUE(verdicts.at(0.012));
  EXPECT_FALSE(verdicts.at(-0.031));
  const auto table = bd::format_validation(rows, bd::ListingFormat::kTable);
  EXPECT_NE(table.find("(|.| <= 2 %: pass)"), std::string::npos) << table;
  EXPECT_NE(table.find("(|.| <= 2 %: FAIL)"), std::string::npos) << table;
}

TEST(CurveQuery, CsvQuotesAGroupOrSettingThatHoldsACommaQuoteOrLineBreak) {
  bd::CurvePoint p;
  p.group = "a,b";
  p.setting = "domain.cells=[20, 6, 20]";
  p.case_id = "0123456789abcdef";
  p.angle_deg = 65;
  p.w_m_s = -0.1;
  p.error_method = "sokal_autocorrelation";
  bd::CurvePoint q = p;
  q.group = "line\nbreak \"quoted\"";
  const auto csv = bd::format_curve({p, q}, bd::ListingFormat::kCsv);
  EXPECT_NE(csv.find("\n\"a,b\",65,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n\"line\nbreak \"\"quoted\"\"\",65,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",\"domain.cells=[20, 6, 20]\"\n"), std::string::npos) << csv;
}

TEST(ReplicaRounds, AdaptivePointsRunWhatSteinsFirstStageAsksForInOneRoundAndReportItsError) {
  // Target 1 % of |<<w_p>>|; the first three replicas -0.100, -0.102, -0.098 (sd 0.002): Stein
  // needs t_2 sd / sqrt(n) <= 0.001, n >= (1.3213 * 2)^2 = 6.98, so 7 replicas, 4 added at once.
  TempDir tmp;
  bd::Database db((tmp.path / "a.db").string(), bd::OpenMode::kCreate);
  const std::string text = R"(
name = "adapt"
replicas_target_rel_error = 0.01
[base.time]
end = 2.0
average_from = 1.0
[matrix]
"gravity.angle_deg" = [90]
)";
  auto study = bd::expand_study_string(text);
  ASSERT_EQ(study.cases.size(), 3u);
  bd::register_study(db, study);
  const double first[] = {-0.100, -0.102, -0.098};
  for (const auto& c : study.cases)
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id,
                      summary_of(c, {first[c.replica], 0.0, 1.0}));
  auto round = bd::next_replica_round(db, study);
  ASSERT_EQ(round.added.size(), 4u);
  EXPECT_EQ(round.added.back().replica, 6);
  // The added replicas run (any values: the stage-one scatter fixed their number) and are
  // registered as study run registers them; the next round adds none.
  for (const auto& c : round.added) study.cases.push_back(c);
  bd::register_study(db, study);
  for (const auto& c : round.added)
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id,
                      summary_of(c, {-0.1 + 0.003 * (c.replica - 4), 0.0, 1.0}));
  round = bd::next_replica_round(db, study);
  EXPECT_TRUE(round.added.empty());
  EXPECT_EQ(round.precise, 1);
  // The curve reports Stein's error: t_2 s0 / sqrt(7), s0 from the first three alone.
  const auto pts = bd::query_curve(db, "adapt");
  ASSERT_EQ(pts.size(), 1u);
  EXPECT_EQ(pts[0].n_replicas, 7);
  EXPECT_EQ(pts[0].error.basis, "two_stage_stein");
  EXPECT_NEAR(*pts[0].error.error_m_s, boycott::stats::one_sigma_t_factor(2.0) * 0.002 / std::sqrt(7.0),
              1e-12);
}

TEST(Listings, CasesAsTableCsvAndJsonHoldTheSameRows) {
  bd::CaseState done;
  done.study = "s";
  done.group = "base";
  done.id = "00000000000000aa";
  done.angle_deg = 65.0;
  done.status = bd::CaseStatus::kDone;
  bd::CaseState failed = done;
  failed.id = "00000000000000bb";
  failed.status = bd::CaseStatus::kFailed;
  failed.failures = 2;
  failed.last_error = "error: the run became unphysical, at t = 0.1 s";
  const std::vector<bd::CaseState> cases = {done, failed};
  const auto table = bd::format_cases(cases, bd::ListingFormat::kTable);
  EXPECT_NE(table.find("00000000000000bb"), std::string::npos);
  EXPECT_EQ(table.find(" \n"), std::string::npos) << "no padding at a line's end:\n" << table;
  const auto csv = bd::format_cases(cases, bd::ListingFormat::kCsv);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "study,group,case,angle_deg,status,failures,last_error");
  // A comma in the error is quoted: the row keeps its 7 fields.
  EXPECT_NE(csv.find(",\"error: the run became unphysical, at t = 0.1 s\"\n"), std::string::npos) << csv;
  const auto json = nlohmann::json::parse(bd::format_cases(cases, bd::ListingFormat::kJson));
  ASSERT_EQ(json.size(), 2u);
  EXPECT_EQ(json[1]["angle_deg"], 65.0);
  EXPECT_EQ(json[1]["failures"], 2);
  EXPECT_EQ(json[1]["status"], "failed");
  EXPECT_EQ(json[0]["last_error"], "");
  EXPECT_THROW(bd::parse_listing_format("xml"), boycott::InputError);
  // An escape sequence in a cell (a solver's last error, say) reaches no terminal raw; CSV keeps
  // the data as it is.
  failed.last_error =
      "error: \x1b]0;owned\x07 \xc2\x9b"
      "2J";
  const auto raw = bd::format_cases({failed}, bd::ListingFormat::kTable);
  EXPECT_EQ(raw.find('\x1b'), std::string::npos) << raw;
  EXPECT_EQ(raw.find("\xc2\x9b"), std::string::npos) << raw;
  EXPECT_NE(raw.find("\\x1B]0;owned\\x07 \\u009B2J"), std::string::npos) << raw;
  EXPECT_NE(bd::printable("⟨⟨w_p⟩⟩ θ").find("⟨⟨w_p⟩⟩ θ"), std::string::npos) << "UTF-8 text passes";
}
