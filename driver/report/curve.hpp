#pragma once
// The correlation curve <<w_p>>(theta) and r_acc(theta) as text and as a plot (SVG, PDF or PNG) in the layout
// of Zeng et al. (2021) Fig. 14: settling velocity (left) and acceleration ratio (right) vs angle.
#include <string>
#include <vector>

#include "driver/report/curve_query.hpp"
#include "driver/report/listing_format.hpp"
#include "driver/report/paper_reference.hpp"
#include "driver/report/peak_query.hpp"
#include "driver/report/plot_cairo.hpp"
#include "driver/store/store.hpp"

namespace boycott::driver {

std::string format_curve(const std::vector<CurvePoint>& pts, ListingFormat f);
/// Both panels, one line per group with error bars (capped), each replica as a faint dot; with
/// `paper`, the values Zeng et al. (2021) state (driver/report/paper_reference.hpp) as hollow diamonds;
/// with `peaks` (query_peak's rows), each curve's peak as a dashed box of its 68 % intervals of
/// angle and value around a cross. Drawn with Cairo as SVG, PDF or PNG (driver/report/plot_cairo.hpp).
plot::Plot curve_plot(const std::vector<CurvePoint>& pts, const std::string& title,
                      const std::vector<PaperValue>* paper = nullptr,
                      plot::Format format = plot::Format::kSvg, const std::vector<PeakRow>* peaks = nullptr);

/// `query cases`: one row per case with its status and, unless done, its last error.
std::string format_cases(const std::vector<CaseState>& cases, ListingFormat f);

}  // namespace boycott::driver
