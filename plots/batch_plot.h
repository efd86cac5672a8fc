#pragma once
// Pictures of a batch of runs (runs/batch_report.h): the spread of a figure over seeds, per
// scenario (box plots), and its distribution in one scenario (histograms). Deterministic: the same
// values give the same bytes.
//
// Box plots: the box spans the quartiles (common/quantile.h), the thick line is the median, the
// whiskers reach the most extreme values within 1.5 interquartile ranges of the box (Tukey), and
// every value is drawn as a small grey dot, spread sideways so that equal values stay visible;
// values beyond the whiskers are also circled.

#include <string>
#include <vector>

namespace airtwin::plots {

/// One box: a category's values (any order, finite; may be empty) and its captions.
struct BoxGroup {
  std::string label;  ///< under the box (a scenario's name)
  std::string note;   ///< a second line under it, e.g. "9/10 done"
  std::vector<double> values;
};

/// Writes a PNG of one box per group side by side, under `title`, values on a y axis labelled
/// `y_label` from min(0, smallest value) up. Width grows with the groups (about 110 px each,
/// 640 px at least, 2400 at most), height 560 px. Groups without values show "no data". Throws
/// InputError naming the path when a value is not finite or the file cannot be written.
void write_box_plot_png(const std::string& title, const std::string& y_label,
                        const std::vector<BoxGroup>& groups, const std::string& path);

/// One histogram panel.
struct HistogramPanel {
  std::string title;
  std::string x_label;
  std::string note;  ///< under the title, e.g. "1 failed run not shown"
  std::vector<double> values;
};

/// Writes a PNG of the panels side by side (560 x 420 px each) under `title`: counts of runs in
/// clamp(ceil(sqrt(n)), 5, 30) equal bins over [smallest, largest] value (values that agree to
/// 1e-4 of their size, or a single value: one bin around them). A panel without values shows "no
/// data". Throws InputError as write_box_plot_png.
void write_histograms_png(const std::string& title, const std::vector<HistogramPanel>& panels,
                          const std::string& path);

}  // namespace airtwin::plots
